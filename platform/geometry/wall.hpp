// SPDX-License-Identifier: MIT
// Wall primitives. Scenario walls (plane, box container, cylinder container)
// are expanded into primitives: an infinite plane, or the inside of a finite
// axis-aligned cylinder mantle. A primitive answers one question per
// particle: how far is the sphere centre from the surface (on the particle
// side), and along which unit normal (from the wall towards the centre).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

namespace domel::platform {

struct WallPrimitive {
  enum class Shape { plane, cylinder_inside };
  Shape shape = Shape::plane;
  std::string name;          ///< e.g. "container.zmin"
  std::size_t material = 0;  ///< index into the scenario's materials
  // plane: a point on it and the unit normal pointing to the particles' side
  double p[3] = {0, 0, 0};
  double n[3] = {0, 0, 1};
  // cylinder mantle, particles inside: axis 0/1/2, axis passes through c,
  // radius, extent [lo, hi] along the axis (no contact outside it)
  int axis = 2;
  double c[3] = {0, 0, 0};
  double radius = 0.0;
  double lo = 0.0, hi = 0.0;
  /// simulated time from which the wall is gone (an outlet plug, a lifted cylinder)
  double remove_at = std::numeric_limits<double>::infinity();

  /// Distance `d` of the point from the surface (positive on the particle
  /// side) and unit normal (nx, ny, nz) from the wall to the point. Returns
  /// false when the point has no defined contact (outside a mantle's extent).
  bool gap(double x, double y, double z, double& d, double& nx, double& ny, double& nz) const {
    if (shape == Shape::plane) {
      d = (x - p[0]) * n[0] + (y - p[1]) * n[1] + (z - p[2]) * n[2];
      nx = n[0]; ny = n[1]; nz = n[2];
      return true;
    }
    const double q[3] = {x - c[0], y - c[1], z - c[2]};
    const double along = (axis == 0 ? x : axis == 1 ? y : z);
    if (along < lo || along > hi) return false;
    double rx = q[0], ry = q[1], rz = q[2];
    if (axis == 0) rx = 0; else if (axis == 1) ry = 0; else rz = 0;
    const double rho = std::sqrt(rx * rx + ry * ry + rz * rz);
    if (rho <= 0.0) return false;
    d = radius - rho;
    nx = -rx / rho; ny = -ry / rho; nz = -rz / rho;
    return true;
  }
};

}  // namespace domel::platform
