// SPDX-License-Identifier: MIT
// Particles between ranks (issue 19): migration of owned particles to the
// rank whose region holds them, and ghost copies of the particles within the
// list cut-off of another rank's region. A particle travels as every
// per-particle array of the store (ParticleStore::for_each_array), so what a
// module adds to the store (external forces, aux arrays) travels with it.
#pragma once

#include "core/archive.hpp"
#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "distributed/communicator.hpp"
#include "distributed/decomposition.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace domel::platform {

/// Bytes one particle of this store takes in a message of the fields whose
/// sync policy has any of `sync` (ParticleStore::for_each_field).
std::size_t particle_bytes(const ParticleStore& s, unsigned sync = ParticleStore::kMigrate);
/// Particles `which` of s, in that order, as bytes: the fields with any of
/// `sync` (kMigrate: a migration or a gather; kGhostBuild: new ghosts); with
/// `shift`, the q-th one's position moved by shift[q] (a periodic image).
std::vector<char> pack_particles(const ParticleStore& s, const std::vector<std::uint32_t>& which,
                                 const std::vector<std::array<double, 3>>* shift = nullptr,
                                 unsigned sync = ParticleStore::kMigrate);
/// Append the particles of `bytes` (packed from a store of the same fields,
/// with the same `sync`) to s; the fields not sent start at zero.
void unpack_particles(ParticleStore& s, const std::vector<char>& bytes, unsigned sync = ParticleStore::kMigrate);

/// Ids for `count` new particles of this rank (a pour, an inflow) that are
/// unique over all ranks: rank r's block follows those of ranks 0..r-1, and
/// `next_id`, the same on every rank before and after, advances by the total.
/// Returns this rank's first id. Collective.
std::uint64_t claim_ids(std::uint64_t count, std::uint64_t& next_id, const Communicator& comm);

struct ExchangeCounts {
  std::size_t sent = 0, received = 0;
  std::size_t histories_sent = 0;  ///< migrate(): pair histories that went with the particles
};

/// Send every particle whose owner is another rank there, and append the
/// ones other ranks send here (by sending rank, each in its store order).
/// Each set of `histories` (the live contact histories of s's pair list,
/// of its wall lists) is keyed by the particle that leads each row (id_i):
/// a row goes where that particle goes, since its owner computes the
/// contact; each set then holds this rank's rows (the kept ones, then the
/// received ones by sending rank). Collective.
ExchangeCounts migrate(ParticleStore& s, const Decomposition& d, const Communicator& comm,
                       const std::vector<PairHistories*>& histories = {});

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
///
/// The ghosts live in the rank's store after its own particles: [0, owned)
/// are owned, [owned, size) ghosts.
class GhostExchange {
 public:
  /// Replace the ghosts of s (everything from `owned` on) by this rank's
  /// ghosts now, by sending rank, each in its store order. Collective.
  ExchangeCounts build(ParticleStore& s, std::size_t owned, const Decomposition& d, double cutoff,
                       const Communicator& comm, const PeriodicBox& box = {});
  /// Positions, velocities and angular velocities of the owners into their
  /// ghosts (same particles as at build()). Collective.
  void update(ParticleStore& s, const Communicator& comm) const;
  /// The ghosts' forces and torques added to their owners'. Collective.
  void reverse(ParticleStore& s, const Communicator& comm) const;
  /// The ghosts' contact counts (ParticleStore::contacts) added to their
  /// owners', the ghosts' set to 0. Collective.
  void reverse_counts(ParticleStore& s, const Communicator& comm) const;
  /// The owned count at the last build (the first ghost's index).
  std::size_t owned() const { return first_.empty() ? 0 : first_.front(); }
  /// The store's size at the last build (the end of the ghosts).
  std::size_t size() const { return first_.empty() ? 0 : first_.back(); }
  /// Bytes sent to other ranks by one update() and by one reverse() of s.
  std::size_t update_bytes(const ParticleStore& s) const;
  std::size_t reverse_bytes(const ParticleStore& s) const;
  /// Checkpoints: who-went-where of the last build (what update() and
  /// reverse() read until the next build).
  void save(ArchiveWriter& w, const std::string& prefix) const;
  void load(const ArchiveReader& r, const std::string& prefix, int ranks);
  /// Both directions of save and load, field by field (core/archive.hpp);
  /// `ranks` the run's rank count (loading).
  void fields(CheckpointFields& f, int ranks);

 private:
  /// Throws unless s holds the particles of the last build.
  void check(const ParticleStore& s, const char* what) const;
  std::vector<std::vector<std::uint32_t>> sent_;  ///< per rank: the owned particles it holds as ghosts
  std::vector<std::vector<std::array<double, 3>>> shift_;  ///< per rank: each copy's periodic shift [m]
  std::vector<std::size_t> first_;                ///< per rank: its first ghost in the store (and the size at the end)
};

}  // namespace domel::platform
