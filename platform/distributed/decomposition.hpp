// SPDX-License-Identifier: MIT
// Spatial decomposition of a subdomain over ranks (issue 19): recursive
// coordinate bisection (RCB) by an integer cost per particle. Each cut halves
// the ranks of a region (the larger half to the right when odd) along the
// region's longest axis, where the cost below the cut reaches the left half's
// share. The cut is found from cost histograms (two passes of kBins bins),
// which are summed over the ranks as integers: exact, so every rank computes
// the same tree, and the tree depends only on the set of (position, cost),
// never on which rank holds which particle or on timings. Why RCB and not a
// regular grid: a pile, a silo or a settling column puts most contacts in a
// small part of the box, which a grid can only balance by over-splitting;
// RCB follows the cost with one cut per level (as LAMMPS's `balance rcb` and
// Zoltan's RCB do). Regions tile all space: the faces on the outside are at
// infinity, so a particle that strays out of the extent still has an owner.
#pragma once

#include "core/neighbor_list.hpp"
#include "distributed/communicator.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace domel::platform {

struct Region {
  double lo[3], hi[3];
  /// The distance from p to the region (0 inside).
  double distance(const double p[3]) const;
};

class Decomposition {
 public:
  static constexpr int kBins = 512;

  /// One part: all space on rank 0.
  Decomposition();

  /// Bisect `parts` regions from the points (x, y, z)[k] with costs cost[k],
  /// k < n, of this rank; `extent` bounds the histograms (points outside it
  /// count in the nearest bin). Collective: every rank of `comm` calls it.
  static Decomposition bisect(const Region& extent, int parts, const double* x, const double* y, const double* z,
                              const std::uint64_t* cost, std::size_t n, const Communicator& comm);

  int parts() const { return nodes_.empty() ? 1 : nodes_[0].count; }
  /// The part whose region holds p (exactly one).
  int owner(const double p[3]) const;
  /// Part k's region (outer faces at +-infinity).
  const Region& region(int part) const { return nodes_[leaf_[static_cast<std::size_t>(part)]].region; }
  /// Every part whose region lies within `cutoff` of p (the owner included),
  /// ascending, into `out` (cleared first). With a periodic box, the regions
  /// end at its faces along its periodic axes (there, beyond a face is the
  /// other side's image, not more of the region).
  void parts_within(const double p[3], double cutoff, std::vector<int>& out, const PeriodicBox& box = {}) const;

  struct Node {
    Region region;  ///< what it owns (outer faces at infinity)
    int first = 0, count = 1;  ///< its parts: [first, first + count)
    int axis = -1;             ///< -1: a leaf
    double cut = 0;            ///< left: p[axis] < cut
    int left = -1, right = -1;
  };
  const std::vector<Node>& nodes() const { return nodes_; }

 private:
  std::vector<Node> nodes_;
  std::vector<std::size_t> leaf_;  ///< node of each part
};

}  // namespace domel::platform
