// SPDX-License-Identifier: MIT
// The ABI's view of a subdomain's particles (abi.h, domel_particles_v1), for
// the controller and fluid-coupler families: the read-only arrays point into
// the store; the cell indices and the force arrays the plugin adds to are the
// caller's.
#pragma once

#include "core/particle_store.hpp"

#include <domel/sdk/abi.h>

namespace domel::platform {

inline domel_particles_v1 particles_view(ParticleStore& s, const uint32_t* cell, double* fx, double* fy, double* fz) {
  domel_particles_v1 v{};
  v.struct_size = sizeof v;
  v.n = s.size();
  v.id = s.id.data();
  v.x = s.x.data(), v.y = s.y.data(), v.z = s.z.data();
  v.vx = s.vx.data(), v.vy = s.vy.data(), v.vz = s.vz.data();
  v.mass = s.mass.data();
  v.radius = s.radius.data();
  v.cell = cell;
  v.fx = fx, v.fy = fy, v.fz = fz;
  return v;
}

}  // namespace domel::platform
