// SPDX-License-Identifier: MIT
// Particles between ranks (issue 19): migration of owned particles to the
// rank whose region holds them, and ghost copies of the particles within the
// list cut-off of another rank's region. A particle travels as every
// per-particle array of the store (ParticleStore::for_each_array), so what a
// module adds to the store (external forces, aux arrays) travels with it.
#pragma once

#include "core/particle_store.hpp"
#include "distributed/communicator.hpp"
#include "distributed/decomposition.hpp"

#include <cstdint>
#include <vector>

namespace domel::platform {

/// Bytes one particle of this store takes (every array's element).
std::size_t particle_bytes(const ParticleStore& s);
/// Particles `which` of s, in that order, as bytes.
std::vector<char> pack_particles(const ParticleStore& s, const std::vector<std::uint32_t>& which);
/// Append the particles of `bytes` (packed from a store of the same layout:
/// the same external-force switch and aux count) to s.
void unpack_particles(ParticleStore& s, const std::vector<char>& bytes);

struct ExchangeCounts {
  std::size_t sent = 0, received = 0;
};

/// Send every particle whose owner is another rank there, and append the
/// ones other ranks send here (by sending rank, each in its store order).
/// Collective.
ExchangeCounts migrate(ParticleStore& s, const Decomposition& d, const Communicator& comm);

/// The ghosts of this rank: copies of other ranks' particles within `cutoff`
/// of its region, by sending rank, each in its store order (`ghosts` is
/// replaced; its layout follows `owned`). Collective.
ExchangeCounts exchange_ghosts(const ParticleStore& owned, ParticleStore& ghosts, const Decomposition& d,
                               double cutoff, const Communicator& comm);

}  // namespace domel::platform
