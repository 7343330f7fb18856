// SPDX-License-Identifier: MIT
// What a run spread over several processes (issue 19) asks of the layer
// that spreads it (distributed/run_ranks.hpp): every rank builds the same
// scenario, keeps its share of each subdomain's particles and steps it;
// rank 0 alone writes the outputs, from the particles gathered to it in id
// order and from statistics summed over the ranks. Simulation::run() takes
// one through RunOptions::ranks; without one the run is one process.
#pragma once

#include "core/error.hpp"
#include "core/particle_store.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <vector>

namespace domel::platform {

class Subdomain;

class RunRanks {
 public:
  virtual ~RunRanks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Keep this rank's share of sd's particles and spread sd over the ranks
  /// (before setup()). Collective.
  virtual void distribute(Subdomain& sd) = 0;
  /// The particles every rank owns of sd, in id order, on rank 0 (on the
  /// others: empty), or with `everywhere` on every rank. Collective.
  virtual ParticleStore gather(Subdomain& sd, bool everywhere = false) = 0;
  /// Every rank's bytes, on every rank, by rank. Collective.
  virtual std::vector<std::vector<char>> all_gather(const std::vector<char>& mine) = 0;
  /// Every rank's bytes, by rank, on rank 0 (on the others: none). Collective.
  virtual std::vector<std::vector<char>> gather_to_root(const std::vector<char>& mine) = 0;
  /// Element-wise sums over the ranks, in place. Collective.
  virtual void sum(std::vector<std::uint64_t>& v) = 0;
  /// Element-wise sums over the ranks, added up in rank order, so the same
  /// bits on every rank and run to run for a given rank count. Collective.
  std::vector<double> sum_in_rank_order(const std::vector<double>& mine) {
    std::vector<char> bytes(mine.size() * sizeof(double));
    if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
    std::vector<double> total(mine.size(), 0.0);
    for (const auto& b : all_gather(bytes)) {
      if (b.size() != bytes.size()) throw RuntimeError("sum over the ranks: the ranks sent different lengths");
      for (std::size_t k = 0; k < total.size(); ++k) {
        double x;
        std::memcpy(&x, b.data() + k * sizeof(double), sizeof(double));
        total[k] += x;
      }
    }
    return total;
  }
  /// The largest x over the ranks. Collective.
  virtual double max(double x) = 0;
  /// What sd's ranks exchanged since the start, summed over the ranks (for
  /// summary.json: particles and histories migrated, ghosts, bytes).
  /// Collective.
  virtual nlohmann::json traffic(const Subdomain& sd) = 0;
};

}  // namespace domel::platform
