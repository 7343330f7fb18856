// SPDX-License-Identifier: MIT
// A subdomain spread over the ranks of a communicator (issue 19): the
// RankExchange the subdomain calls at its step's phases, built on the
// decomposition and the particle exchange of this folder. At every list
// build the space is shared out again by recursive coordinate bisection of
// the particles' costs (never timings: a given rank count gives the same
// run every time), particles move to their owners with the contact
// histories they lead, and the ghosts are built anew; between builds the
// ghosts follow their owners, and their forces go home every step.
#pragma once

#include "distributed/communicator.hpp"
#include "distributed/decomposition.hpp"
#include "distributed/particle_exchange.hpp"
#include "subdomain/rank_exchange.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace domel::platform {

class Subdomain;

/// What crossed between ranks, summed since the start (this rank's share).
struct RankTraffic {
  std::uint64_t migrations = 0;      ///< exchange phases
  std::uint64_t migrated = 0;        ///< particles sent to another rank
  std::uint64_t histories_sent = 0;  ///< pair histories that went with them
  std::uint64_t ghost_builds = 0, ghosts = 0;  ///< ghosts received at the builds
  std::uint64_t updates = 0, update_bytes = 0;    ///< forward exchanges
  std::uint64_t reverses = 0, reverse_bytes = 0;  ///< reverse exchanges
};

class SubdomainRanks final : public RankExchange {
 public:
  SubdomainRanks(Communicator comm, const PeriodicBox& box);
  bool over_ranks() const override { return true; }
  PeriodicBox pair_box(const PeriodicBox&) const override { return {}; }
  void any(bool* flags, std::size_t n) override;
  double max(double x) override;
  std::size_t migrate(ParticleStore& s, std::size_t owned, const std::vector<std::uint64_t>& cost,
                      const std::vector<PairHistories*>& histories) override;
  void build_ghosts(ParticleStore& s, std::size_t owned, double skin) override;
  void update_ghosts(ParticleStore& s) override;
  void reverse(ParticleStore& s) override;
  void reverse_counts(ParticleStore& s) override { ghosts_.reverse_counts(s, comm_); }
  int rank() const override { return comm_.rank(); }
  int size() const override { return comm_.size(); }
  void save(ArchiveWriter& w, const std::string& prefix) const override;
  void load(const ArchiveReader& r, const std::string& prefix, std::size_t owned, std::size_t ghosts_end) override;
  /// The traffic counters in a checkpoint, both directions (core/archive.hpp).
  void traffic_fields(CheckpointFields& f);

  const Communicator& communicator() const { return comm_; }
  const Decomposition& decomposition() const { return d_; }
  const RankTraffic& traffic() const { return traffic_; }

 private:
  /// The box the bisection's histograms span: the periodic box along its
  /// periodic axes, the particles' bounds over all ranks along the others.
  Region extent(const ParticleStore& s, std::size_t owned) const;
  Communicator comm_;
  PeriodicBox box_;
  Decomposition d_;
  GhostExchange ghosts_;
  RankTraffic traffic_;
};

/// Spread `sd` over the ranks of `comm`: call before setup(), with the
/// store holding this rank's share of the particles (any share: the first
/// exchange moves each particle to its owner). Returns the exchange, owned
/// by the subdomain.
SubdomainRanks& distribute(Subdomain& sd, const Communicator& comm);

}  // namespace domel::platform
