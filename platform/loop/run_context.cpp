// SPDX-License-Identifier: MIT
// What components see of a run (component.hpp): the particles and
// statistics of a level at an output time, gathered once per time on ranks.
#include "loop/component.hpp"

#include "loop/ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <cmath>

namespace domel::platform {

RunContext::RunContext(std::vector<std::unique_ptr<Subdomain>>& subdomains_in, std::vector<WallPrimitive>& walls_in,
                       std::filesystem::path out_in, RunRanks& ranks_in, double macro_in, std::uint64_t first_in,
                       std::uint64_t stop_in, bool restart_in)
    : subdomains(subdomains_in),
      walls(walls_in),
      out(std::move(out_in)),
      ranks(ranks_in),
      writer(ranks_in.rank() == 0),
      macro(macro_in),
      first(first_in),
      stop(stop_in),
      restart(restart_in),
      gathered_(subdomains_in.size()),
      gathered_at_(subdomains_in.size(), std::nan("")) {}

RunContext::~RunContext() = default;

const ParticleStore& RunContext::particles(std::size_t k, double t) {
  if (!(gathered_at_[k] == t)) {
    gathered_[k] = ranks.gather(*subdomains[k]);
    gathered_at_[k] = t;
  }
  return *gathered_[k];
}

SubdomainStats RunContext::stats(std::size_t k, double t) {
  // the kinetic statistics of the whole set (rank 0's; on one process the
  // store's own), the counts and the largest overlap over the ranks
  const SubdomainStats local = subdomains[k]->stats();
  SubdomainStats st = kinetic_stats(particles(k, t));
  std::vector<std::uint64_t> counts{local.contacts, local.wall_contacts};
  ranks.sum(counts);
  st.contacts = counts[0];
  st.wall_contacts = counts[1];
  st.max_overlap_ratio = ranks.max(local.max_overlap_ratio);
  return st;
}

}  // namespace domel::platform
