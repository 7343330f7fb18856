// SPDX-License-Identifier: MIT
// A subdomain's checkpoints: what the next step depends on, written after
// finishing the last step and read back instead of setup().
#include "subdomain/subdomain.hpp"

#include "core/archive.hpp"
#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <utility>

namespace domel::platform {

/// What a subdomain's "state/" section holds beside its parts (particles,
/// lists, walls, split, exchange): one list of fields for both directions.
struct SubdomainSavedState {
  double time = 0, dt = 0, coarse_grain = 0, skin = 0, max_overlap_ratio = 0, wall_time = 0, forces_time = 0;
  std::uint64_t steps = 0, contacts = 0, wall_contacts = 0, builds_since_reorder = 0, reordered_size = 0;
  bool far_active = false, walls_force_rebuild = false;
  bool ranked = false;  ///< a part of a subdomain spread over ranks
  std::uint64_t rank = 0, ranks = 1, owned = 0, ghosts_end = 0;
  bool edited = false;
  std::uint64_t walls = 0;
  std::vector<std::uint64_t> thread_pair_contacts;

  void fields(CheckpointFields& f) {
    f("time", time);
    f("dt", dt);
    f("coarse_grain", coarse_grain);
    f("skin", skin);
    f("max_overlap_ratio", max_overlap_ratio);
    f("wall_time", wall_time);
    f("forces_time", forces_time);
    f("steps", steps);
    f("contacts", contacts);
    f("wall_contacts", wall_contacts);
    f("builds_since_reorder", builds_since_reorder);
    f("reordered_size", reordered_size);
    f("far_active", far_active);
    f("walls_force_rebuild", walls_force_rebuild);
    f("ranked", ranked);
    if (ranked) {
      f("rank", rank);
      f("ranks", ranks);
      f("owned", owned);
      f("ghosts_end", ghosts_end);
      f("edited", edited);
    }
    f("walls", walls);
    f("thread_pair_contacts", thread_pair_contacts);
  }
};

void Subdomain::save(ArchiveWriter& w, const std::string& p) {
  store();  // finishes the last step and counts the contacts
  if (edited_)
    throw RuntimeError("subdomain '" + name_ + "': a checkpoint between an edit of the particles and the next step "
                       "(the ghosts are dropped, the lists name them) cannot be written");
  SubdomainSavedState st{time_, dt_, coarse_grain_, skin_, last_max_overlap_ratio_, wall_time_, forces_time_,
                steps_, last_contacts_, last_wall_contacts_, builds_since_reorder_, reordered_size_,
                far_active_, walls_force_rebuild_};
  // over ranks, this rank's part: its own particles, then its ghosts, and
  // who holds which ghosts (the fields are written for a part of a rank)
  st.ranked = ranks_->over_ranks();
  st.rank = static_cast<std::uint64_t>(ranks_->rank());
  st.ranks = static_cast<std::uint64_t>(ranks_->size());
  st.owned = owned();
  st.ghosts_end = store_.size();
  st.edited = edited_;
  ranks_->save(w, p + "exchange/");
  st.walls = wall_lists_.size();
  for (const auto& ts : scratch_) st.thread_pair_contacts.push_back(ts.pair_contacts);
  save_fields(w, p + "state/", [&](CheckpointFields& f) { st.fields(f); });
  store_.save(w, p + "particles/");
  nlist_.save(w, p + "pairs/");
  for (std::size_t k = 0; k < wall_lists_.size(); ++k) wall_lists_[k].save(w, p + "wall" + std::to_string(k) + "/");
  partition_.save(w, p + "split/");
}

bool Subdomain::restore(const ArchiveReader& r, const std::string& p) {
  SubdomainSavedState st;
  const std::size_t own = load_state(r, p, &st);
  if (st.ranked != ranks_->over_ranks())
    r.fail(p + "state/ranked", st.ranked ? "holds a subdomain spread over ranks; this run is one process"
                                         : "holds a subdomain of one process; this run is spread over ranks");
  if (st.rank != static_cast<std::uint64_t>(ranks_->rank()) || st.ranks != static_cast<std::uint64_t>(ranks_->size()))
    r.fail(p + "state/rank", "is rank " + std::to_string(st.rank) + " of " + std::to_string(st.ranks) +
                                 ", not rank " + std::to_string(ranks_->rank()) + " of " +
                                 std::to_string(ranks_->size()));
  if (own > st.ghosts_end || st.ghosts_end != store_.size())
    r.fail(p + "state/ghosts_end", "does not count the part's own particles and ghosts");
  ghosts_ = store_.size() - own;
  ghosts_end_ = store_.size();
  edited_ = st.edited;
  ranks_->load(r, p + "exchange/", own, ghosts_end_);
  if (st.thread_pair_contacts.size() != scratch_.size()) return false;  // the split is rebuilt at the next evaluation
  partition_.load(r, p + "split/");
  for (std::size_t t = 0; t < scratch_.size(); ++t) scratch_[t].pair_contacts = st.thread_pair_contacts[t];
  return true;
}

void Subdomain::restore_shared_out(const std::vector<std::pair<const ArchiveReader*, std::string>>& parts) {
  // Every part's own particles whose id falls to this rank (id modulo the
  // rank count, as at the start of a run), with the histories of the pairs
  // and wall contacts they lead, keyed by ids; then the exchange moves each
  // particle to the owner of its place with its histories, and the lists
  // are built anew, carrying the histories over by ids. The forces are the
  // checkpoint's (complete on their owners), so the next step goes on from
  // the saved state.
  const uint32_t stride = pipeline_->history_stride();
  std::optional<ParticleStore> kept;
  std::vector<PairHistories> h(1 + wall_lists_.size());
  for (auto& set : h) set.stride = stride;
  auto take_rows = [&](PairHistories& into, const PairHistories& from) {
    for (std::size_t k = 0; k < from.size(); ++k) {
      if (!keeps(from.id_i[k])) continue;
      into.id_i.push_back(from.id_i[k]);
      into.id_j.push_back(from.id_j[k]);
      into.values.insert(into.values.end(), from.values.begin() + static_cast<std::ptrdiff_t>(k * stride),
                         from.values.begin() + static_cast<std::ptrdiff_t>((k + 1) * stride));
    }
  };
  double max_overlap_ratio = 0.0;
  for (const auto& [r, p] : parts) {
    const std::size_t own = load_state(*r, p);
    max_overlap_ratio = std::max(max_overlap_ratio, last_max_overlap_ratio_);
    take_rows(h[0], nlist_.live_histories());
    for (std::size_t w = 0; w < wall_lists_.size(); ++w) take_rows(h[1 + w], wall_lists_[w].live_histories(stride));
    std::vector<std::uint8_t> drop(store_.size());
    for (std::size_t k = 0; k < store_.size(); ++k) drop[k] = k >= own || !keeps(store_.id[k]);
    store_.remove_marked(drop);
    if (!kept) kept.emplace(store_);  // a copy: the next part loads into store_ as configured (aux arrays)
    else kept->append(store_);
  }
  store_ = std::move(*kept);
  nlist_.adopt_histories(std::move(h[0]));
  for (std::size_t w = 0; w < wall_lists_.size(); ++w)
    if (wall_lists_[w].built) wall_lists_[w].adopt_histories(std::move(h[1 + w]));
  ghosts_ = 0;
  ghosts_end_ = store_.size();
  edited_ = false;
  exchange();
  rebuild_lists();
  // the statistics of the last evaluation, as this rank's lists hold them
  // now: the contacts whose histories were carried over
  last_contacts_ = 0;
  for (std::uint8_t t : nlist_.touching) last_contacts_ += t;
  last_wall_contacts_ = 0;
  for (const WallNeighbors& w : wall_lists_)
    for (std::uint8_t t : w.touching) last_wall_contacts_ += t;
  last_max_overlap_ratio_ = max_overlap_ratio;
  contacts_counted_ = false;
  contacts_collected_ = false;
}

std::size_t Subdomain::load_state(const ArchiveReader& r, const std::string& p, SubdomainSavedState* saved) {
  synchronize();
  SubdomainSavedState local;
  SubdomainSavedState& st = saved ? *saved : local;
  load_fields(r, p + "state/", [&](CheckpointFields& f) { st.fields(f); });
  if (st.dt != dt_)
    r.fail(p + "state/dt", "was written with a time step of " + std::to_string(st.dt) + " s; subdomain '" + name_ +
                               "' now steps " + std::to_string(dt_) + " s");
  if (st.coarse_grain != coarse_grain_)
    r.fail(p + "state/coarse_grain", "was written with coarse_grain " + std::to_string(st.coarse_grain) +
                                         "; subdomain '" + name_ + "' now has " + std::to_string(coarse_grain_));
  if (st.skin != skin_) r.fail(p + "state/skin", "was written with another neighbour-list skin");
  nlist_.configure(skin_, pipeline_->history_stride());
  // particles placed small by a refinement at the start (a coupling whose fine
  // level started empty: Coupling::refine_at_start) carry the growth fields,
  // which a restarted scenario only adds when it refines again: add them here
  if (r.has(p + "particles/grow_to")) enable_growth();
  store_.load(r, p + "particles/");
  if (!st.ranked) st.owned = st.ghosts_end = store_.size();  // a part of one process: all its own, no ghosts
  const auto own = static_cast<std::size_t>(st.owned);
  if (own > store_.size()) r.fail(p + "state/owned", "counts more particles than the part holds");
  nlist_.load(r, p + "pairs/");
  const std::size_t n = store_.size();
  for (std::size_t e = 0; e < nlist_.size(); ++e)
    if (nlist_.i[e] >= n || nlist_.j[e] >= n) r.fail(p + "pairs/i", "names a particle beyond the store");
  if (st.walls != wall_lists_.size())
    r.fail(p + "state/walls", "holds " + std::to_string(st.walls) + " walls; the scenario has " +
                                  std::to_string(wall_lists_.size()));
  for (std::size_t k = 0; k < wall_lists_.size(); ++k) {
    const std::string wp = p + "wall" + std::to_string(k) + "/";
    wall_lists_[k].load(r, wp);
    for (uint32_t q : wall_lists_[k].particle)
      if (q >= n) r.fail(wp + "particle", "names a particle beyond the store");
    if (wall_lists_[k].history.size() != wall_lists_[k].particle.size() * pipeline_->history_stride())
      r.fail(wp + "history", "does not hold this contact model's history per candidate");
  }
  time_ = st.time;
  last_max_overlap_ratio_ = st.max_overlap_ratio;
  wall_time_ = st.wall_time;
  forces_time_ = st.forces_time;
  steps_ = st.steps;
  last_contacts_ = static_cast<std::size_t>(st.contacts);
  last_wall_contacts_ = static_cast<std::size_t>(st.wall_contacts);
  builds_since_reorder_ = static_cast<std::size_t>(st.builds_since_reorder);
  reordered_size_ = static_cast<std::size_t>(st.reordered_size);
  far_active_ = st.far_active;
  walls_force_rebuild_ = st.walls_force_rebuild;
  for (std::size_t w = 0; w < walls_now_.size(); ++w)
    if (walls_now_[w].moving) walls_now_[w].place((*walls_)[w], wall_time_);
  if (gravity_) gravity_->at(time_, body_forces_.gravity);  // the loaded forces' time
  kick_pending_ = false;
  reduce_pending_ = false;
  contacts_counted_ = true;
  find_growth();
  return own;
}

}  // namespace domel::platform
