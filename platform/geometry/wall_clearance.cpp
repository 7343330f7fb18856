// SPDX-License-Identifier: MIT
#include "geometry/wall_clearance.hpp"

#include "geometry/region.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace domel::platform {

WallClearance::WallClearance(const std::vector<WallPrimitive>& walls, double t, double r_max) {
  for (std::size_t w = 0; w < walls.size(); ++w) {
    if (!walls[w].active(t)) continue;
    Placed p{walls[w], w, {}};
    p.wall.place(walls[w], t);
    if (p.wall.shape == WallPrimitive::Shape::mesh) {
      // a mesh acts from both sides: it overlaps a sphere, never holds a point (r_max 0: nothing to ask)
      if (!p.wall.mesh || p.wall.verts.empty() || !(r_max > 0)) continue;
      // the grid's cells are at least twice its reach: a flat mesh asked about tiny spheres would
      // otherwise get cells of atoms across its whole extent
      double lo[3], hi[3];
      for (int a = 0; a < 3; ++a) lo[a] = hi[a] = p.wall.verts[a];
      for (std::size_t v = 0; v < p.wall.verts.size(); v += 3)
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], p.wall.verts[v + a]);
          hi[a] = std::max(hi[a], p.wall.verts[v + a]);
        }
      const double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
      p.grid.build(p.wall.verts, *p.wall.mesh, std::max(r_max, 1e-3 * diag));
    }
    walls_.push_back(std::move(p));
  }
}

double WallClearance::overlap(const double p[3], double r, std::size_t* which) const {
  double deepest = 0.0;
  for (const Placed& pl : walls_) {
    const WallPrimitive& w = pl.wall;
    double d = 0.0;
    bool touches = false;
    if (w.shape == WallPrimitive::Shape::mesh) {
      // the closest point of the triangles within reach (a mesh acts from both sides)
      query_.clear();
      pl.grid.query(p[0], p[1], p[2], query_);
      double best = INFINITY;
      for (uint32_t t : query_) {
        const uint32_t* v = &w.mesh->tri[3 * t];
        double q[3];
        closest_on_triangle(p, &w.verts[3 * v[0]], &w.verts[3 * v[1]], &w.verts[3 * v[2]], q);
        best = std::min(best, std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                        (p[2] - q[2]) * (p[2] - q[2])));
      }
      touches = std::isfinite(best);
      d = best;
    } else {
      double nx, ny, nz;
      touches = w.gap(p[0], p[1], p[2], d, nx, ny, nz);
    }
    if (touches && r - d > deepest) {
      deepest = r - d;
      if (which) *which = pl.index;
    }
  }
  return deepest;
}

bool WallClearance::covers(const domel_region_v1& region, std::size_t* which) const {
  if (walls_.empty()) return false;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const bool along = region.shape == 1 || a == static_cast<int>(region.axis);
    lo[a] = along ? region.lo[a] : region.center[a] - region.radius;
    hi[a] = along ? region.hi[a] : region.center[a] + region.radius;
  }
  constexpr int kSamples = 17;
  std::map<std::size_t, std::size_t> holds;  // wall -> samples inside it
  for (int i = 0; i < kSamples; ++i)
    for (int j = 0; j < kSamples; ++j)
      for (int k = 0; k < kSamples; ++k) {
        const int ijk[3] = {i, j, k};
        double p[3];
        for (int a = 0; a < 3; ++a) p[a] = lo[a] + (hi[a] - lo[a]) * ijk[a] / (kSamples - 1.0);
        if (!region_contains(region, p[0], p[1], p[2])) continue;
        std::size_t w = 0;
        if (overlap(p, 0.0, &w) <= 0.0) return false;  // a place on the particles' side of every wall
        ++holds[w];
      }
  if (holds.empty()) return false;  // a degenerate region: nothing sampled, nothing to say
  if (which)
    *which = std::max_element(holds.begin(), holds.end(), [](const auto& a, const auto& b) {
               return a.second < b.second;
             })->first;
  return true;
}

}  // namespace domel::platform
