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

void Subdomain::save(ArchiveWriter& w, const std::string& p) {
  store();  // finishes the last step and counts the contacts
  if (ranks_ && edited_)
    throw RuntimeError("subdomain '" + name_ + "': a checkpoint between an edit of the particles and the next step "
                       "(the ghosts are dropped, the lists name them) cannot be written");
  if (ranks_) {
    // this rank's part: its own particles, then its ghosts, and who holds which ghosts
    w.put(p + "rank", std::vector<std::uint64_t>{static_cast<std::uint64_t>(ranks_->rank()),
                                                 static_cast<std::uint64_t>(ranks_->size()), owned_, ghosts_end_,
                                                 edited_ ? 1u : 0u});
    ranks_->save(w, p + "exchange/");
  }
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
  if (r.has(p + "rank") != (ranks_ != nullptr))
    r.fail(p + "rank", ranks_ ? "holds a subdomain of one process; this run is spread over ranks"
                              : "holds a subdomain spread over ranks; this run is one process");
  const std::size_t own = load_state(r, p);
  if (ranks_) {
    const auto rank = r.get<std::uint64_t>(p + "rank");
    if (rank[0] != static_cast<std::uint64_t>(ranks_->rank()) || rank[1] != static_cast<std::uint64_t>(ranks_->size()))
      r.fail(p + "rank", "is rank " + std::to_string(rank[0]) + " of " + std::to_string(rank[1]) + ", not rank " +
                             std::to_string(ranks_->rank()) + " of " + std::to_string(ranks_->size()));
    owned_ = own;
    ghosts_end_ = rank[3];
    edited_ = rank[4] != 0;
    if (owned_ > ghosts_end_ || ghosts_end_ != store_.size())
      r.fail(p + "rank", "does not count the part's own particles and ghosts");
    ranks_->load(r, p + "exchange/");
    if (ranks_->ghosts_begin() != owned_ || ranks_->ghosts_end() != ghosts_end_)
      r.fail(p + "exchange/ghosts/first", "does not place the ghosts after the rank's own particles");
  }
  const auto pair_contacts = r.get<std::uint64_t>(p + "thread_pair_contacts");
  if (pair_contacts.size() != scratch_.size()) return false;  // the split is rebuilt at the next evaluation
  partition_.load(r, p + "split/");
  for (std::size_t t = 0; t < scratch_.size(); ++t) scratch_[t].pair_contacts = pair_contacts[t];
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
  if (ranks_) {
    owned_ = store_.size();
    ghosts_end_ = owned_;
    edited_ = false;
  }
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

std::size_t Subdomain::load_state(const ArchiveReader& r, const std::string& p) {
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
  std::size_t own = SIZE_MAX;
  if (r.has(p + "rank")) {
    const auto rank = r.get<std::uint64_t>(p + "rank");
    if (rank.size() != 5) r.fail(p + "rank", "holds " + std::to_string(rank.size()) + " values, expected 5");
    own = rank[2];
  }
  nlist_.configure(skin_, pipeline_->history_stride());
  store_.load(r, p + "particles/");
  if (own == SIZE_MAX) own = store_.size();
  if (own > store_.size()) r.fail(p + "rank", "counts more particles than the part holds");
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
  return own;
}

}  // namespace domel::platform
