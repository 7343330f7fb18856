// SPDX-License-Identifier: MIT
#include "distributed/run_ranks.hpp"

#include "distributed/particle_exchange.hpp"
#include "distributed/subdomain_ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <numeric>

namespace domel::platform {

void MpiRunRanks::distribute(Subdomain& sd) {
  // every rank built the same particles: keep every size-th by id (the first
  // exchange moves each to the owner of its place)
  ParticleStore& s = sd.store();
  const auto n = static_cast<std::uint64_t>(comm_.size()), me = static_cast<std::uint64_t>(comm_.rank());
  std::vector<std::uint8_t> other(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) other[k] = s.id[k] % n != me;
  s.remove_marked(other);
  platform::distribute(sd, comm_);
}


ParticleStore MpiRunRanks::gather(Subdomain& sd) {
  const ParticleStore& s = sd.store();
  std::vector<std::uint32_t> mine(sd.owned());
  std::iota(mine.begin(), mine.end(), 0u);
  std::vector<std::vector<char>> send(static_cast<std::size_t>(comm_.size()));
  send[0] = pack_particles(s, mine);
  const auto recv = comm_.all_to_all(send);
  ParticleStore all;
  if (s.has_external_force()) all.enable_external_force();
  all.add_aux(s.aux.size());
  if (comm_.rank() != 0) return all;
  for (const auto& b : recv) unpack_particles(all, b);
  std::vector<std::uint32_t> order(all.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return all.id[a] < all.id[b]; });
  all.permute(order);
  return all;
}

}  // namespace domel::platform
