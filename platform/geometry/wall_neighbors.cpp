// SPDX-License-Identifier: MIT
// Building wall candidate lists and carrying their history over.
#include "geometry/wall_neighbors.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace domel::platform {

void WallNeighbors::build(const ParticleStore& s, const WallPrimitive& w, double skin, uint32_t stride) {
  if (!std::isinf(w.remove_at) && w.remove_at <= 0.0) {  // removed from the start
    *this = WallNeighbors{};
    return;
  }
  std::unordered_map<std::uint64_t, std::size_t> old;
  std::vector<double> old_history;
  old_history.swap(history);
  for (std::size_t k = 0; k < particle.size(); ++k)
    if (touching[k]) old.emplace(particle_id[k], k);
  particle.clear();
  particle_id.clear();
  touching.clear();
  for (std::size_t k = 0; k < s.size(); ++k) {
    double d, nx, ny, nz;
    if (!w.gap(s.x[k], s.y[k], s.z[k], d, nx, ny, nz)) {
      // outside a mantle's extent now, but may enter within the skin
      if (w.shape == WallPrimitive::Shape::cylinder_inside) {
        const double along = (w.axis == 0 ? s.x[k] : w.axis == 1 ? s.y[k] : s.z[k]);
        if (along < w.lo - s.radius[k] - skin || along > w.hi + s.radius[k] + skin) continue;
        particle.push_back(static_cast<uint32_t>(k));
      }
      continue;
    }
    if (d < s.radius[k] + skin) particle.push_back(static_cast<uint32_t>(k));
  }
  for (const uint32_t k : particle) particle_id.push_back(s.id[k]);
  history.assign(particle.size() * stride, 0.0);
  touching.assign(particle.size(), 0);
  if (!old.empty() && stride > 0) {
    for (std::size_t k = 0; k < particle.size(); ++k) {
      auto it = old.find(particle_id[k]);
      if (it == old.end()) continue;
      std::copy_n(old_history.begin() + it->second * stride, stride, history.begin() + k * stride);
      touching[k] = 1;
    }
  }
}

}  // namespace domel::platform
