// SPDX-License-Identifier: MIT
// What a subdomain reports about itself, apart from its particles: the
// statistics of the probes and the run summary (kinetic energies, angular
// speeds, contact counts, overlaps), the memory its arrays hold, and the
// per-particle contact counts of the VTK output. Observers only: nothing
// here runs in the step loop.
#pragma once

#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "geometry/wall.hpp"
#include "geometry/wall_neighbors.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace domel::platform {

/// Observables of the last force evaluation and the current state.
struct SubdomainStats {
  std::size_t particles = 0;         ///< all particles, fixed ones included
  std::size_t fixed = 0;             ///< fixed particles (not in the kinetic statistics)
  std::size_t contacts = 0;          ///< particle-particle contacts
  std::size_t wall_contacts = 0;
  double kinetic_translational = 0;  ///< [J]
  double kinetic_rotational = 0;     ///< [J]
  double mean_angular_speed = 0;     ///< mean |omega| [rad/s]
  /// median |omega| [rad/s]: robust against the few particles that spin
  /// freely about their contact normal, which rolling models do not resist
  /// and which pin the plain mean (docs/validation/repose.md)
  double median_angular_speed = 0;
  /// mean |omega| over particles with |omega| < 1 rad/s [rad/s] (the peers' trimmed statistic)
  double trimmed_mean_angular_speed = 0;
  double max_overlap_ratio = 0;      ///< max delta / (mean diameter of the pair), walls: delta / d
};

/// Bytes held by a subdomain's per-particle and per-contact arrays (their
/// capacity), for the run summary and the memory benchmark.
struct MemoryUse {
  std::size_t particles = 0;        ///< the particle store and its packed positions (PackedPositions)
  std::size_t neighbor_lists = 0;   ///< pair and wall lists without their history
  std::size_t contact_history = 0;  ///< per-entry history rows of the pair and wall lists
  std::size_t threads = 0;          ///< the other threads' force arrays
};

/// Overlapping pairs among a set of particles before any step (from a state
/// file or insertions), by a cell list of side 2 r_max: O(N).
struct InitialOverlaps {
  std::size_t pairs = 0;      ///< pairs with delta > 0
  double worst = 0;           ///< largest delta / (R_i + R_j), the probes' max_overlap_ratio
  std::uint64_t worst_ids[2] = {0, 0};
  /// The pairs above `limit` (worst first, at most 5): ids and ratio.
  struct Pair {
    std::uint64_t a, b;
    double ratio;
  };
  std::vector<Pair> above;
  std::size_t above_count = 0;  ///< how many pairs exceed `limit` in all
};
/// Periodic axes of `box`: pairs through an image count too.
InitialOverlaps find_initial_overlaps(const ParticleStore& s, double limit, const PeriodicBox& box = {});

/// The kinetic part of the statistics (particles, fixed, energies, angular
/// speeds) of particles [0, count).
SubdomainStats kinetic_stats(const ParticleStore& s, std::size_t count = SIZE_MAX);

/// The bytes of the store and the lists (MemoryUse::threads left 0).
MemoryUse list_memory(const ParticleStore& s, const NeighborList& list, const std::vector<WallNeighbors>& walls);

/// Fill s.contacts from the contact flags the last force evaluation left in
/// the lists: the screened part of the pair list (`screened` entries) and
/// the wall lists of the walls active at `forces_time`. Call before anyone
/// changes the layout the evaluation ran on.
void count_contacts(ParticleStore& s, const NeighborList& list, std::size_t screened,
                    const std::vector<WallNeighbors>& wall_lists, const std::vector<WallPrimitive>& walls,
                    double forces_time);

}  // namespace domel::platform
