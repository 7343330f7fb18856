// SPDX-License-Identifier: MIT
// Particles between ranks (issue 19): migration of owned particles to the
// rank whose region holds them, and ghost copies of the particles within the
// list cut-off of another rank's region. A particle travels as every
// per-particle array of the store (ParticleStore::for_each_array), so what a
// module adds to the store (external forces, aux arrays) travels with it.
#pragma once

#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "distributed/communicator.hpp"
#include "distributed/decomposition.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace domel::platform {

/// Bytes one particle of this store takes (every array's element).
std::size_t particle_bytes(const ParticleStore& s);
/// Particles `which` of s, in that order, as bytes; with `shift`, the q-th
/// one's position moved by shift[q] (a periodic image).
std::vector<char> pack_particles(const ParticleStore& s, const std::vector<std::uint32_t>& which,
                                 const std::vector<std::array<double, 3>>* shift = nullptr);
/// Append the particles of `bytes` (packed from a store of the same layout:
/// the same external-force switch and aux count) to s.
void unpack_particles(ParticleStore& s, const std::vector<char>& bytes);

/// Ids for `count` new particles of this rank (a pour, an inflow) that are
/// unique over all ranks: rank r's block follows those of ranks 0..r-1, and
/// `next_id`, the same on every rank before and after, advances by the total.
/// Returns this rank's first id. Collective.
std::uint64_t claim_ids(std::uint64_t count, std::uint64_t& next_id, const Communicator& comm);

struct ExchangeCounts {
  std::size_t sent = 0, received = 0;
};

/// Send every particle whose owner is another rank there, and append the
/// ones other ranks send here (by sending rank, each in its store order).
/// Collective.
ExchangeCounts migrate(ParticleStore& s, const Decomposition& d, const Communicator& comm);

/// The ghosts of a rank and the way back to their owners. build() sends
/// copies of the owned particles within `cutoff` of other ranks' regions and
/// keeps who went where, so that between rebuilds update() refreshes the
/// ghosts' motion (the forward exchange, the step's ghost_update phase) and
/// reverse() adds the forces and torques the ghosts collected to their
/// owners (the reverse_exchange phase), in the order of the sending ranks:
/// the same sums every run for a given rank count. With periodic boundaries
/// a ghost is an image: a copy shifted by whole periods, sent also to the
/// owner's own rank when its region reaches the other face, so that pairs
/// through a face are pairs of plain separations as inside (the box must be
/// at least twice the cut-off along each periodic axis, as for one process).
class GhostExchange {
 public:
  /// Replace `ghosts` (layout as `owned`) by this rank's ghosts, by sending
  /// rank, each in its store order. Collective.
  ExchangeCounts build(const ParticleStore& owned, ParticleStore& ghosts, const Decomposition& d, double cutoff,
                       const Communicator& comm, const PeriodicBox& box = {});
  /// Positions, velocities and angular velocities of the owners into their
  /// ghosts (same particles as at build()). Collective.
  void update(const ParticleStore& owned, ParticleStore& ghosts, const Communicator& comm) const;
  /// The ghosts' forces and torques added to their owners'. Collective.
  void reverse(const ParticleStore& ghosts, ParticleStore& owned, const Communicator& comm) const;

 private:
  std::vector<std::vector<std::uint32_t>> sent_;  ///< per rank: the owned particles it holds as ghosts
  std::vector<std::vector<std::array<double, 3>>> shift_;  ///< per rank: each copy's periodic shift [m]
  std::vector<std::size_t> first_;                ///< per rank: its first ghost here (and the total at the end)
};

}  // namespace domel::platform
