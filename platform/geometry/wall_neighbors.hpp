// SPDX-License-Identifier: MIT
// Per-wall candidate lists: the particles within (radius + skin) of one wall
// primitive, rebuilt with the particle neighbour list, with per-contact
// history carried across rebuilds and re-ordering by particle id.
#pragma once

#include "core/particle_store.hpp"
#include "geometry/wall.hpp"

#include <cstdint>
#include <vector>

namespace domel::platform {

/// Candidate particles of one wall primitive, with per-contact history.
class WallNeighbors {
 public:
  void build(const ParticleStore& s, const WallPrimitive& w, double skin, uint32_t stride);
  std::vector<uint32_t> particle;      ///< particle indices at this build
  std::vector<std::uint64_t> particle_id;  ///< their ids (history is carried over by id)
  std::vector<double> history;
  std::vector<uint8_t> touching;
};

}  // namespace domel::platform
