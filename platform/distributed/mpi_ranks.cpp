// SPDX-License-Identifier: MIT
#include "distributed/mpi_ranks.hpp"

#include "distributed/particle_exchange.hpp"
#include "distributed/subdomain_ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <numeric>
#include <utility>

namespace domel::platform {

void MpiRunRanks::distribute(Subdomain& sd, int first, int count) {
  // every rank built the same particles: each rank of the group keeps every
  // count-th by id (the first exchange moves each to the owner of its
  // place); the ranks outside keep none. A group of one rank holds the
  // subdomain as one process does (no exchange: the fused step).
  const bool whole = count <= 0 || (first == 0 && count == comm_.size());
  const bool member = whole || (comm_.rank() >= first && comm_.rank() < first + count);
  const Communicator group = whole ? comm_ : comm_.split(member ? 0 : 1);
  group_size_.emplace_back(&sd, whole ? comm_.size() : count);
  if (member && group.size() == 1) return;
  ParticleStore& s = sd.store();
  std::vector<std::uint8_t> other(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) other[k] = !member || !starts_on_rank(s.id[k], group.rank(), group.size());
  s.remove_marked(other);
  if (!member) {
    sd.set_elsewhere();
    return;
  }
  spread_.emplace_back(&sd, &platform::distribute(sd, group));
}

nlohmann::json MpiRunRanks::traffic(const Subdomain& sd) {
  RankTraffic t;
  for (const auto& [s, r] : spread_)
    if (s == &sd) t = r->traffic();
  std::vector<std::uint64_t> v{t.migrations, t.migrated,  t.histories_sent, t.ghost_builds, t.ghosts,
                               t.updates,    t.update_bytes, t.reverses,   t.reverse_bytes};
  comm_.sum(v);
  std::uint64_t ranks = 1;
  for (const auto& [s, n] : group_size_)
    if (s == &sd) ranks = static_cast<std::uint64_t>(n);
  return {{"list_builds", v[0] / ranks},
          {"particles_migrated", v[1]},
          {"contact_histories_migrated", v[2]},
          {"ghosts_per_build", v[3] > 0 ? static_cast<double>(v[4]) / static_cast<double>(v[3] / ranks) : 0.0},
          {"ghost_update_bytes_per_step", v[5] > 0 ? static_cast<double>(v[6]) / static_cast<double>(v[5] / ranks) : 0.0},
          {"reverse_bytes_per_step", v[7] > 0 ? static_cast<double>(v[8]) / static_cast<double>(v[7] / ranks) : 0.0}};
}


GatheredParticles MpiRunRanks::gather(Subdomain& sd, bool everywhere) {
  sd.collect_contact_counts();  // the contacts with ghosts counted at their owners too
  const ParticleStore& s = sd.store();
  std::vector<std::uint32_t> mine(sd.owned());
  std::iota(mine.begin(), mine.end(), 0u);
  std::vector<std::vector<char>> send(static_cast<std::size_t>(comm_.size()));
  send[0] = pack_particles(s, mine);
  const auto recv = everywhere ? comm_.all_gather(send[0]) : comm_.all_to_all(send);
  ParticleStore all = s.empty_like();
  if (comm_.rank() != 0 && !everywhere) return GatheredParticles(std::move(all));
  for (const auto& b : recv) unpack_particles(all, b);
  std::vector<std::uint32_t> order(all.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return all.id[a] < all.id[b]; });
  all.permute(order);
  return GatheredParticles(std::move(all));
}

}  // namespace domel::platform
