// SPDX-License-Identifier: MIT
// The parts of the ranks interface (ranks.hpp) that read a subdomain: the
// gathered set's edits carried back to the owners, the contact records
// gathered by id, and the one-process implementation.
#include "loop/ranks.hpp"

#include "core/error.hpp"
#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <string>

namespace domel::platform {

namespace {
/// A record as it travels: the particles by id (j: kWall's id for a wall).
struct RecordById {
  std::uint64_t i, j;
  double f[3], p[3];
  std::uint64_t wall;
};
constexpr std::uint64_t kWallId = UINT64_MAX;
/// The contact records of the last force evaluation on every rank (each pair
/// once: on the rank that computed it), indexed into `all`, which holds
/// every rank's particles of sd in id order; in rank order. Collective.
std::vector<ContactRecord> gather_contact_records(RunRanks& ranks, const Subdomain& sd, const ParticleStore& all) {
  const ParticleStore& s = sd.store();
  std::vector<RecordById> mine;
  for (const std::vector<ContactRecord>* list : sd.contact_records())
    for (const ContactRecord& r : *list)
      mine.push_back({s.id[r.i], r.j == ContactRecord::kWall ? kWallId : s.id[r.j], {r.fx, r.fy, r.fz},
                      {r.px, r.py, r.pz}, r.wall});
  std::vector<char> bytes(mine.size() * sizeof(RecordById));
  if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
  auto index_of = [&](std::uint64_t id) {
    const auto it = std::lower_bound(all.id.begin(), all.id.end(), id);
    if (it == all.id.end() || *it != id)
      throw RuntimeError("subdomain '" + sd.name() + "': a contact record names particle id " + std::to_string(id) +
                         ", which no rank holds");
    return static_cast<std::uint32_t>(it - all.id.begin());
  };
  std::vector<ContactRecord> out;
  for (const auto& b : ranks.all_gather(bytes))
    for (std::size_t at = 0; at + sizeof(RecordById) <= b.size(); at += sizeof(RecordById)) {
      RecordById r;
      std::memcpy(&r, b.data() + at, sizeof(r));
      ContactRecord c{};
      c.i = index_of(r.i);
      c.j = r.j == kWallId ? ContactRecord::kWall : index_of(r.j);
      c.fx = r.f[0]; c.fy = r.f[1]; c.fz = r.f[2];
      c.px = r.p[0]; c.py = r.p[1]; c.pz = r.p[2];
      c.wall = static_cast<std::uint32_t>(r.wall);
      out.push_back(c);
    }
  return out;
}

}  // namespace

std::vector<std::size_t> RunRanks::where_in_gathered(Subdomain& sd, const ParticleStore& whole,
                                                     const std::string& who) {
  const ParticleStore& s = sd.store();
  std::vector<std::size_t> at(sd.owned());
  for (std::size_t q = 0; q < at.size(); ++q) {
    const auto it = std::lower_bound(whole.id.begin(), whole.id.end(), s.id[q]);
    if (it == whole.id.end() || *it != s.id[q])
      throw RuntimeError(who + ": particle id " + std::to_string(s.id[q]) + " of subdomain '" + sd.name() +
                         "' is missing from its level's gathered particles");
    at[q] = static_cast<std::size_t>(it - whole.id.begin());
  }
  return at;
}

void RunRanks::removed(Subdomain& sd, std::vector<std::uint64_t> ids) {
  if (ids.empty()) return;
  std::sort(ids.begin(), ids.end());
  ParticleStore& s = sd.particles_to_edit();
  std::vector<std::uint8_t> mark(s.size(), 0);
  for (std::size_t q = 0; q < s.size(); ++q) mark[q] = std::binary_search(ids.begin(), ids.end(), s.id[q]) ? 1 : 0;
  s.remove_marked(mark);
}

std::pair<std::size_t, std::size_t> RunRanks::keep_added(Subdomain& sd, const ParticleStore& whole,
                                                         std::size_t first) {
  std::vector<std::uint32_t> mine;
  for (std::size_t k = first; k < whole.size(); ++k)
    if (sd.keeps(whole.id[k])) mine.push_back(static_cast<std::uint32_t>(k));
  if (mine.empty()) return {0, 0};
  ParticleStore& own = sd.particles_to_edit();
  own.append(whole, mine);
  return {own.size() - mine.size(), own.size()};
}

std::vector<const std::vector<ContactRecord>*> RunRanks::contact_records(Subdomain& sd, const ParticleStore& whole,
                                                                         std::vector<ContactRecord>& storage) {
  storage = gather_contact_records(*this, sd, whole);
  return {&storage};
}

RunRanks& one_process() {
  static SingleProcess ranks;
  return ranks;
}

GatheredParticles SingleProcess::gather(Subdomain& sd, bool) { return GatheredParticles(sd.store()); }

std::vector<std::size_t> SingleProcess::where_in_gathered(Subdomain& sd, const ParticleStore&, const std::string&) {
  std::vector<std::size_t> at(sd.owned());
  std::iota(at.begin(), at.end(), std::size_t{0});
  return at;
}

std::vector<const std::vector<ContactRecord>*> SingleProcess::contact_records(Subdomain& sd, const ParticleStore&,
                                                                              std::vector<ContactRecord>&) {
  return sd.contact_records();
}

}  // namespace domel::platform
