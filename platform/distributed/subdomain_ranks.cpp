// SPDX-License-Identifier: MIT
#include "distributed/subdomain_ranks.hpp"

#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace domel::platform {

SubdomainRanks::SubdomainRanks(Communicator comm, const PeriodicBox& box) : comm_(std::move(comm)), box_(box) {}

void SubdomainRanks::any(bool* flags, std::size_t n) {
  if (comm_.size() == 1) return;
  std::vector<std::uint64_t> v(flags, flags + n);
  comm_.sum(v);
  for (std::size_t k = 0; k < n; ++k) flags[k] = v[k] != 0;
}

double SubdomainRanks::max(double x) { return comm_.max(x); }

Region SubdomainRanks::extent(const ParticleStore& s, std::size_t owned) const {
  // lo and -hi per axis, gathered: the smallest of each over the ranks
  std::vector<double> bounds(6, std::numeric_limits<double>::max());
  for (std::size_t k = 0; k < owned; ++k) {
    const double p[3] = {s.x[k], s.y[k], s.z[k]};
    for (int a = 0; a < 3; ++a) {
      bounds[static_cast<std::size_t>(a)] = std::min(bounds[static_cast<std::size_t>(a)], p[a]);
      bounds[static_cast<std::size_t>(3 + a)] = std::min(bounds[static_cast<std::size_t>(3 + a)], -p[a]);
    }
  }
  std::vector<char> mine(bounds.size() * sizeof(double));
  std::memcpy(mine.data(), bounds.data(), mine.size());
  for (const auto& b : comm_.all_gather(mine))
    for (std::size_t i = 0; i < bounds.size(); ++i) {
      double v = 0.0;
      std::memcpy(&v, b.data() + i * sizeof(double), sizeof(double));
      bounds[i] = std::min(bounds[i], v);
    }
  Region r{};
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    r.lo[a] = box_.axis[a] ? box_.lo[a] : bounds[i];
    r.hi[a] = box_.axis[a] ? box_.hi[a] : -bounds[3 + i];
    if (!(r.lo[a] <= r.hi[a])) r.lo[a] = r.hi[a] = 0.0;  // no particles anywhere
  }
  return r;
}

std::size_t SubdomainRanks::migrate(ParticleStore& s, std::size_t owned, const std::vector<std::uint64_t>& cost,
                                    const std::vector<PairHistories*>& histories) {
  s.truncate(owned);
  box_.wrap(s);
  if (comm_.size() > 1) {
    d_ = Decomposition::bisect(extent(s, owned), comm_.size(), s.x.data(), s.y.data(), s.z.data(), cost.data(),
                               s.size(), comm_);
  }
  const ExchangeCounts c = platform::migrate(s, d_, comm_, histories);
  ++traffic_.migrations;
  traffic_.migrated += c.sent;
  traffic_.histories_sent += c.histories_sent;
  return s.size();
}

void SubdomainRanks::save(ArchiveWriter& w, const std::string& p) const {
  ghosts_.save(w, p + "ghosts/");
  save_fields(w, p + "traffic/", [&](CheckpointFields& f) { const_cast<SubdomainRanks*>(this)->traffic_fields(f); });
}

void SubdomainRanks::load(const ArchiveReader& r, const std::string& p, std::size_t owned, std::size_t ghosts_end) {
  ghosts_.load(r, p + "ghosts/", comm_.size());
  load_fields(r, p + "traffic/", [&](CheckpointFields& f) { traffic_fields(f); });
  // the ghosts of the last build sit after the part's own particles; a part
  // without ghosts may have had particles added since that build
  const bool placed = ghosts_.owned() == owned && ghosts_.size() == ghosts_end;
  const bool none = ghosts_end == owned && ghosts_.size() == ghosts_.owned();
  if (!placed && !none) r.fail(p + "ghosts/first", "does not place the ghosts after the rank's own particles");
}

void SubdomainRanks::traffic_fields(CheckpointFields& f) {
  RankTraffic& t = traffic_;
  f("migrations", t.migrations);
  f("migrated", t.migrated);
  f("histories_sent", t.histories_sent);
  f("ghost_builds", t.ghost_builds);
  f("ghosts", t.ghosts);
  f("updates", t.updates);
  f("update_bytes", t.update_bytes);
  f("reverses", t.reverses);
  f("reverse_bytes", t.reverse_bytes);
}

void SubdomainRanks::build_ghosts(ParticleStore& s, std::size_t owned, double skin) {
  double rmax = 0.0;
  for (std::size_t k = 0; k < owned; ++k) rmax = std::max(rmax, s.radius[k]);
  const ExchangeCounts c = ghosts_.build(s, owned, d_, 2.0 * max(rmax) + skin, comm_, box_);
  ++traffic_.ghost_builds;
  traffic_.ghosts += c.received;
}

void SubdomainRanks::update_ghosts(ParticleStore& s) {
  ghosts_.update(s, comm_);
  ++traffic_.updates;
  traffic_.update_bytes += ghosts_.update_bytes(s);
}

void SubdomainRanks::reverse(ParticleStore& s) {
  ghosts_.reverse(s, comm_);
  ++traffic_.reverses;
  traffic_.reverse_bytes += ghosts_.reverse_bytes(s);
}

SubdomainRanks& distribute(Subdomain& sd, const Communicator& comm) {
  auto ranks = std::make_unique<SubdomainRanks>(comm, sd.periodic());
  SubdomainRanks& out = *ranks;
  sd.set_rank_exchange(std::move(ranks));
  return out;
}

}  // namespace domel::platform
