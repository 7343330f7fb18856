// SPDX-License-Identifier: MIT
#include "outputs/gathered_contacts.hpp"

#include "core/error.hpp"
#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <cstring>
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
}  // namespace

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

}  // namespace domel::platform
