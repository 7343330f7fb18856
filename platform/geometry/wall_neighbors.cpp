// SPDX-License-Identifier: MIT
// Building wall candidate lists and carrying their history over.
#include "geometry/wall_neighbors.hpp"

#include "core/archive.hpp"
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace domel::platform {

void WallNeighbors::clear() {
  particle.clear();
  particle_id.clear();
  triangle.clear();
  history.clear();
  touching.clear();
  built = false;
}

PairHistories WallNeighbors::live_histories(uint32_t stride) const {
  PairHistories h;
  h.stride = stride;
  for (std::size_t k = 0; k < particle.size(); ++k) {
    if (!touching[k]) continue;
    h.id_i.push_back(particle_id[k]);
    h.id_j.push_back(triangle.empty() ? 0 : triangle[k]);
    h.values.insert(h.values.end(), history.begin() + static_cast<std::ptrdiff_t>(k * stride),
                    history.begin() + static_cast<std::ptrdiff_t>((k + 1) * stride));
  }
  return h;
}

void WallNeighbors::adopt_histories(PairHistories h) {
  // what build() reads of the last list: the live rows' ids, triangles and history
  const std::size_t m = h.size();
  particle.assign(m, 0);  // no index of this store: only the ids are looked up
  particle_id = std::move(h.id_i);
  triangle.resize(m);
  for (std::size_t k = 0; k < m; ++k) triangle[k] = static_cast<uint32_t>(h.id_j[k]);
  touching.assign(m, 1);
  history = std::move(h.values);
}

void WallNeighbors::build(const ParticleStore& s, const WallPrimitive& w, double skin, uint32_t stride, bool active,
                          std::size_t count) {
  if (!active) {
    clear();
    return;
  }
  const bool is_mesh = w.shape == WallPrimitive::Shape::mesh;
  const std::size_t n = std::min(count, s.size());
  // live contacts by (particle id, triangle)
  using Key = std::pair<std::uint64_t, uint32_t>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const { return std::hash<std::uint64_t>()(k.first * 0x9E3779B97F4A7C15ull ^ k.second); }
  };
  std::unordered_map<Key, std::size_t, KeyHash> old;
  auto key = [&](std::size_t k) { return Key{particle_id[k], is_mesh ? triangle[k] : 0u}; };
  std::vector<double> old_history;
  old_history.swap(history);
  for (std::size_t k = 0; k < particle.size(); ++k)
    if (touching[k]) old.emplace(key(k), k);
  particle.clear();
  particle_id.clear();
  triangle.clear();
  touching.clear();
  if (is_mesh) {
    double rmax = 0;
    for (double r : s.radius) rmax = std::max(rmax, r);
    const double reach = rmax + skin;
    if (!grid_valid_ || reach > grid_reach_ || w.moving) {
      grid_.build(w.verts, *w.mesh, reach);
      grid_valid_ = true;
      grid_reach_ = reach;
    }
    const TriangleMesh& m = *w.mesh;
    for (std::size_t k = 0; k < n; ++k) {
      if (s.fixed(k)) continue;  // see below
      query_.clear();
      grid_.query(s.x[k], s.y[k], s.z[k], query_);
      if (query_.empty()) continue;
      std::sort(query_.begin(), query_.end());
      const double p[3] = {s.x[k], s.y[k], s.z[k]};
      const double lim = s.radius[k] + skin;
      for (const uint32_t t : query_) {
        double q[3];
        closest_on_triangle(p, &w.verts[3 * m.tri[3 * t]], &w.verts[3 * m.tri[3 * t + 1]],
                            &w.verts[3 * m.tri[3 * t + 2]], q);
        const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        if (dx * dx + dy * dy + dz * dz < lim * lim) {
          particle.push_back(static_cast<uint32_t>(k));
          triangle.push_back(t);
        }
      }
    }
  } else {
    // A fixed particle never moves, so a wall's force on it changes nothing,
    // and a fixed floor laid under a container (the collapse tests' rough
    // floor spans the box, the cylinder stands on it) would otherwise count
    // as contacts "inside" the cylinder's wall, overlapping it by up to 27
    // diameters in the diagnostics. As two fixed particles never interact.
    for (std::size_t k = 0; k < n; ++k)
      if (!s.fixed(k) && w.near(s.x[k], s.y[k], s.z[k], s.radius[k] + skin))
        particle.push_back(static_cast<uint32_t>(k));
  }
  for (const uint32_t k : particle) particle_id.push_back(s.id[k]);
  history.assign(particle.size() * stride, 0.0);
  touching.assign(particle.size(), 0);
  if (!old.empty() && stride > 0) {
    for (std::size_t k = 0; k < particle.size(); ++k) {
      auto it = old.find(key(k));
      if (it == old.end()) continue;
      std::copy_n(old_history.begin() + it->second * stride, stride, history.begin() + k * stride);
      touching[k] = 1;
    }
  }
  built = true;
}

}  // namespace domel::platform

// ---- checkpoints ----------------------------------------------------------

namespace domel::platform {

void WallNeighbors::fields(CheckpointFields& f) {
  f("particle", particle);
  f("particle_id", particle_id);
  f("triangle", triangle);
  f("history", history);
  f("touching", touching);
  f("built_time", built_time);
  f("built", built);
  if (!f.loading()) return;
  grid_valid_ = false;
  if (particle_id.size() != particle.size() || touching.size() != particle.size() ||
      (!triangle.empty() && triangle.size() != particle.size()))
    f.reader().fail(f.prefix() + "particle", "holds a wall candidate list whose arrays disagree in length");
}

void WallNeighbors::save(ArchiveWriter& w, const std::string& p) const {
  save_fields(w, p, [&](CheckpointFields& f) { const_cast<WallNeighbors*>(this)->fields(f); });
}

void WallNeighbors::load(const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f); });
}

}  // namespace domel::platform
