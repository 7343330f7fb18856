// SPDX-License-Identifier: MIT
// How far a sphere reaches into the walls, outside the step: for placing new
// particles (start-up insertions and pours keep clear of every wall) and for
// the start-up check of the particles a run begins with (issue 41). The
// distances are the contact kernels' own (WallPrimitive::gap, and the
// closest point of a mesh's triangles), so "clear" here means "no wall
// contact at the first step".
#pragma once

#include "geometry/triangle_mesh.hpp"
#include "geometry/wall.hpp"

#include <domel/sdk/abi.h>

#include <cstddef>
#include <vector>

namespace domel::platform {

/// The walls that act at one time, placed there (a moving wall at its pose
/// then), asked about spheres of radius at most `r_max`. With r_max 0 (a
/// question about points: covers()) meshes are left out: a mesh acts from
/// both sides and holds no point. One thread at a time (overlap() keeps a
/// scratch list).
class WallClearance {
 public:
  WallClearance(const std::vector<WallPrimitive>& walls, double t, double r_max);

  /// The deepest overlap of the sphere (centre p, radius r <= r_max) with
  /// these walls: r minus the centre's distance from the surface on the
  /// particle side (more than r for a centre behind a plane or outside a
  /// container's mantle); 0 when it touches none. `which` gets the index
  /// (into the walls given) of the deepest.
  double overlap(const double p[3], double r, std::size_t* which = nullptr) const;

  bool clear(const double p[3], double r) const { return overlap(p, r) <= 0.0; }

  /// True when no point of the region (sampled on a grid of 17 points per
  /// axis over its box, the box's faces included) lies on the particles'
  /// side of every wall: a region wholly inside the walls, where nothing can
  /// be placed. `which` gets the wall (index into the walls given) that
  /// holds the most of the samples.
  bool covers(const domel_region_v1& region, std::size_t* which = nullptr) const;
  bool empty() const { return walls_.empty(); }

 private:
  struct Placed {
    WallPrimitive wall;
    std::size_t index;
    TriangleGrid grid;  ///< meshes: the triangles near a point
  };
  std::vector<Placed> walls_;
  mutable std::vector<uint32_t> query_;
};

}  // namespace domel::platform
