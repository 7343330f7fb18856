// SPDX-License-Identifier: MIT
// Shared geometry of rolling-resistance kernels: the rolling part of the
// relative angular velocity, omega_r = omega_rel - (omega_rel . n) n
// (docs/physics.md §2: the twisting part about n is left to twisting models).
#pragma once

#include <domel/sdk/abi.h>

namespace domel::plugins::rolling {

struct Vec3 {
  double x, y, z;
};

inline Vec3 rolling_velocity(const domel_contact_batch_v1& b, uint32_t c) {
  const double wn = b.wx[c] * b.nx[c] + b.wy[c] * b.ny[c] + b.wz[c] * b.nz[c];
  return {b.wx[c] - wn * b.nx[c], b.wy[c] - wn * b.ny[c], b.wz[c] - wn * b.nz[c]};
}

/// The normal force that sets the torque cap: the elastic part, never
/// negative. LIGGGHTS' cdt does the same (k_n delta_n, docs/physics.md §2.1);
/// its epsd caps with the total |F_n| (elastic + dashpot). We use the elastic
/// part for both built-ins: the dashpot part changes sign with the normal
/// velocity and would make the cap, and so the torque, jump during loading
/// and unloading; at rest the two agree.
inline double cap_force(const domel_contact_batch_v1& b, uint32_t c) {
  return b.fn_elastic[c] > 0.0 ? b.fn_elastic[c] : 0.0;
}

}  // namespace domel::plugins::rolling
