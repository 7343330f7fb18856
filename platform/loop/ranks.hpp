// SPDX-License-Identifier: MIT
// What a run asks of the processes it runs on (issue 19; issue 40: ranks as
// a layer). Every run has one: SingleProcess (below) on one process, where a
// gather is the subdomain's own store and a sum is the value itself;
// MpiRunRanks (distributed/mpi_ranks.hpp) under mpirun, where every rank
// builds the same scenario, keeps its share of each subdomain's particles
// and steps it, and rank 0 alone writes the outputs, from the particles
// gathered to it in id order and from statistics summed over the ranks. So a
// component says what it needs once (a level's whole set of particles, a
// sum, an edit of the whole set carried back) and runs alike on both.
#pragma once

#include "averaging/cell_grid.hpp"
#include "core/error.hpp"
#include "core/particle_store.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
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

/// A level's whole set of particles as RunRanks::gather hands it out: on one
/// process the subdomain's own store, not a copy (an edit of it is the
/// level's edit); on ranks a gathered copy in id order, whose edits the ranks
/// carry back to the owners (RunRanks::removed, keep_added,
/// where_in_gathered).
class GatheredParticles {
 public:
  GatheredParticles() = default;
  explicit GatheredParticles(ParticleStore& own) : own_(&own) {}
  explicit GatheredParticles(ParticleStore&& copy) : copy_(std::move(copy)) {}
  ParticleStore& operator*() { return own_ ? *own_ : copy_; }
  const ParticleStore& operator*() const { return own_ ? *own_ : copy_; }
  ParticleStore* operator->() { return &**this; }
  const ParticleStore* operator->() const { return &**this; }

 private:
  ParticleStore* own_ = nullptr;
  ParticleStore copy_;
};

class RunRanks {
 public:
  virtual ~RunRanks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// For the log: " on each of N ranks", or nothing on one process.
  virtual std::string on_each() const = 0;
  /// Keep this rank's share of sd's particles and spread sd over the ranks
  /// [first, first + count) (count 0: all ranks); a rank outside the group
  /// holds none of sd (Subdomain::set_elsewhere). Before setup().
  /// Collective over all ranks.
  virtual void distribute(Subdomain& sd, int first = 0, int count = 0) = 0;
  /// The particles every rank owns of sd: in id order, on rank 0 (on the
  /// others: empty), or with `everywhere` on every rank; on one process the
  /// store itself. Collective.
  virtual GatheredParticles gather(Subdomain& sd, bool everywhere = false) = 0;
  /// Where each particle this rank owns of sd, store()[0, owned()), sits in
  /// `whole` (gather(sd, true)). Throws RuntimeError, naming `who`, for one
  /// that is missing. Not collective.
  virtual std::vector<std::size_t> where_in_gathered(Subdomain& sd, const ParticleStore& whole,
                                                     const std::string& who);
  /// The particles `ids` were removed from sd's gathered set (every rank
  /// alike): each rank removes those it owns. Not collective.
  virtual void removed(Subdomain& sd, std::vector<std::uint64_t> ids);
  /// Particles were appended to sd's gathered set `whole` at [first,
  /// whole.size()) (every rank alike): each rank keeps those whose id falls
  /// to it (Subdomain::keeps). Returns where they are in sd's store, [begin,
  /// end), for their body forces. Not collective.
  virtual std::pair<std::size_t, std::size_t> keep_added(Subdomain& sd, const ParticleStore& whole,
                                                         std::size_t first);
  /// The contact records of sd's last recorded step, indexing `whole`
  /// (gather(sd, true)): on ranks every rank's, gathered into `storage`; on
  /// one process the subdomain's own lists. Collective.
  virtual std::vector<const std::vector<ContactRecord>*> contact_records(Subdomain& sd, const ParticleStore& whole,
                                                                         std::vector<ContactRecord>& storage);
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
  virtual void reduce_in_rank_order(std::vector<double>& sums, std::vector<double>& maxima) {
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
  /// summary.json: particles and histories migrated, ghosts, bytes); null
  /// on one process. Collective.
  virtual nlohmann::json traffic(const Subdomain& sd) = 0;
};

/// The ranks of a run on one process: rank 0 of 1. A gather is the store, a
/// sum or a maximum the value itself (bit for bit: no 0 + x), an edit of a
/// gathered set already the level's edit.
class SingleProcess final : public RunRanks {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  std::string on_each() const override { return {}; }
  void distribute(Subdomain&, int, int) override {}
  GatheredParticles gather(Subdomain& sd, bool everywhere = false) override;
  std::vector<std::size_t> where_in_gathered(Subdomain& sd, const ParticleStore& whole,
                                             const std::string& who) override;
  void removed(Subdomain&, std::vector<std::uint64_t>) override {}
  std::pair<std::size_t, std::size_t> keep_added(Subdomain&, const ParticleStore& whole, std::size_t first) override {
    return {first, whole.size()};
  }
  std::vector<const std::vector<ContactRecord>*> contact_records(Subdomain& sd, const ParticleStore& whole,
                                                                 std::vector<ContactRecord>& storage) override;
  std::vector<std::vector<char>> all_gather(const std::vector<char>& mine) override { return {mine}; }
  std::vector<std::vector<char>> gather_to_root(const std::vector<char>& mine) override { return {mine}; }
  void sum(std::vector<std::uint64_t>&) override {}
  void reduce_in_rank_order(std::vector<double>&, std::vector<double>&) override {}
  double max(double x) override { return x; }
  nlohmann::json traffic(const Subdomain&) override { return nullptr; }
};

/// A SingleProcess for components used outside a run's loop (tests, tools)
/// until the run hands them its ranks: it holds no state, so one serves all.
RunRanks& one_process();

}  // namespace domel::platform
