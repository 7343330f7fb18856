// SPDX-License-Identifier: MIT
// Shared definitions of rolling-resistance kernels (docs/physics.md §2):
// the rolling part of the relative angular velocity,
//   omega_r = omega_rel - (omega_rel . n) n
// (the twisting part about n is left to twisting models), and the force that
// caps the rolling torque, the elastic normal force clamped at 0. They take
// values, not the batch, so that the kernels' loops over restrict-qualified
// arrays inline them and vectorise.
#pragma once

namespace domel::plugins::rolling {

struct Vec3 {
  double x, y, z;
};

inline Vec3 rolling_velocity(double wx, double wy, double wz, double nx, double ny, double nz) {
  const double wn = wx * nx + wy * ny + wz * nz;
  return {wx - wn * nx, wy - wn * ny, wz - wn * nz};
}

inline double cap_force(double fn_elastic) { return fn_elastic > 0.0 ? fn_elastic : 0.0; }

}  // namespace domel::plugins::rolling
