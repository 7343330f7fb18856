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
// A subdomain of one process holds a OneProcessExchange: no ghosts, every
// collective a no-op, so the step calls the same phases either way.
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
  /// Whether the subdomain is spread over ranks (a communicator of one rank
  /// counts: its periodic images are ghosts and its step goes in phase order).
  virtual bool over_ranks() const = 0;
  /// The box in which pairs measure their separations: one process, the
  /// periodic box (nearest images); over ranks, none (the images are ghosts).
  virtual PeriodicBox pair_box(const PeriodicBox& box) const = 0;
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
  /// Append the ghosts: every particle that can meet one of s[0, owned)
  /// before the next build (cut-off: the largest diameter on any rank plus
  /// the `skin`). Collective.
  virtual void build_ghosts(ParticleStore& s, std::size_t owned, double skin) = 0;
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
  /// The part read back holds s[0, owned) of its own and ghosts up to
  /// `ghosts_end`; refused (r.fail) when the saved ghosts sit elsewhere.
  virtual void load(const ArchiveReader& r, const std::string& prefix, std::size_t owned, std::size_t ghosts_end) = 0;
};

/// The exchange of a subdomain that lives on one process: it owns every
/// particle, builds no ghosts, and every collective is a no-op. Its periodic
/// images are nearest images (pair_box), and the subdomain wraps positions
/// and keeps the contact histories in place itself (migrate is not called).
class OneProcessExchange final : public RankExchange {
 public:
  bool over_ranks() const override { return false; }
  PeriodicBox pair_box(const PeriodicBox& box) const override { return box; }
  void any(bool*, std::size_t) override {}
  double max(double x) override { return x; }
  std::size_t migrate(ParticleStore& s, std::size_t owned, const std::vector<std::uint64_t>&,
                      const std::vector<PairHistories*>&) override {
    s.truncate(owned);
    return s.size();
  }
  void build_ghosts(ParticleStore&, std::size_t, double) override {}
  void update_ghosts(ParticleStore&) override {}
  void reverse(ParticleStore&) override {}
  void reverse_counts(ParticleStore&) override {}
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void save(ArchiveWriter&, const std::string&) const override {}
  void load(const ArchiveReader&, const std::string&, std::size_t, std::size_t) override {}
};

}  // namespace domel::platform
