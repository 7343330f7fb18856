// SPDX-License-Identifier: MIT
// A subdomain's statistics, memory and contact counts (diagnostics.hpp).
#include "subdomain/diagnostics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace domel::platform {

SubdomainStats kinetic_stats(const ParticleStore& s, std::size_t count) {
  SubdomainStats st;
  const std::size_t n = std::min(count, s.size());
  st.particles = n;
  double sum_w = 0, sum_slow = 0;
  std::size_t slow = 0;
  std::vector<double> speeds;
  speeds.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (s.fixed(k)) {
      ++st.fixed;
      continue;
    }
    st.kinetic_translational += 0.5 * s.mass[k] * (s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k] + s.vz[k] * s.vz[k]);
    const double w2 = s.wx[k] * s.wx[k] + s.wy[k] * s.wy[k] + s.wz[k] * s.wz[k];
    st.kinetic_rotational += 0.5 * w2 / s.inv_inertia[k];
    const double speed = std::sqrt(w2);
    speeds.push_back(speed);
    sum_w += speed;
    if (speed < 1.0) {
      sum_slow += speed;
      ++slow;
    }
  }
  if (!speeds.empty()) {
    st.mean_angular_speed = sum_w / speeds.size();
    const std::size_t mid = speeds.size() / 2;
    std::nth_element(speeds.begin(), speeds.begin() + mid, speeds.end());
    double median = speeds[mid];
    if (speeds.size() % 2 == 0) median = 0.5 * (median + *std::max_element(speeds.begin(), speeds.begin() + mid));
    st.median_angular_speed = median;
  }
  if (slow) st.trimmed_mean_angular_speed = sum_slow / slow;
  return st;
}

MemoryUse list_memory(const ParticleStore& s, const NeighborList& list, const std::vector<WallNeighbors>& walls) {
  MemoryUse m;
  m.particles = s.bytes();
  m.neighbor_lists = list.bytes_without_history();
  m.contact_history = list.history_bytes();
  for (const WallNeighbors& w : walls) {
    m.neighbor_lists += w.bytes_without_history();
    m.contact_history += w.history_bytes();
  }
  return m;
}

void count_contacts(ParticleStore& s, const NeighborList& list, std::size_t screened,
                    const std::vector<WallNeighbors>& wall_lists, const std::vector<WallPrimitive>& walls,
                    double forces_time) {
  s.contacts.assign(s.size(), 0u);
  if (!list.layout_stale(s))
    for (std::size_t e = 0; e < screened; ++e)
      if (list.touching[e]) {
        ++s.contacts[list.i[e]];
        ++s.contacts[list.j[e]];
      }
  for (std::size_t w = 0; w < wall_lists.size(); ++w) {
    if (!walls[w].active(forces_time)) continue;
    const WallNeighbors& wl = wall_lists[w];
    for (std::size_t e = 0; e < wl.particle.size(); ++e)
      if (wl.touching[e] && wl.particle[e] < s.size()) ++s.contacts[wl.particle[e]];
  }
}

InitialOverlaps find_initial_overlaps(const ParticleStore& s, double limit, const PeriodicBox& box) {
  InitialOverlaps out;
  const std::size_t n = s.size();
  if (n < 2) return out;
  double rmax = 0, lo[3] = {s.x[0], s.y[0], s.z[0]}, hi[3] = {s.x[0], s.y[0], s.z[0]};
  for (std::size_t k = 0; k < n; ++k) {
    rmax = std::max(rmax, s.radius[k]);
    lo[0] = std::min(lo[0], s.x[k]);
    lo[1] = std::min(lo[1], s.y[k]);
    lo[2] = std::min(lo[2], s.z[k]);
    hi[0] = std::max(hi[0], s.x[k]);
    hi[1] = std::max(hi[1], s.y[k]);
    hi[2] = std::max(hi[2], s.z[k]);
  }
  if (!(rmax > 0) || !std::isfinite(lo[0] + lo[1] + lo[2])) return out;
  // hash the cells (x, y, z) -> particles: a sparse pour or a tall silo needs no dense grid.
  // A cell is at least the largest diameter (a particle's partners lie in the 27 cells
  // around its own) and at least a 1e-9th of the particles' extent, so that radii of
  // 1e-300 m give cell indices of at most 1e9, not infinite ones (run-time fuzzer).
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const double cell = std::max(2.0 * rmax, std::isfinite(extent) ? 1e-9 * extent : 0.0);
  using Cell = std::array<long long, 3>;
  struct CellHash {
    std::size_t operator()(const Cell& c) const {
      return static_cast<std::size_t>((static_cast<std::uint64_t>(c[0]) * 73856093ull) ^
                                      (static_cast<std::uint64_t>(c[1]) * 19349663ull) ^
                                      (static_cast<std::uint64_t>(c[2]) * 83492791ull));
    }
  };
  auto key = [](long long i, long long j, long long k) { return Cell{i, j, k}; };
  auto coord = [&](double v, int a) {
    // clamped (monotonically, so neighbouring cells stay neighbours) to what a long long holds;
    // NaN (an extent beyond a double) goes to the last cell
    const double t = std::floor((v - lo[a]) / cell);
    return static_cast<long long>(t < -1e15 ? -1e15 : t < 1e15 ? t : 1e15);
  };
  std::unordered_map<Cell, std::vector<std::uint32_t>, CellHash> cells;
  cells.reserve(n);
  for (std::size_t k = 0; k < n; ++k)
    cells[key(coord(s.x[k], 0), coord(s.y[k], 1), coord(s.z[k], 2))].push_back(static_cast<std::uint32_t>(k));
  std::vector<InitialOverlaps::Pair> above;
  // periodic axes: the images of each particle one period away on either side
  std::vector<std::array<double, 3>> shifts = {{0.0, 0.0, 0.0}};
  for (const auto& sh : box.image_shifts())
    shifts.push_back({sh[0] * box.length(0), sh[1] * box.length(1), sh[2] * box.length(2)});
  for (std::size_t p = 0; p < n; ++p)
    for (const auto& shift : shifts) {
    const double xp = s.x[p] + shift[0], yp = s.y[p] + shift[1], zp = s.z[p] + shift[2];
    const long long ci = coord(xp, 0), cj = coord(yp, 1), ck = coord(zp, 2);
    for (long long di = -1; di <= 1; ++di)
      for (long long dj = -1; dj <= 1; ++dj)
        for (long long dk = -1; dk <= 1; ++dk) {
          const auto it = cells.find(key(ci + di, cj + dj, ck + dk));
          if (it == cells.end()) continue;
          for (std::uint32_t q : it->second) {
            if (q <= p) continue;  // each pair once: q sits in one cell, visited once from p
            const double dx = xp - s.x[q], dy = yp - s.y[q], dz = zp - s.z[q];
            const double rsum = s.radius[p] + s.radius[q];
            const double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 >= rsum * rsum) continue;
            const double ratio = (rsum - std::sqrt(d2)) / rsum;
            ++out.pairs;
            if (ratio > out.worst) {
              out.worst = ratio;
              out.worst_ids[0] = s.id[p];
              out.worst_ids[1] = s.id[q];
            }
            if (ratio > limit) above.push_back({s.id[p], s.id[q], ratio});
          }
        }
  }
  out.above_count = above.size();
  std::sort(above.begin(), above.end(), [](const auto& a, const auto& b) { return a.ratio > b.ratio; });
  if (above.size() > 5) above.resize(5);
  out.above = std::move(above);
  return out;
}

}  // namespace domel::platform
