// SPDX-License-Identifier: MIT
// A subdomain's statistics, memory and contact counts (diagnostics.hpp).
#include "subdomain/diagnostics.hpp"

#include <algorithm>
#include <cmath>

namespace domel::platform {

SubdomainStats kinetic_stats(const ParticleStore& s) {
  SubdomainStats st;
  st.particles = s.size();
  double sum_w = 0, sum_slow = 0;
  std::size_t slow = 0;
  std::vector<double> speeds;
  speeds.reserve(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) {
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

}  // namespace domel::platform
