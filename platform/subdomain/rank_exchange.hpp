// SPDX-License-Identifier: MIT
// What a subdomain spread over several processes asks of the layer that
// spreads it (distributed/, issue 19). Its store then holds this rank's own
// particles first, [0, owned), and after them ghosts: copies of other ranks'
// particles (and periodic images, also of its own) within the list cut-off
// of its region. Ghosts take part in pairs but are neither integrated nor
// counted; a pair is computed by the rank that owns its lower id, and its
// contact history lives there. The subdomain calls these at the phases of
// its step (step_phases.hpp): migrate at exchange, build_ghosts before the
// list build, update_ghosts at ghost_update, reverse at reverse_exchange.
#pragma once

#include "core/archive.hpp"
#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace domel::platform {

/// The rank that keeps a particle every rank created alike (the particles at
/// a start, a pour's, an inflow's, a checkpoint's on another rank count): id
/// modulo the rank count. The next exchange moves it to the owner of its place.
inline bool starts_on_rank(std::uint64_t id, int rank, int ranks) {
  return id % static_cast<std::uint64_t>(ranks) == static_cast<std::uint64_t>(rank);
}

class RankExchange {
 public:
  virtual ~RankExchange() = default;
  /// Element-wise OR of flags[0, n) over the ranks. Collective.
  virtual void any(bool* flags, std::size_t n) = 0;
  /// The largest x over the ranks. Collective.
  virtual double max(double x) = 0;
  /// Drop the ghosts (everything from `owned` on), wrap positions into the
  /// periodic box, share space out again by `cost` (one value per owned
  /// particle), and move each particle to its owner, with the contact
  /// histories it leads (each set of `histories` keyed by the leading
  /// particle's id in id_i, replaced by this rank's rows). Returns the
  /// owned count. Collective.
  virtual std::size_t migrate(ParticleStore& s, std::size_t owned, const std::vector<std::uint64_t>& cost,
                              const std::vector<PairHistories*>& histories) = 0;
  /// Append the ghosts within `cutoff` of this rank's region. Collective.
  virtual void build_ghosts(ParticleStore& s, std::size_t owned, double cutoff) = 0;
  /// The owners' motion into their ghosts. Collective.
  virtual void update_ghosts(ParticleStore& s) = 0;
  /// The ghosts' forces and torques added to their owners'. Collective.
  virtual void reverse(ParticleStore& s) = 0;
  /// The ghosts' contact counts added to their owners'. Collective.
  virtual void reverse_counts(ParticleStore& s) = 0;
  /// This rank's size of the exchange (a checkpoint holds one part per rank).
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Checkpoints: what the steps until the next build read (who holds
  /// which ghosts) and the traffic counted so far. Not collective.
  virtual void save(ArchiveWriter& w, const std::string& prefix) const = 0;
  virtual void load(const ArchiveReader& r, const std::string& prefix) = 0;
  /// Where the ghosts of the last build start and end in the store.
  virtual std::size_t ghosts_begin() const = 0;
  virtual std::size_t ghosts_end() const = 0;
};

}  // namespace domel::platform
