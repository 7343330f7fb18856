// SPDX-License-Identifier: MIT
// Velocity-Verlet integration of a particle store and the body-force list.
//
// The body forces are a list: gravity (m g, stored once, here) and the
// store's per-particle external force (ParticleStore::ext_f*, written by
// controllers and fluid couplers), when enabled. Every force reset goes
// through it — the step's own, set-up's, and that of particles added
// between steps — so no other code writes f = m g.
//
// The passes are free functions over index ranges, so a thread runs each on
// its part of the store:
//   kick_drift  the first half kick and the drift; optionally fused with the
//               previous step's second half kick (the deferred step), the
//               neighbour-list displacement check and the force reset;
//   kick_check  the second half kick on its own, with the finiteness check.
// Fields: read mass, inv_mass, inv_inertia, f, t (and ext_f when enabled);
// write x, v, w (and f, t on a reset).
#pragma once

#include "core/particle_store.hpp"

#include <cstddef>

namespace domel::platform {

class NeighborList;

/// The body-force list. apply() resets f to the sum of the entries and t to 0.
struct BodyForces {
  double gravity[3] = {0, 0, 0};  ///< [m/s^2]
  /// f = m g (+ the external force), t = 0 for particles [first, last).
  void apply(ParticleStore& s, std::size_t first, std::size_t last) const;
};

/// What kick_drift counted over its range (sums of 0/1, see integrator.cpp).
struct DriftCounts {
  double beyond_skin = 0;  ///< particles that moved more than half the skin since the last list build
  double beyond_near = 0;  ///< particles that moved more than half the near tier's gap (NeighborList::near_size)
  double nonfinite = 0;    ///< particles non-finite after the previous step's second half kick (with finish)
};

struct KickDrift {
  double dt = 0;
  double half = 0;           ///< this step's half time step
  double finish_half = 0;    ///< the previous step's pending second half kick (0 with finish = false)
  bool finish = false;       ///< do the previous step's second half kick first
  const NeighborList* check = nullptr;  ///< displacements since this list's build (null: no check)
  const BodyForces* reset = nullptr;    ///< reset the forces to the body forces (null: leave them)
  /// Copy the drifted x, y, z and the radius into these 4 doubles per
  /// particle (PackedPositions::xyzr, sized for the store; null: no copy).
  double* pack = nullptr;
};

/// Pass 1 of a step over particles [first, last).
DriftCounts kick_drift(ParticleStore& s, std::size_t first, std::size_t last, const KickDrift& how);

/// The second half kick of `half` and the finiteness check over [first, last).
/// Returns the count of particles whose position or velocity is non-finite.
double kick_check(ParticleStore& s, std::size_t first, std::size_t last, double half);

/// The first particle in [0, n) whose position or velocity is non-finite (n if none).
std::size_t first_nonfinite(const ParticleStore& s);

}  // namespace domel::platform
