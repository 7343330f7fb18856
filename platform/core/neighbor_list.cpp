// SPDX-License-Identifier: MIT
// Cell-list construction of the Verlet list and history carry-over.
#include "core/neighbor_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace domel::platform {

namespace {
inline std::uint64_t pair_key(std::uint64_t a, std::uint64_t b) {
  // ids below 2^32 in practice; mix both halves so larger ids still hash well
  return (a << 32) ^ b ^ (a >> 32);
}
}  // namespace

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

void NeighborList::build(const ParticleStore& s, ThreadPool* pool) {
  const std::size_t n = s.size();
  // Keep only the live history (pairs in contact, ~1-2 per particle), keyed by
  // (id_i, id_j), and release the old list before the new one is built: the
  // build's peak memory is then the new list plus the contacts, not two lists
  // (docs/performance.md, memory).
  std::size_t live = 0;
  for (std::size_t k = 0; k < i.size(); ++k) live += touching[k] ? 1 : 0;
  std::unordered_map<std::uint64_t, std::size_t> old;
  old.reserve(live);
  std::vector<double> old_history;
  old_history.reserve(live * stride_);
  for (std::size_t k = 0; k < i.size(); ++k) {
    if (!touching[k]) continue;
    old.emplace(pair_key(built_ids_[i[k]], built_ids_[j[k]]), old_history.size() / std::max<uint32_t>(stride_, 1));
    old_history.insert(old_history.end(), history.begin() + static_cast<std::ptrdiff_t>(k * stride_),
                       history.begin() + static_cast<std::ptrdiff_t>((k + 1) * stride_));
  }
  const std::size_t previous = i.size();
  for (auto* v : {&i, &j}) std::vector<uint32_t>().swap(*v);
  std::vector<double>().swap(history);
  std::vector<uint8_t>().swap(touching);
  // Tiers (see near_size()): near entries go to i/j, far ones to fi/fj, each in
  // build order; far is appended after the cell loop.
  const double h = near_gap();
  struct Part {
    std::vector<uint32_t> i, j, fi, fj;
  };
  const int nt = pool != nullptr && n >= 4096 ? pool->size() : 1;
  std::vector<Part> parts(static_cast<std::size_t>(nt));

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
    const double cell = 2.0 * rmax + skin_;
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
    };
    const std::size_t ncell = static_cast<std::size_t>(dim[0]) * dim[1] * dim[2];
    std::vector<uint32_t> start(ncell + 1, 0), order(n), cell_index(n);
    for (std::size_t k = 0; k < n; ++k) {
      int c[3];
      cell_of(k, c);
      cell_index[k] = static_cast<uint32_t>((static_cast<std::size_t>(c[2]) * dim[1] + c[1]) * dim[0] + c[0]);
      ++start[cell_index[k] + 1];
    }
    for (std::size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
    {
      std::vector<uint32_t> fill(start.begin(), start.end() - 1);
      for (std::size_t k = 0; k < n; ++k) order[fill[cell_index[k]]++] = static_cast<uint32_t>(k);
    }
    // The scan over particles a, in contiguous ranges, one per thread: each
    // range appends to its own near and far arrays, and the ranges are joined
    // in order, so the list is exactly the one-thread list for any thread
    // count (entries in order of a, then of the cell scan).
    // size from the last build (+5 %) rather than growing by doubling
    const std::size_t expect = (previous > 0 ? previous + previous / 20 : 4 * n) / static_cast<std::size_t>(nt);
    auto scan = [&](std::size_t a_first, std::size_t a_last, Part& part) {
    part.i.reserve(expect);
    part.j.reserve(expect);
    for (std::size_t a = a_first; a < a_last; ++a) {
      int c[3];
      cell_of(a, c);
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
              if ((s.flags[a] & s.flags[b] & ParticleStore::kFixed) != 0) continue;  // two fixed: never interact
              const double ddx = s.x[a] - s.x[b], ddy = s.y[a] - s.y[b], ddz = s.z[a] - s.z[b];
              const double cut = s.radius[a] + s.radius[b] + skin_;
              const double d2 = ddx * ddx + ddy * ddy + ddz * ddz;
              if (d2 < cut * cut) {
                const bool near = std::sqrt(d2) - s.radius[a] - s.radius[b] < h;
                auto& ti = near ? part.i : part.fi;
                auto& tj = near ? part.j : part.fj;
                if (s.id[a] < s.id[b]) { ti.push_back(static_cast<uint32_t>(a)); tj.push_back(b); }
                else { ti.push_back(b); tj.push_back(static_cast<uint32_t>(a)); }
              }
            }
          }
        }
      }
    }
    };
    if (nt == 1) {
      scan(0, n, parts[0]);
    } else {
      pool->for_range(n, [&](std::size_t first, std::size_t last, int t) {
        scan(first, last, parts[static_cast<std::size_t>(t)]);
      });
    }
  }
  std::size_t near_total = 0, total = 0;
  for (const Part& p : parts) {
    near_total += p.i.size();
    total += p.i.size() + p.fi.size();
  }
  i.reserve(total);
  j.reserve(total);
  for (Part& p : parts) {
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
  history.assign(i.size() * stride_, 0.0);
  touching.assign(i.size(), 0);
  if (!old.empty() && stride_ > 0) {
    // look-ups in the (now read-only) map, each entry written by one thread
    auto carry = [&](std::size_t first, std::size_t last) {
      for (std::size_t k = first; k < last; ++k) {
        auto it = old.find(pair_key(s.id[i[k]], s.id[j[k]]));
        if (it == old.end()) continue;
        std::copy_n(old_history.begin() + static_cast<std::ptrdiff_t>(it->second * stride_), stride_,
                    history.begin() + static_cast<std::ptrdiff_t>(k * stride_));
        touching[k] = 1;
      }
    };
    if (nt == 1) carry(0, i.size());
    else pool->for_range(i.size(), [&](std::size_t first, std::size_t last, int) { carry(first, last); });
  }
  x0_ = s.x; y0_ = s.y; z0_ = s.z;
  built_ids_ = s.id;
  built_size_ = n;
  built_version_ = s.layout_version;
  ++builds_;
}

}  // namespace domel::platform
