// SPDX-License-Identifier: MIT
// How the threads share a force evaluation, and how their partial sums come
// together: the pair list's tiers are cut into contiguous per-thread ranges
// of near-equal estimated cost (balance), each thread's particle span and
// its own zone, which no other thread's pairs touch, are found (zones), the
// particles are split for the pass that sums the threads' private arrays
// and evaluates the wall contacts (split_for_reduce), and the sums are
// added into the store in thread order (reduce). Every split is a function
// of the lists and their contact flags, never of timings, so a run is
// bit-identical for a given thread count.
#pragma once

#include "contact/contact_sweep.hpp"
#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "geometry/wall.hpp"
#include "geometry/wall_neighbors.hpp"

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace domel::platform {

class ArchiveWriter;
class ArchiveReader;

class ForcePartition {
 public:
  /// One thread's private force arrays (threads > 0) and particle spans.
  struct ThreadForces {
    std::vector<double> fx, fy, fz, tx, ty, tz;
    std::size_t lo = 0, hi = 0;  ///< particle-index span of this thread's pairs this step
    /// The part of [lo, hi) that no other thread's pairs touch this step:
    /// forces on these particles go straight into the store (own_lo ==
    /// own_hi == hi when there is none). Only [lo, own_lo) and [own_hi, hi)
    /// of the private arrays are cleared and summed.
    std::size_t own_lo = 0, own_hi = 0;
    std::size_t span[2][2] = {{0, 0}, {0, 0}};  ///< the span per list tier (near, far)
    /// The parts of the span that go through the private arrays.
    std::array<std::pair<std::size_t, std::size_t>, 2> shared_ranges() const {
      return {{{lo, own_lo}, {own_hi, hi}}};
    }
  };

  /// The estimated cost of the force evaluation's pieces, in units of one
  /// pair-list entry's overlap screen (measured on S1 and S2 at 10k on two
  /// threads, docs/performance.md): a pair contact (contact kernels, scatter), a
  /// wall-list entry (its gap test), a wall contact. The threads' split and
  /// the ranks' decomposition (Subdomain::rank_costs) weigh the work alike.
  static constexpr std::uint64_t kPairContactCost = 15;
  static constexpr std::uint64_t kWallEntryCost = 1;
  static constexpr std::uint64_t kWallContactCost = 6;

  void set_threads(int threads);
  int threads() const { return static_cast<int>(threads_.size()); }

  /// The cost-balanced ranges of the pair list's tiers (threads > 1), from
  /// the list's contact flags and the threads' contact counts of the last
  /// evaluation. Recomputed after each list build, and every kBalanceEvery
  /// steps when the threads' estimated costs differ by more than
  /// kRebalanceAt; also refreshes the wall work of split_for_reduce.
  void balance(const NeighborList& list, bool far_active, const std::vector<ContactScratch>& contacts,
               const std::vector<WallNeighbors>& wall_lists, const std::vector<WallPrimitive>& walls_now,
               double time, std::uint64_t step, std::size_t particles);
  /// Each thread's span and own zone for this evaluation.
  void zones(bool far_active);
  /// Thread t's list entries of tier 0 (near) or 1 (far).
  std::pair<std::size_t, std::size_t> entries(int tier, int t) const {
    const auto q = static_cast<std::size_t>(t);
    return {split_[tier][q], split_[tier][q + 1]};
  }
  const ThreadForces& thread(int t) const { return threads_[static_cast<std::size_t>(t)]; }
  /// Thread t's (> 0) private arrays for n particles, their shared ranges cleared.
  ForceAccumulator private_accumulator(int t, std::size_t n);

  /// Split [0, n) for the pass that sums the private arrays and evaluates
  /// the wall contacts, so that each thread gets the same estimated cost.
  void split_for_reduce(std::size_t n);
  /// Thread t's particles in that pass.
  std::pair<std::size_t, std::size_t> reduce_range(int t) const {
    const auto q = static_cast<std::size_t>(t);
    return {pass2_split_[q], pass2_split_[q + 1]};
  }
  /// Add the other threads' private sums of particles [first, last) into the store, in thread order.
  void reduce(ParticleStore& s, std::size_t first, std::size_t last) const;

  /// The split as the next evaluation would find it: the tiers' ranges, the
  /// build they belong to, the threads' spans and the wall work (checkpoints:
  /// a restart then sums the forces in the same order). The private force
  /// arrays are scratch, cleared before each use.
  void save(ArchiveWriter& w, const std::string& prefix) const;
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load, field by field (core/archive.hpp).
  void fields(CheckpointFields& f);

  /// Bytes of the private force arrays.
  std::size_t bytes() const;

 private:
  void refresh_wall_work(const std::vector<WallNeighbors>& wall_lists, const std::vector<WallPrimitive>& walls_now,
                         double time);

  std::vector<ThreadForces> threads_;
  std::vector<std::size_t> split_[2];  ///< per list tier (near, far): ranges of the threads
  std::size_t split_builds_ = 0;
  /// (particle, wall cost of the entries up to this one), ascending in particle
  std::vector<std::pair<uint32_t, double>> wall_work_;
  std::vector<std::size_t> split_cuts_;  ///< split_for_reduce's segment bounds and weights
  std::vector<double> split_weights_;
  std::vector<std::size_t> pass2_split_;
};

}  // namespace domel::platform
