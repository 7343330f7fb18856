// SPDX-License-Identifier: MIT
// A subdomain's checkpoints: what the next step depends on, written after
// finishing the last step and read back instead of setup().
#include "subdomain/subdomain.hpp"

#include "core/archive.hpp"
#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <utility>

namespace domel::platform {

void Subdomain::save(ArchiveWriter& w, const std::string& p) {
  if (ranks_)
    throw RuntimeError("subdomain '" + name_ + "': checkpoints of a subdomain spread over ranks are not supported yet "
                       "(docs/distributed.md)");
  store();  // finishes the last step and counts the contacts
  store_.save(w, p + "particles/");
  nlist_.save(w, p + "pairs/");
  w.put_scalar<std::uint64_t>(p + "walls", wall_lists_.size());
  for (std::size_t k = 0; k < wall_lists_.size(); ++k) wall_lists_[k].save(w, p + "wall" + std::to_string(k) + "/");
  partition_.save(w, p + "split/");
  std::vector<std::uint64_t> pair_contacts;
  for (const auto& ts : scratch_) pair_contacts.push_back(ts.pair_contacts);
  w.put(p + "thread_pair_contacts", pair_contacts);
  w.put(p + "reals", std::vector<double>{time_, dt_, coarse_grain_, skin_, last_max_overlap_ratio_, wall_time_,
                                         forces_time_});
  w.put(p + "counters", std::vector<std::uint64_t>{steps_, last_contacts_, last_wall_contacts_, builds_since_reorder_,
                                                   reordered_size_, far_active_ ? 1u : 0u,
                                                   walls_force_rebuild_ ? 1u : 0u});
}

bool Subdomain::restore(const ArchiveReader& r, const std::string& p) {
  synchronize();
  const auto reals = r.get<double>(p + "reals");
  const auto counters = r.get<std::uint64_t>(p + "counters");
  if (reals.size() != 7) r.fail(p + "reals", "holds " + std::to_string(reals.size()) + " values, expected 7");
  if (counters.size() != 7) r.fail(p + "counters", "holds " + std::to_string(counters.size()) + " values, expected 7");
  if (reals[1] != dt_)
    r.fail(p + "reals", "was written with a time step of " + std::to_string(reals[1]) + " s; subdomain '" + name_ +
                            "' now steps " + std::to_string(dt_) + " s");
  if (reals[2] != coarse_grain_)
    r.fail(p + "reals", "was written with coarse_grain " + std::to_string(reals[2]) + "; subdomain '" + name_ +
                            "' now has " + std::to_string(coarse_grain_));
  if (reals[3] != skin_) r.fail(p + "reals", "was written with another neighbour-list skin");
  nlist_.configure(skin_, pipeline_->history_stride());
  store_.load(r, p + "particles/");
  nlist_.load(r, p + "pairs/");
  const std::size_t n = store_.size();
  for (std::size_t e = 0; e < nlist_.size(); ++e)
    if (nlist_.i[e] >= n || nlist_.j[e] >= n) r.fail(p + "pairs/i", "names a particle beyond the store");
  if (r.scalar<std::uint64_t>(p + "walls") != wall_lists_.size())
    r.fail(p + "walls", "holds " + std::to_string(r.scalar<std::uint64_t>(p + "walls")) + " walls; the scenario has " +
                            std::to_string(wall_lists_.size()));
  for (std::size_t k = 0; k < wall_lists_.size(); ++k) {
    const std::string wp = p + "wall" + std::to_string(k) + "/";
    wall_lists_[k].load(r, wp);
    for (uint32_t q : wall_lists_[k].particle)
      if (q >= n) r.fail(wp + "particle", "names a particle beyond the store");
    if (wall_lists_[k].history.size() != wall_lists_[k].particle.size() * pipeline_->history_stride())
      r.fail(wp + "history", "does not hold this contact model's history per candidate");
  }
  time_ = reals[0];
  last_max_overlap_ratio_ = reals[4];
  wall_time_ = reals[5];
  forces_time_ = reals[6];
  steps_ = counters[0];
  last_contacts_ = counters[1];
  last_wall_contacts_ = counters[2];
  builds_since_reorder_ = counters[3];
  reordered_size_ = counters[4];
  far_active_ = counters[5] != 0;
  walls_force_rebuild_ = counters[6] != 0;
  for (std::size_t w = 0; w < walls_now_.size(); ++w)
    if (walls_now_[w].moving) walls_now_[w].place((*walls_)[w], wall_time_);
  if (gravity_) gravity_->at(time_, body_forces_.gravity);  // the loaded forces' time
  kick_pending_ = false;
  reduce_pending_ = false;
  contacts_counted_ = true;
  const auto pair_contacts = r.get<std::uint64_t>(p + "thread_pair_contacts");
  if (pair_contacts.size() != scratch_.size()) return false;  // the split is rebuilt at the next evaluation
  partition_.load(r, p + "split/");
  for (std::size_t t = 0; t < scratch_.size(); ++t) scratch_[t].pair_contacts = pair_contacts[t];
  return true;
}

}  // namespace domel::platform
