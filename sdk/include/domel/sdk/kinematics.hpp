// SPDX-License-Identifier: MIT
//
// domel SDK — contact kinematics every rolling-resistance model needs,
// header-only. They take and return values, not the batch, so that a
// kernel's loop over restrict-qualified arrays inlines them and vectorises
// (no branch, no call, no aliasing question). Formulas: docs/physics.md §2
// (rolling part of the relative angular velocity) and §3.4 (the stored
// rolling angle or spring torque carried into the current tangent plane).
#pragma once

#include <cmath>

namespace domel::sdk {

struct Vec3 {
  double x, y, z;
};

/// The rolling part of the relative angular velocity w = omega_i - omega_j
/// (the batch's wx, wy, wz) at a contact with unit normal n:
///   omega_r = w - (w . n) n
/// The twisting part (w . n) n is left to twisting models (physics.md §2).
inline Vec3 rolling_velocity(double wx, double wy, double wz, double nx, double ny, double nz) {
  const double wn = wx * nx + wy * ny + wz * nz;
  return {wx - wn * nx, wy - wn * ny, wz - wn * nz};
}

/// A history vector h (a rolling angle, a spring torque) projected onto the
/// tangent plane of the current unit normal n and scaled back to its former
/// length, so that it never acquires a twisting component and the contact's
/// rotation does not shrink it (physics.md §3.4):
///   t = h - (h . n) n,   result = t |h| / |t|   (t = 0: returned as is)
/// The length ratio is one square root of the ratio of the squares,
/// sqrt(|h|^2 / |t|^2), not |h| / |t| with two: the rolling kernels' square
/// roots were most of their time (docs/performance.md).
inline Vec3 tangent_keep_length(double hx, double hy, double hz, double nx, double ny, double nz) {
  const double len0_sq = hx * hx + hy * hy + hz * hz;
  const double proj = hx * nx + hy * ny + hz * nz;
  const double tx = hx - proj * nx, ty = hy - proj * ny, tz = hz - proj * nz;
  const double len1_sq = tx * tx + ty * ty + tz * tz;
  const double keep = len1_sq > 0.0 ? std::sqrt(len0_sq / len1_sq) : 1.0;
  return {tx * keep, ty * keep, tz * keep};
}

/// The force that caps a rolling torque: the given normal force clamped at
/// 0, so that a net attractive contact exerts no rolling resistance.
inline double cap_force(double fn) { return fn > 0.0 ? fn : 0.0; }

}  // namespace domel::sdk
