// SPDX-License-Identifier: MIT
// What a run spread over several processes (issue 19) asks of the layer
// that spreads it (distributed/mpi_ranks.hpp): every rank builds the same
// scenario, keeps its share of each subdomain's particles and steps it;
// rank 0 alone writes the outputs, from the particles gathered to it in id
// order and from statistics summed over the ranks. Simulation::run() takes
// one through RunOptions::ranks; without one the run is one process.
#pragma once

#include "core/error.hpp"
#include "core/particle_store.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace domel::platform {

class Subdomain;

/// The levels' rank groups (subdomains[].rank_share): group k is the ranks
/// [first, first + count), consecutive in the subdomains' order, sized in
/// proportion to the shares (largest remainders, ties to the earlier
/// subdomain), at least one rank each: `ranks` >= shares.size().
struct RankGroup {
  int first = 0, count = 0;
};
inline std::vector<RankGroup> rank_groups(const std::vector<double>& shares, int ranks) {
  const std::size_t n = shares.size();
  double total = 0;
  for (double s : shares) total += s;
  std::vector<int> c(n);
  std::vector<double> rest(n);
  int used = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double q = ranks * shares[k] / total;
    c[k] = std::max(1, static_cast<int>(std::floor(q)));
    rest[k] = q - std::floor(q);
    used += c[k];
  }
  while (used < ranks) {  // the largest remainder first
    std::size_t best = 0;
    for (std::size_t k = 1; k < n; ++k)
      if (rest[k] > rest[best]) best = k;
    ++c[best];
    rest[best] = -1;
    ++used;
  }
  while (used > ranks) {  // a group raised to one rank: the largest other gives one back
    std::size_t big = 0;
    for (std::size_t k = 1; k < n; ++k)
      if (c[k] >= c[big]) big = k;
    --c[big];
    --used;
  }
  std::vector<RankGroup> g(n);
  for (std::size_t k = 0, first = 0; k < n; first += static_cast<std::size_t>(c[k]), ++k)
    g[k] = {static_cast<int>(first), c[k]};
  return g;
}

class RunRanks {
 public:
  virtual ~RunRanks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Keep this rank's share of sd's particles and spread sd over the ranks
  /// [first, first + count) (count 0: all ranks); a rank outside the group
  /// holds none of sd (Subdomain::set_elsewhere). Before setup().
  /// Collective over all ranks.
  virtual void distribute(Subdomain& sd, int first = 0, int count = 0) = 0;
  /// The particles every rank owns of sd, in id order, on rank 0 (on the
  /// others: empty), or with `everywhere` on every rank. Collective.
  virtual ParticleStore gather(Subdomain& sd, bool everywhere = false) = 0;
  /// Every rank's bytes, on every rank, by rank. Collective.
  virtual std::vector<std::vector<char>> all_gather(const std::vector<char>& mine) = 0;
  /// Every rank's bytes, by rank, on rank 0 (on the others: none). Collective.
  virtual std::vector<std::vector<char>> gather_to_root(const std::vector<char>& mine) = 0;
  /// Element-wise sums over the ranks, in place. Collective.
  virtual void sum(std::vector<std::uint64_t>& v) = 0;
  /// One count summed over the ranks. Collective.
  std::uint64_t sum_count(std::uint64_t x) {
    std::vector<std::uint64_t> v{x};
    sum(v);
    return v[0];
  }
  /// Element-wise sums over the ranks, added up in rank order, so the same
  /// bits on every rank and run to run for a given rank count. Collective.
  std::vector<double> sum_in_rank_order(const std::vector<double>& mine) {
    std::vector<double> total(mine), none;
    reduce_in_rank_order(total, none);
    return total;
  }
  /// Element-wise sums (added up in rank order) and maxima over the ranks,
  /// in place: the same bits on every rank. Collective.
  void reduce_in_rank_order(std::vector<double>& sums, std::vector<double>& maxima) {
    std::vector<double> both(sums);
    both.insert(both.end(), maxima.begin(), maxima.end());
    std::vector<char> bytes(both.size() * sizeof(double));
    if (!both.empty()) std::memcpy(bytes.data(), both.data(), bytes.size());
    std::fill(sums.begin(), sums.end(), 0.0);
    bool first = true;
    for (const auto& b : all_gather(bytes)) {
      if (b.size() != bytes.size()) throw RuntimeError("reduction over the ranks: the ranks sent different lengths");
      for (std::size_t k = 0; k < both.size(); ++k) {
        double x;
        std::memcpy(&x, b.data() + k * sizeof(double), sizeof(double));
        if (k < sums.size()) sums[k] += x;
        else maxima[k - sums.size()] = first ? x : std::max(maxima[k - sums.size()], x);
      }
      first = false;
    }
  }
  /// The largest x over the ranks. Collective.
  virtual double max(double x) = 0;
  /// What sd's ranks exchanged since the start, summed over the ranks (for
  /// summary.json: particles and histories migrated, ghosts, bytes).
  /// Collective.
  virtual nlohmann::json traffic(const Subdomain& sd) = 0;
};

}  // namespace domel::platform
