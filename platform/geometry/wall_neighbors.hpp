// SPDX-License-Identifier: MIT
// Per-wall candidate lists: the particles within (radius + skin) of one wall
// primitive (for a mesh: the (particle, triangle) pairs within radius +
// skin), rebuilt with the particle neighbour list or when the wall has moved
// more than skin/2, with per-contact history carried across rebuilds and
// re-ordering by particle id (and triangle).
#pragma once

#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "geometry/triangle_mesh.hpp"
#include "geometry/wall.hpp"

#include <cstdint>
#include <vector>

namespace domel::platform {

class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

/// Candidate particles of one wall primitive, with per-contact history.
class WallNeighbors {
 public:
  /// Rebuild the candidates of wall `w` (placed at its current position).
  /// An inactive wall (`active` false) gets an empty list. Only particles
  /// [0, count) are candidates (the rank's own, not its ghosts).
  void build(const ParticleStore& s, const WallPrimitive& w, double skin, uint32_t stride, bool active = true,
             std::size_t count = SIZE_MAX);
  /// Drop every candidate and its history (a wall that is removed or not yet active).
  void clear();
  /// The live contacts' histories keyed by particle id (id_i) and triangle
  /// (id_j; 0 for a primitive), `stride` values each; and the inverse: the
  /// next build() carries `h` over (particles that moved between ranks took
  /// their wall contacts along).
  PairHistories live_histories(uint32_t stride) const;
  void adopt_histories(PairHistories h);
  /// Bytes held (capacity): the history rows, and everything else.
  std::size_t history_bytes() const { return history.capacity() * sizeof(double); }
  std::size_t bytes_without_history() const {
    return (particle.capacity() + triangle.capacity()) * sizeof(uint32_t) +
           particle_id.capacity() * sizeof(std::uint64_t) + touching.capacity();
  }
  /// The candidates, their history and build state (checkpoints; the
  /// triangle grid is a cache, rebuilt on demand).
  void save(ArchiveWriter& w, const std::string& prefix) const;
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load, field by field (core/archive.hpp).
  void fields(CheckpointFields& f);
  std::vector<uint32_t> particle;      ///< particle indices at this build (ascending)
  std::vector<std::uint64_t> particle_id;  ///< their ids (history is carried over by id)
  std::vector<uint32_t> triangle;      ///< mesh walls: the candidate triangle of each entry
  std::vector<double> history;
  std::vector<uint8_t> touching;
  double built_time = 0.0;             ///< the simulated time of the wall's placement at this build (NaN: unknown)
  bool built = false;                  ///< built while the wall was active

 private:
  TriangleGrid grid_;
  bool grid_valid_ = false;
  double grid_reach_ = 0.0;
  std::vector<uint32_t> query_;
};

}  // namespace domel::platform
