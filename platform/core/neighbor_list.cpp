// SPDX-License-Identifier: MIT
// Cell-list construction of the Verlet list and history carry-over.
#include "core/neighbor_list.hpp"

#include "core/archive.hpp"
#include "core/error.hpp"
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace domel::platform {

namespace {
inline std::uint64_t pair_key(std::uint64_t a, std::uint64_t b) {
  // ids below 2^32 in practice; mix both halves so larger ids still hash well
  return (a << 32) ^ b ^ (a >> 32);
}
}  // namespace

std::size_t PeriodicBox::wrap(ParticleStore& s) const {
  std::size_t moved = 0;
  for (int a = 0; a < 3; ++a) {
    if (!axis[a]) continue;
    std::vector<double>& x = a == 0 ? s.x : a == 1 ? s.y : s.z;
    const double L = length(a);
    for (double& v : x) {
      if (v >= lo[a] && v < hi[a]) continue;
      v -= L * std::floor((v - lo[a]) / L);
      if (v >= hi[a]) v -= L;  // round-off at the face
      if (v < lo[a]) v = lo[a];
      ++moved;
    }
  }
  return moved;
}

bool NeighborList::needs_rebuild(const ParticleStore& s) const {
  if (layout_stale(s)) return true;
  const double limit2 = rebuild_displacement2();
  const std::size_t n = s.size();
  for (std::size_t k = 0; k < n; ++k) {
    const double dx = s.x[k] - x0_[k], dy = s.y[k] - y0_[k], dz = s.z[k] - z0_[k];
    if (dx * dx + dy * dy + dz * dz > limit2) return true;
  }
  return false;
}

namespace {
/// The live contact history of the last list, keyed by the pair's ids: the
/// keys in row order, and an open-addressing table of row numbers (linear
/// probing, at most 3/4 full) over them. Two flat arrays, no node per
/// contact: 8 bytes per contact plus 5-11 for the table.
class LiveHistory {
 public:
  explicit LiveHistory(std::size_t live) {
    std::size_t cap = 16;
    while (3 * cap < 4 * live) cap *= 2;
    table_.assign(cap, kNone);
    mask_ = cap - 1;
    keys_.reserve(live);
  }
  /// Add the next row (rows are numbered in the order of add()).
  void add(std::uint64_t key) {
    std::size_t h = mix(key) & mask_;
    while (table_[h] != kNone) h = (h + 1) & mask_;
    table_[h] = static_cast<std::uint32_t>(keys_.size());
    keys_.push_back(key);
  }
  /// The row of `key`, or kNone.
  std::uint32_t find(std::uint64_t key) const {
    for (std::size_t h = mix(key) & mask_; table_[h] != kNone; h = (h + 1) & mask_)
      if (keys_[table_[h]] == key) return table_[h];
    return kNone;
  }
  std::size_t size() const { return keys_.size(); }
  static constexpr std::uint32_t kNone = UINT32_MAX;

 private:
  static std::uint64_t mix(std::uint64_t z) {  // the splitmix64 finaliser (Steele et al. 2014)
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  std::vector<std::uint32_t> table_;
  std::vector<std::uint64_t> keys_;
  std::size_t mask_ = 0;
};
}  // namespace

template <class CellOf, class Visit>
void NeighborList::for_each_periodic_pair(std::size_t a_first, std::size_t a_last, const int dim[3],
                                          const uint32_t* start, const uint32_t* order, const double per[3],
                                          const double inv_per[3], CellOf&& cell_of, const ParticleStore& s,
                                          double near_gap, Visit&& visit) const {
  // the distinct neighbour offsets per axis
  int offs[3][3], noff[3];
  for (int a = 0; a < 3; ++a) {
    noff[a] = 0;
    const int from = box_.axis[a] && dim[a] < 3 ? 0 : -1;
    const int to = box_.axis[a] && dim[a] == 1 ? 0 : 1;
    for (int o = from; o <= to; ++o) offs[a][noff[a]++] = o;
  }
  for (std::size_t a = a_first; a < a_last; ++a) {
    int c[3];
    cell_of(a, c);
    const double xa = s.x[a], ya = s.y[a], za = s.z[a], ra = s.radius[a];
    const bool fixed_a = (s.flags[a] & ParticleStore::kFixed) != 0;
    for (int kz = 0; kz < noff[2]; ++kz) {
      int cz = c[2] + offs[2][kz];
      if (box_.axis[2]) cz = (cz + dim[2]) % dim[2];
      else if (cz < 0 || cz >= dim[2]) continue;
      for (int ky = 0; ky < noff[1]; ++ky) {
        int cy = c[1] + offs[1][ky];
        if (box_.axis[1]) cy = (cy + dim[1]) % dim[1];
        else if (cy < 0 || cy >= dim[1]) continue;
        for (int kx = 0; kx < noff[0]; ++kx) {
          int cx = c[0] + offs[0][kx];
          if (box_.axis[0]) cx = (cx + dim[0]) % dim[0];
          else if (cx < 0 || cx >= dim[0]) continue;
          const std::size_t cc = (static_cast<std::size_t>(cz) * dim[1] + cy) * dim[0] + cx;
          for (uint32_t q = start[cc]; q < start[cc + 1]; ++q) {
            const uint32_t b = order[q];
            if (b <= a) continue;
            if (fixed_a && (s.flags[b] & ParticleStore::kFixed) != 0) continue;
            const double rb = s.radius[b];
            const double ddx = min_image(xa - s.x[b], per[0], inv_per[0]);
            const double ddy = min_image(ya - s.y[b], per[1], inv_per[1]);
            const double ddz = min_image(za - s.z[b], per[2], inv_per[2]);
            const double cut = ra + rb + skin_;
            const double d2 = ddx * ddx + ddy * ddy + ddz * ddz;
            if (d2 < cut * cut) visit(a, b, std::sqrt(d2) - ra - rb < near_gap);
          }
        }
      }
    }
  }
}

PairHistories NeighborList::live_histories() const {
  PairHistories h;
  h.stride = stride_;
  for (std::size_t k = 0; k < i.size(); ++k) {
    if (!touching[k]) continue;
    h.id_i.push_back(built_ids_[i[k]]);
    h.id_j.push_back(built_ids_[j[k]]);
    h.values.insert(h.values.end(), history.begin() + static_cast<std::ptrdiff_t>(k * stride_),
                    history.begin() + static_cast<std::ptrdiff_t>((k + 1) * stride_));
  }
  return h;
}

void NeighborList::adopt_histories(PairHistories h) {
  // the live rows of a list whose particles [0, m) hold the i ids and
  // [m, 2m) the j ids, and whose layout no store can match: the next build
  // finds the rows by ids
  const std::size_t m = h.size();
  if (h.id_j.size() != m || h.values.size() != m * stride_ || (m > 0 && h.stride != stride_))
    throw std::invalid_argument("NeighborList::adopt_histories: " + std::to_string(m) + " pairs with " +
                                std::to_string(h.id_j.size()) + " partners and " + std::to_string(h.values.size()) +
                                " history values (" + std::to_string(stride_) + " per pair expected)");
  built_ids_ = std::move(h.id_i);
  built_ids_.insert(built_ids_.end(), h.id_j.begin(), h.id_j.end());
  i.resize(m);
  j.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    i[k] = static_cast<uint32_t>(k);
    j[k] = static_cast<uint32_t>(m + k);
  }
  touching.assign(m, 1);
  history = std::move(h.values);
  near_size_ = m;
  built_size_ = SIZE_MAX;  // layout_stale() from now on: the next build carries over by ids
}

void NeighborList::build(const ParticleStore& s, ThreadPool* pool, std::size_t owned) {
  const std::size_t n = s.size();
  // Keep only the live history (pairs in contact, ~1-6 per particle), keyed by
  // (id_i, id_j), moved to the front of the history array. The list's arrays
  // are cleared but keep their capacity: the new list, about the size of the
  // old, is built into them and the live rows are moved to their new entries
  // in place, so a rebuild neither allocates the list anew nor copies its
  // history (either raised the peak resident memory by 50-190 bytes per
  // particle; docs/performance.md, memory). Transient: the keys of the live
  // contacts and their table, the cell index and the entries of the threads
  // other than the first.
  grown_ = 0.0;
  std::size_t live = 0;
  for (std::size_t k = 0; k < i.size(); ++k) live += touching[k] ? 1 : 0;
  // When no particle was added, removed or re-ordered since the last build
  // (most builds), a live pair keeps its indices and orientation: its new
  // entry is found in its row of the new list (rows_of below), and only the
  // live pairs are looked up. Otherwise by ids, through the table.
  const bool same_layout = !layout_stale(s);
  LiveHistory old(same_layout ? 0 : live);
  std::vector<std::pair<uint32_t, uint32_t>> old_pairs;
  if (same_layout) old_pairs.reserve(live);
  for (std::size_t k = 0, row = 0; k < i.size(); ++k) {
    if (!touching[k]) continue;
    if (same_layout) old_pairs.emplace_back(i[k], j[k]);
    else old.add(pair_key(built_ids_[i[k]], built_ids_[j[k]]));
    std::copy_n(history.begin() + static_cast<std::ptrdiff_t>(k * stride_), stride_,
                history.begin() + static_cast<std::ptrdiff_t>(row * stride_));  // row <= k: front to back is safe
    ++row;
  }
  history.resize(live * stride_);
  const std::size_t previous = i.size(), previous_far = i.size() - near_size_;
  i.clear();
  j.clear();
  touching.clear();
  // Tiers (see near_size()): near entries go to i/j, far ones to fi/fj, each in
  // build order; far is appended after the cell loop. The first thread's near
  // entries are written straight into the list's arrays.
  const double h = near_gap();
  const bool with_ghosts = owned < n;
  struct Part {
    std::vector<uint32_t> i, j, fi, fj;
    std::size_t near = 0, far = 0;  ///< entries of the counting pass
  };
  const int nt = pool != nullptr && n >= 4096 ? pool->size() : 1;
  std::vector<Part> parts(static_cast<std::size_t>(nt));
  parts[0].i = std::move(i);
  parts[0].j = std::move(j);
  // body(first, last, thread) over [0, count), split over the threads
  auto in_ranges = [&](std::size_t count, auto&& body) {
    if (nt == 1) body(std::size_t{0}, count, 0);
    else pool->for_range(count, body);
  };

  if (n > 0) {
    double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                    std::numeric_limits<double>::max()};
    double hi[3] = {-lo[0], -lo[1], -lo[2]};
    double rmax = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      lo[0] = std::min(lo[0], s.x[k]); hi[0] = std::max(hi[0], s.x[k]);
      lo[1] = std::min(lo[1], s.y[k]); hi[1] = std::max(hi[1], s.y[k]);
      lo[2] = std::min(lo[2], s.z[k]); hi[2] = std::max(hi[2], s.z[k]);
      rmax = std::max(rmax, s.radius[k]);
    }
    // Every cell must be at least one cutoff wide, so that all partners of a
    // particle lie in its own or an adjacent cell: floor(span / cutoff) cells.
    // A periodic axis spans its box, the cells of both faces adjacent.
    const double cell = 2.0 * rmax + skin_;
    for (int a = 0; a < 3; ++a)
      if (box_.axis[a]) {
        if (box_.length(a) < 2.0 * cell)
          throw RuntimeError("periodic box " + std::to_string(box_.length(a)) + " m long along " +
                                   std::string(1, static_cast<char>('x' + a)) +
                                   ", less than twice the neighbour-list cut-off " + std::to_string(cell) +
                                   " m (largest diameter + skin): a particle would meet two images of another");
        lo[a] = box_.lo[a];
        hi[a] = box_.hi[a];
      }
    int dim[3];
    for (int a = 0; a < 3; ++a) {
      const double span = hi[a] - lo[a];
      dim[a] = static_cast<int>(std::max(1.0, std::min(static_cast<double>(1 << 20), span / cell)));
    }
    // A few particles far from the rest (thrown out of a silo, say) would
    // stretch the grid until the bound below merges everything into a few
    // huge cells, and the build would go quadratic. Then span the grid over
    // the central 99.8 % of the particles on each axis instead: cell_of()
    // clamps the outliers into the edge cells, and clamping is monotone and
    // never separates two particles by more than one cell, so no pair is lost.
    if (static_cast<double>(dim[0]) * dim[1] * dim[2] > 8.0 * static_cast<double>(n) + 64 && n > 1000) {
      std::vector<double> c(n);
      const std::size_t k_lo = n / 1000, k_hi = n - 1 - n / 1000;
      for (int a = 0; a < 3; ++a) {
        if (box_.axis[a]) continue;  // spans its box
        const std::vector<double>& src = a == 0 ? s.x : a == 1 ? s.y : s.z;
        std::copy(src.begin(), src.begin() + static_cast<std::ptrdiff_t>(n), c.begin());
        std::nth_element(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(k_lo), c.end());
        const double q_lo = c[k_lo];
        std::nth_element(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(k_hi), c.end());
        const double q_hi = c[k_hi];
        lo[a] = std::max(lo[a], q_lo - cell);
        hi[a] = std::min(hi[a], q_hi + cell);
        dim[a] = static_cast<int>(std::max(1.0, std::min(static_cast<double>(1 << 20), (hi[a] - lo[a]) / cell)));
      }
    }
    // Keep the cell count bounded for sparse systems (halving only widens cells).
    while (static_cast<double>(dim[0]) * dim[1] * dim[2] > 8.0 * static_cast<double>(n) + 64) {
      for (int a = 0; a < 3; ++a) dim[a] = std::max(1, dim[a] / 2);
    }
    double inv[3];
    for (int a = 0; a < 3; ++a) inv[a] = dim[a] / std::max(hi[a] - lo[a], 1e-300) * (1.0 - 1e-12);
    auto cell_of = [&](std::size_t k, int* c) {
      const double p[3] = {s.x[k], s.y[k], s.z[k]};
      // clamp in double first: an outlier far outside [lo, hi] must not overflow the int cast
      for (int a = 0; a < 3; ++a)
        c[a] = static_cast<int>(std::min(static_cast<double>(dim[a] - 1), std::max(0.0, (p[a] - lo[a]) * inv[a])));
      // a periodic axis wraps (a particle an exchange hook left past a face
      // belongs to the cell of its image, whose neighbours hold its partners)
      if (box_.any())
        for (int a = 0; a < 3; ++a)
          if (box_.axis[a]) {
            const double u = std::floor((p[a] - lo[a]) * inv[a]);
            if (u >= 0 && u < dim[a]) continue;
            const double m = std::fmod(u, static_cast<double>(dim[a]));
            c[a] = static_cast<int>(m < 0 ? m + dim[a] : m);
          }
    };
    const std::size_t ncell = static_cast<std::size_t>(dim[0]) * dim[1] * dim[2];
    std::vector<uint32_t> start(ncell + 1, 0), order(n);
    {
      std::vector<uint32_t> cell_index(n);
      for (std::size_t k = 0; k < n; ++k) {
        int c[3];
        cell_of(k, c);
        cell_index[k] = static_cast<uint32_t>((static_cast<std::size_t>(c[2]) * dim[1] + c[1]) * dim[0] + c[0]);
        ++start[cell_index[k] + 1];
      }
      for (std::size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
      std::vector<uint32_t> fill(start.begin(), start.end() - 1);
      for (std::size_t k = 0; k < n; ++k) order[fill[cell_index[k]]++] = static_cast<uint32_t>(k);
    }
    // The scan over particles a, in contiguous ranges, one per thread: each
    // range appends to its own near and far arrays, and the ranges are joined
    // in order, so the list is exactly the one-thread list for any thread
    // count (entries in order of a, then of the cell scan).
    // visit(a, b, near) for each pair within the cut-off, b > a.
    // Periodic axes: the neighbour cells wrap around, each visited once
    // (with 2 cells the one below is the one above), and distances are
    // taken to the nearest image.
    double per[3], inv_per[3];
    box_.periods(per, inv_per);
    const bool periodic = box_.any();
    auto for_each_pair = [&](std::size_t a_first, std::size_t a_last, auto&& visit) {
      if (periodic) {
        for_each_periodic_pair(a_first, a_last, dim, start.data(), order.data(), per, inv_per, cell_of, s, h, visit);
        return;
      }
      const double skin = skin_;
      for (std::size_t a = a_first; a < a_last; ++a) {
        int c[3];
        cell_of(a, c);
        const double xa = s.x[a], ya = s.y[a], za = s.z[a], ra = s.radius[a];
        const bool fixed_a = (s.flags[a] & ParticleStore::kFixed) != 0;
        for (int dz = -1; dz <= 1; ++dz) {
          const int cz = c[2] + dz;
          if (cz < 0 || cz >= dim[2]) continue;
          for (int dy = -1; dy <= 1; ++dy) {
            const int cy = c[1] + dy;
            if (cy < 0 || cy >= dim[1]) continue;
            for (int dx = -1; dx <= 1; ++dx) {
              const int cx = c[0] + dx;
              if (cx < 0 || cx >= dim[0]) continue;
              const std::size_t cc = (static_cast<std::size_t>(cz) * dim[1] + cy) * dim[0] + cx;
              for (uint32_t q = start[cc]; q < start[cc + 1]; ++q) {
                const uint32_t b = order[q];
                if (b <= a) continue;
                if (fixed_a && (s.flags[b] & ParticleStore::kFixed) != 0) continue;  // two fixed: never interact
                const double rb = s.radius[b];
                const double ddx = xa - s.x[b], ddy = ya - s.y[b], ddz = za - s.z[b];
                const double cut = ra + rb + skin;
                const double d2 = ddx * ddx + ddy * ddy + ddz * ddz;
                if (d2 < cut * cut) visit(a, b, std::sqrt(d2) - ra - rb < h);
              }
            }
          }
        }
      }
    };
    // Capacity: the last build's size + 5 %, all of it in the first thread's
    // arrays (they become the list), and the last far tier's + 5 % per
    // thread for the far entries. The first build counts first. So no array
    // grows by doubling, which would leave up to half of it unused at the
    // peak.
    std::size_t expect = previous + previous / 20;
    std::size_t expect_far = (previous_far + previous_far / 20) / static_cast<std::size_t>(nt);
    const bool first_build = previous == 0;
    if (first_build) {
      in_ranges(n, [&](std::size_t first, std::size_t last, int t) {
        Part& part = parts[static_cast<std::size_t>(t)];
        for_each_pair(first, last, [&part](std::size_t, uint32_t, bool near) { ++(near ? part.near : part.far); });
      });
      for (const Part& p : parts) expect += p.near + p.far;
    }
    in_ranges(n, [&](std::size_t first, std::size_t last, int t) {
      Part& part = parts[static_cast<std::size_t>(t)];
      const std::size_t want = t == 0 ? expect : first_build ? part.near : expect / static_cast<std::size_t>(nt);
      const std::size_t want_far = first_build ? part.far : expect_far;
      part.i.reserve(want);
      part.j.reserve(want);
      part.fi.reserve(want_far);
      part.fj.reserve(want_far);
      for_each_pair(first, last, [&](std::size_t a, uint32_t b, bool near) {
        auto& ti = near ? part.i : part.fi;
        auto& tj = near ? part.j : part.fj;
        const bool a_leads = s.id[a] < s.id[b];
        if (with_ghosts && (a_leads ? a : b) >= owned) return;  // the lower id is a ghost: its owner computes it
        if (a_leads) { ti.push_back(static_cast<uint32_t>(a)); tj.push_back(b); }
        else { ti.push_back(b); tj.push_back(static_cast<uint32_t>(a)); }
      });
    });
  }
  std::size_t near_total = 0, total = 0;
  for (const Part& p : parts) {
    near_total += p.i.size();
    total += p.i.size() + p.fi.size();
  }
  i = std::move(parts[0].i);
  j = std::move(parts[0].j);
  i.reserve(total);  // no-op unless the list outgrew the estimate
  j.reserve(total);
  for (std::size_t t = 1; t < parts.size(); ++t) {
    Part& p = parts[t];
    i.insert(i.end(), p.i.begin(), p.i.end());
    j.insert(j.end(), p.j.begin(), p.j.end());
    std::vector<uint32_t>().swap(p.i);
    std::vector<uint32_t>().swap(p.j);
  }
  near_size_ = near_total;
  for (Part& p : parts) {
    i.insert(i.end(), p.fi.begin(), p.fi.end());
    j.insert(j.end(), p.fj.begin(), p.fj.end());
    std::vector<uint32_t>().swap(p.fi);
    std::vector<uint32_t>().swap(p.fj);
  }
  // history and flags in their kept capacity, with 5 % headroom when they
  // grow (reserve() keeps the live rows at the front)
  const std::size_t rows = i.size() * stride_;
  if (history.capacity() < rows) history.reserve(rows + rows / 20);
  if (touching.capacity() < i.size()) touching.reserve(i.size() + i.size() / 20);
  history.resize(std::max(rows, live * stride_));
  touching.assign(i.size(), 0);
  if (live > 0 && stride_ > 0) {
    // The new entry of each live row (look-ups in the now read-only table;
    // each entry and each row is written by one thread)...
    constexpr std::uint32_t kNone = LiveHistory::kNone;
    std::vector<std::uint32_t> dest(live, kNone);
    if (same_layout) {
      // Each tier lists its entries in order of a = min(i, j), the particle
      // whose cell scan found the pair: row offsets per tier, then a scan of
      // the pair's row (~10 entries) per live pair.
      std::vector<std::uint32_t> rows_of(2 * (n + 1), 0);
      for (std::size_t k = 0; k < i.size(); ++k) ++rows_of[(k < near_size_ ? 0 : n + 1) + std::min(i[k], j[k]) + 1];
      for (std::size_t t = 0; t < 2; ++t) {
        std::uint32_t* r = rows_of.data() + t * (n + 1);
        r[0] = static_cast<std::uint32_t>(t == 0 ? 0 : near_size_);
        for (std::size_t a = 0; a < n; ++a) r[a + 1] += r[a];
      }
      in_ranges(live, [&](std::size_t first, std::size_t last, int) {
        for (std::size_t row = first; row < last; ++row) {
          const auto [oi, oj] = old_pairs[row];
          const std::size_t a = std::min(oi, oj);
          for (std::size_t t = 0; t < 2 && dest[row] == kNone; ++t) {
            const std::uint32_t* r = rows_of.data() + t * (n + 1);
            for (std::size_t k = r[a]; k < r[a + 1]; ++k)
              if (i[k] == oi && j[k] == oj) {
                dest[row] = static_cast<std::uint32_t>(k);
                touching[k] = 1;
                break;
              }
          }
        }
      });
    } else {
      in_ranges(i.size(), [&](std::size_t first, std::size_t last, int) {
        for (std::size_t k = first; k < last; ++k) {
          const std::uint32_t row = old.find(pair_key(s.id[i[k]], s.id[j[k]]));
          if (row == kNone) continue;
          dest[row] = static_cast<std::uint32_t>(k);
          touching[k] = 1;
        }
      });
    }
    // ...then each row moved there in place, following chains: a row whose
    // place still holds an unmoved live row swaps it out and carries it on.
    // Rows of contacts that left the list (a deleted particle) are dropped.
    std::vector<double> carried(stride_);
    double* const hist = history.data();
    for (std::size_t r = 0; r < live; ++r) {
      if (dest[r] == kNone) continue;
      std::copy_n(hist + r * stride_, stride_, carried.data());
      std::size_t at = dest[r];
      dest[r] = kNone;
      while (at < live && dest[at] != kNone) {
        std::swap_ranges(carried.begin(), carried.end(), hist + at * stride_);
        const std::size_t next = dest[at];
        dest[at] = kNone;
        at = next;
      }
      std::copy_n(carried.data(), stride_, hist + at * stride_);
    }
  }
  // every other entry starts with zero history
  history.resize(rows);
  in_ranges(i.size(), [&](std::size_t first, std::size_t last, int) {
    for (std::size_t k = first; k < last; ++k)
      if (!touching[k]) std::fill_n(history.begin() + static_cast<std::ptrdiff_t>(k * stride_), stride_, 0.0);
  });
  x0_ = s.x; y0_ = s.y; z0_ = s.z;
  built_ids_ = s.id;
  built_size_ = n;
  built_version_ = s.layout_version;
  ++builds_;
}

}  // namespace domel::platform

// ---- checkpoints ----------------------------------------------------------

namespace domel::platform {

namespace {
/// A periodic box as checkpoints keep it: per axis, periodic (0/1), lo, hi.
std::vector<double> periodic_record(const PeriodicBox& b) {
  std::vector<double> v;
  for (int a = 0; a < 3; ++a) v.insert(v.end(), {b.axis[a] ? 1.0 : 0.0, b.axis[a] ? b.lo[a] : 0.0, b.axis[a] ? b.hi[a] : 0.0});
  return v;
}
}  // namespace

void NeighborList::fields(CheckpointFields& f) {
  f("i", i);
  f("j", j);
  f("history", history);
  f("touching", touching);
  f("x0", x0_);
  f("y0", y0_);
  f("z0", z0_);
  f("built_ids", built_ids_);
  std::uint64_t built_size = built_size_, near_size = near_size_, stride = stride_;
  f("builds", builds_);
  f("built_size", built_size);
  f("built_version", built_version_);
  f("near_size", near_size);
  f("stride", stride);
  double skin = skin_;
  f("skin", skin);
  // the growth since the build, kept only while particles grow, so that a
  // checkpoint of a run without growing particles keeps its earlier layout
  if (f.loading() ? f.reader().has(f.prefix() + "grown") : grown_ != 0.0) f("grown", grown_);
  std::vector<double> periodic = periodic_record(box_);
  f("periodic", periodic);
  if (!f.loading()) return;
  const ArchiveReader& r = f.reader();
  const std::string& p = f.prefix();
  if (stride != stride_)
    r.fail(p + "stride", "holds contact histories of " + std::to_string(stride) +
                             " values per pair; this scenario's contact model keeps " + std::to_string(stride_));
  if (skin != skin_) r.fail(p + "skin", "was written with another neighbour-list skin");
  if (periodic != periodic_record(box_))
    r.fail(p + "periodic", "was written with other periodic boundaries (subdomains[].periodic)");
  built_size_ = static_cast<std::size_t>(built_size);
  near_size_ = static_cast<std::size_t>(near_size);
  if (j.size() != i.size() || touching.size() != i.size() || history.size() != i.size() * stride_ ||
      near_size_ > i.size())
    r.fail(p + "i", "holds a neighbour list whose arrays disagree in length");
}

void NeighborList::save(ArchiveWriter& w, const std::string& p) const {
  save_fields(w, p, [&](CheckpointFields& f) { const_cast<NeighborList*>(this)->fields(f); });
}

void NeighborList::load(const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f); });
}

}  // namespace domel::platform
