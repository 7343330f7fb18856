// SPDX-License-Identifier: MIT
// Verlet neighbour list built from a cell list, with a skin, plus the
// per-pair contact history. The list is a half list: each pair once, oriented
// so that id[i] < id[j]; that orientation never changes, so a history vector
// (defined for "i relative to j") keeps its meaning across rebuilds and
// re-ordering. On rebuild the history of every pair still in contact is
// carried over by the pair's ids. Rebuild when any particle moved more than
// half the skin since the last build (then no pair can have entered contact
// unseen).
#pragma once

#include "core/particle_store.hpp"
#include "core/thread_pool.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace domel::platform {

/// Periodic boundaries of a subdomain (subdomains[].periodic): along each
/// periodic axis a the space repeats with period L_a = hi[a] - lo[a].
/// Positions are wrapped into [lo, hi) when the lists are rebuilt (the
/// step's exchange phase); between rebuilds a particle may stray past a
/// face by up to half the skin. Pairs interact through their nearest image
/// (the minimum-image convention), which is unique while L_a is at least
/// twice the list cut-off (checked at every build).
struct PeriodicBox {
  bool axis[3] = {false, false, false};
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool any() const { return axis[0] || axis[1] || axis[2]; }
  double length(int a) const { return hi[a] - lo[a]; }
  /// The period along each axis, 0 where not periodic (for min_image()).
  void periods(double L[3], double inv_L[3]) const {
    for (int a = 0; a < 3; ++a) {
      L[a] = axis[a] ? length(a) : 0.0;
      inv_L[a] = axis[a] ? 1.0 / length(a) : 0.0;
    }
  }
  /// Wrap the particles' positions into the box (returns how many moved).
  std::size_t wrap(ParticleStore& s) const;
  /// The shifts (-1, 0 or +1 period per axis, 0 along the others) to the
  /// images one period away, the zero shift not included.
  std::vector<std::array<int, 3>> image_shifts() const {
    std::vector<std::array<int, 3>> out;
    for (int sx = -1; sx <= 1; ++sx)
      for (int sy = -1; sy <= 1; ++sy)
        for (int sz = -1; sz <= 1; ++sz)
          if ((sx || sy || sz) && (!sx || axis[0]) && (!sy || axis[1]) && (!sz || axis[2])) out.push_back({sx, sy, sz});
    return out;
  }
};

/// The nearest image of a separation d along an axis of period L (0: none).
inline double min_image(double d, double L, double inv_L) { return d - L * std::nearbyint(d * inv_L); }

class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

/// Live contact histories keyed by their pairs' ids, as they leave one list
/// (NeighborList::live_histories) and enter the next build of another
/// (NeighborList::adopt_histories): what a particle that moves to another
/// rank takes along, for the pairs it leads (the lower id).
struct PairHistories {
  std::uint32_t stride = 0;               ///< history values per pair (the contact model's)
  std::vector<std::uint64_t> id_i, id_j;  ///< id_i < id_j
  std::vector<double> values;             ///< stride values per pair, in pair order
  std::size_t size() const { return id_i.size(); }
};

class NeighborList {
 public:
  void configure(double skin, uint32_t history_stride) {
    skin_ = skin;
    stride_ = history_stride;
  }
  double skin() const { return skin_; }
  void set_periodic(const PeriodicBox& box) { box_ = box; }
  const PeriodicBox& periodic() const { return box_; }
  uint32_t stride() const { return stride_; }

  /// Full check: the store's layout changed, or a particle moved more than
  /// half the skin since the last build.
  bool needs_rebuild(const ParticleStore& s) const;
  /// The layout part of needs_rebuild() alone (O(1)); callers that check the
  /// displacement themselves (fused into the drift loop) use this.
  bool layout_stale(const ParticleStore& s) const {
    return builds_ == 0 || s.size() != built_size_ || s.layout_version != built_version_;
  }
  /// Positions at the last build, and the squared displacement that forces a rebuild.
  const double* x0() const { return x0_.data(); }
  const double* y0() const { return y0_.data(); }
  const double* z0() const { return z0_.data(); }
  /// Half the skin less the growth since the build, squared; -1 (every
  /// displacement is beyond it, so the next check rebuilds) once the growth
  /// alone has used half the skin.
  double rebuild_displacement2() const { return allowance2(0.5 * skin_); }
  /// Particles that grow (Subdomain::grow) close gaps as displacements do: a
  /// pair unlisted at the build, at least the skin apart, closes it by at
  /// most twice the largest displacement plus twice the largest growth of a
  /// radius, so the displacement that forces a rebuild is half the skin less
  /// the growth since the build (`dr` is this step's largest growth).
  void add_growth(double dr) { grown_ += dr; }
  double grown() const { return grown_; }

  /// Two tiers (docs/performance.md): entries [0, near_size()) had a gap
  /// (distance minus radii) below near_gap() at the build, the rest at least
  /// near_gap(). A far entry can only touch once some particle has moved
  /// more than near_gap()/2 since the build (two particles close a gap by at
  /// most twice the largest displacement), so until then only the near tier
  /// needs the overlap screen. Within each tier entries keep build order.
  std::size_t near_size() const { return near_size_; }
  double near_gap() const { return kNearFraction * skin_; }
  double far_tier_displacement2() const { return allowance2(0.5 * near_gap()); }
  static constexpr double kNearFraction = 0.5;
  /// Build from the store's positions; with a pool of several threads the
  /// scan over particles runs in parallel (the same list as on one thread).
  /// With `owned` below the store's size, particles [owned, size) are ghosts
  /// (copies of other ranks' particles, distributed/): a pair is listed only
  /// when its lower id is owned here, since the rank owning that particle
  /// computes the pair (ghost-ghost pairs never).
  void build(const ParticleStore& s, ThreadPool* pool = nullptr, std::size_t owned = SIZE_MAX);
  /// The live histories (pairs in contact at the last force evaluation) by ids.
  PairHistories live_histories() const;
  /// Replace the live histories the next build() carries over by `h` (by
  /// ids): after particles moved between ranks with the pairs they lead.
  void adopt_histories(PairHistories h);
  std::size_t size() const { return i.size(); }
  /// Bytes held (capacity): the contact history, and everything else (the
  /// pair indices, the contact flags, the positions and ids of the last build).
  std::size_t history_bytes() const { return history.capacity() * sizeof(double); }
  std::size_t bytes_without_history() const {
    return (i.capacity() + j.capacity()) * sizeof(uint32_t) + touching.capacity() +
           (x0_.capacity() + y0_.capacity() + z0_.capacity()) * sizeof(double) +
           built_ids_.capacity() * sizeof(std::uint64_t);
  }
  std::size_t builds() const { return builds_; }
  /// The whole list as the next step would find it (pairs, tiers, history,
  /// contact flags, positions and ids at the last build, build counters), so
  /// that a restarted run goes on with the same list (checkpoints).
  void save(ArchiveWriter& w, const std::string& prefix) const;
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load, field by field (core/archive.hpp).
  void fields(CheckpointFields& f);

  std::vector<uint32_t> i, j;      ///< particle indices, id[i] < id[j]
  std::vector<double> history;     ///< size() * stride
  std::vector<uint8_t> touching;   ///< 1 while the pair is in contact (history live)

 private:
  template <class CellOf, class Visit>
  void for_each_periodic_pair(std::size_t a_first, std::size_t a_last, const int dim[3], const uint32_t* start,
                              const uint32_t* order, const double per[3], const double inv_per[3], CellOf&& cell_of,
                              const ParticleStore& s, double near_gap, Visit&& visit) const;
  /// (half - grown)^2, or -1 once the growth has used `half`
  double allowance2(double half) const {
    const double h = half - grown_;
    return h > 0 ? h * h : -1.0;
  }
  double skin_ = 0.0;
  double grown_ = 0.0;  ///< the largest radius growth since the build, summed over steps
  uint32_t stride_ = 0;
  PeriodicBox box_;
  std::size_t builds_ = 0;
  std::vector<double> x0_, y0_, z0_;
  std::vector<std::uint64_t> built_ids_;  ///< ids at the last build (history carry-over)
  std::size_t built_size_ = 0;
  std::uint64_t built_version_ = 0;
  std::size_t near_size_ = 0;
};

}  // namespace domel::platform
