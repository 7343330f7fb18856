// SPDX-License-Identifier: MIT
// The threads' split of a force evaluation (force_partition.hpp).
#include "subdomain/force_partition.hpp"

#include "core/cadence.hpp"

#include "core/archive.hpp"
#include <algorithm>
#include <iterator>

namespace domel::platform {

void ForcePartition::set_threads(int threads) {
  threads_.clear();
  threads_.resize(static_cast<std::size_t>(std::max(1, threads)));
  for (auto& s : split_) s.clear();
  split_builds_ = 0;
}

ForceAccumulator ForcePartition::private_accumulator(int t, std::size_t n) {
  ThreadForces& tf = threads_[static_cast<std::size_t>(t)];
  if (tf.fx.size() != n)
    for (auto* v : {&tf.fx, &tf.fy, &tf.fz, &tf.tx, &tf.ty, &tf.tz}) v->assign(n, 0.0);
  for (const auto& [lo, hi] : tf.shared_ranges()) {
    const auto a = static_cast<std::ptrdiff_t>(lo), b = static_cast<std::ptrdiff_t>(hi);
    for (auto* v : {&tf.fx, &tf.fy, &tf.fz, &tf.tx, &tf.ty, &tf.tz}) std::fill(v->begin() + a, v->begin() + b, 0.0);
  }
  return {tf.fx.data(), tf.fy.data(), tf.fz.data(), tf.tx.data(), tf.ty.data(), tf.tz.data()};
}

void ForcePartition::zones(bool far) {
  // Each thread's particle-index span this step: its near-tier span, widened
  // by its far-tier span while the far tier is screened.
  const int nt = threads();
  for (ThreadForces& tf : threads_) {
    tf.lo = tf.span[0][0];
    tf.hi = tf.span[0][1];
    if (far && tf.span[1][1] > tf.span[1][0]) {
      tf.lo = tf.hi > tf.lo ? std::min(tf.lo, tf.span[1][0]) : tf.span[1][0];
      tf.hi = std::max(tf.hi, tf.span[1][1]);
    }
  }
  // A thread's own zone: the largest interval of its span that no other
  // span meets, found by cutting away each other span in turn (cutting only
  // shrinks the interval, so a span cut away earlier stays clear). The list
  // is built in order of the lower particle index, so after a build in
  // spatial order a thread's span overlaps its neighbours' only in a band one
  // cell layer deep, and most of its forces skip the private arrays, their
  // clearing and their sum.
  for (int t = 1; t < nt; ++t) {
    ThreadForces& tf = threads_[static_cast<std::size_t>(t)];
    std::size_t a = tf.lo, b = tf.hi;
    for (int u = 0; u < nt && a < b; ++u) {
      const ThreadForces& other = threads_[static_cast<std::size_t>(u)];
      if (u == t || other.hi <= other.lo || other.hi <= a || other.lo >= b) continue;
      if (other.lo <= a) a = other.hi;
      else if (other.hi >= b) b = other.lo;
      else if (other.lo - a >= b - other.hi) b = other.lo;  // keep the larger side
      else a = other.hi;
    }
    if (a < b) {
      tf.own_lo = a;
      tf.own_hi = b;
    } else {
      tf.own_lo = tf.own_hi = tf.hi;
    }
  }
}

void ForcePartition::refresh_wall_work(const std::vector<WallNeighbors>& wall_lists,
                                       const std::vector<WallPrimitive>& walls_now, double time) {
  // The wall contacts of a particle are evaluated by the thread whose
  // reduce range holds it. They sit where the walls are, at one end of the
  // spatially ordered store (a floor: the first particles), so they weigh in
  // the split. Per wall-list entry: its gap test, and for a contact the
  // batch gather, the contact kernels and the scatter; a particle's kick
  // costs 1 (weights from the measured pass-1 imbalance on S2 at 10k,
  // docs/performance.md). Kept as (particle, cost of the entries up to this
  // one) in particle order, refreshed with the pair split (balance). Only
  // the split depends on it, never a result.
  std::vector<std::pair<uint32_t, double>>& ev = wall_work_;
  ev.clear();
  for (std::size_t w = 0; w < wall_lists.size(); ++w) {
    if (!walls_now[w].active(time)) continue;
    const WallNeighbors& list = wall_lists[w];
    const auto mid = static_cast<std::ptrdiff_t>(ev.size());
    for (std::size_t e = 0; e < list.particle.size(); ++e)  // ascending particle order
      ev.emplace_back(list.particle[e], static_cast<double>(kWallEntryCost + (list.touching[e] ? kWallContactCost : 0)));
    std::inplace_merge(ev.begin(), ev.begin() + mid, ev.end(),
                       [](const auto& x, const auto& y) { return x.first < y.first; });
  }
  for (std::size_t e = 1; e < ev.size(); ++e) ev[e].second += ev[e - 1].second;  // costs -> running sums
}

void ForcePartition::split_for_reduce(std::size_t n) {
  // Split [0, n) so that each thread has the same estimated cost: a
  // particle costs 1, plus kReduceCost for each other thread whose force
  // span covers it (the reduction's loads and adds), plus its wall contacts
  // (refresh_wall_work). Equal particle counts would leave the whole
  // reduction to the threads whose share overlaps the spans, and the
  // floor's contacts to the first thread. Deterministic: from the spans and
  // the lists only.
  constexpr double kReduceCost = 1.5;
  const int nt = threads();
  std::vector<std::size_t>& cuts = split_cuts_;  // members: no allocation per step
  cuts.assign({0, n});
  for (int t = 1; t < nt; ++t) {
    const ThreadForces& tf = threads_[static_cast<std::size_t>(t)];
    for (std::size_t c : {tf.lo, tf.own_lo, tf.own_hi, tf.hi}) cuts.push_back(std::min(c, n));
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  auto weight = [&](std::size_t k) {
    double w = 1.0;
    for (int t = 1; t < nt; ++t)
      for (const auto& [lo, hi] : threads_[static_cast<std::size_t>(t)].shared_ranges())
        if (k >= lo && k < hi) w += kReduceCost;
    return w;
  };
  std::vector<double>& seg_w = split_weights_;
  seg_w.resize(cuts.size() - 1);
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) seg_w[c] = weight(cuts[c]);
  // The cost of the particles [0, k): non-decreasing in k.
  auto cost_below = [&](std::size_t k) {
    double sum = 0.0;
    for (std::size_t c = 0; c + 1 < cuts.size() && cuts[c] < k; ++c)
      sum += static_cast<double>(std::min(k, cuts[c + 1]) - cuts[c]) * seg_w[c];
    const auto walls = std::lower_bound(wall_work_.begin(), wall_work_.end(), k,
                                        [](const auto& w, std::size_t p) { return w.first < p; });
    return sum + (walls == wall_work_.begin() ? 0.0 : std::prev(walls)->second);
  };
  const double total = cost_below(n);
  pass2_split_.assign(static_cast<std::size_t>(nt) + 1, n);
  pass2_split_[0] = 0;
  for (int q = 1; q < nt; ++q) {
    // the first k with cost_below(k) >= total q / nt
    const double goal = total * q / nt;
    std::size_t lo = pass2_split_[static_cast<std::size_t>(q) - 1], hi = n;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (cost_below(mid) >= goal) hi = mid;
      else lo = mid + 1;
    }
    pass2_split_[static_cast<std::size_t>(q)] = lo;
  }
}

void ForcePartition::reduce(ParticleStore& s, std::size_t first, std::size_t last) const {
  for (int t = 1; t < threads(); ++t) {
    const ThreadForces& tf = threads_[static_cast<std::size_t>(t)];
    for (const auto& [lo, hi] : tf.shared_ranges()) {
      const std::size_t a = std::max(first, lo), b = std::min(last, hi);
      for (std::size_t k = a; k < b; ++k) {
        s.fx[k] += tf.fx[k]; s.fy[k] += tf.fy[k]; s.fz[k] += tf.fz[k];
        s.tx[k] += tf.tx[k]; s.ty[k] += tf.ty[k]; s.tz[k] += tf.tz[k];
      }
    }
  }
}

void ForcePartition::balance(const NeighborList& list, bool far_active, const std::vector<ContactScratch>& contacts,
                             const std::vector<WallNeighbors>& wall_lists,
                             const std::vector<WallPrimitive>& walls_now, double time, std::uint64_t step,
                             std::size_t particles) {
  // Contiguous ranges of each tier of the pair list with near-equal estimated
  // cost: an entry costs 1 (the overlap screen) and a contact kPairContactCost
  // more (the contact kernels and the scatter; the value's measurement is in
  // docs/performance.md). Even entry counts leave the thread with the dense,
  // settled bottom of a column with most of the work. While the contacts
  // stay put, the two serial scans of the list are skipped between builds
  // unless the threads' estimated costs in the last force evaluation (their
  // ranges' entries, and their contacts as counted there) differ by more
  // than kRebalanceAt.
  static const Cadence kBalanceEvery = Cadence::in_ticks(32);
  constexpr double kRebalanceAt = 0.01;
  const int nt = threads();
  const std::size_t tiers[3] = {0, list.near_size(), list.size()};
  if (split_[0].size() == static_cast<std::size_t>(nt) + 1 && split_builds_ == list.builds()) {
    if (!kBalanceEvery.on(step)) return;
    double lo = 0, hi = 0;
    for (std::size_t q = 0; q < static_cast<std::size_t>(nt); ++q) {
      std::size_t entries = split_[0][q + 1] - split_[0][q];
      if (far_active) entries += split_[1][q + 1] - split_[1][q];
      const double cost = static_cast<double>(entries + kPairContactCost * contacts[q].pair_contacts);
      lo = q == 0 ? cost : std::min(lo, cost);
      hi = q == 0 ? cost : std::max(hi, cost);
    }
    if (hi - lo <= kRebalanceAt * hi) return;
  }
  refresh_wall_work(wall_lists, walls_now, time);
  const uint8_t* touching = list.touching.data();
  const uint32_t* li = list.i.data();
  const uint32_t* lj = list.j.data();
  for (int tier = 0; tier < 2; ++tier) {
    const std::size_t begin = tiers[tier], end = tiers[tier + 1];
    std::vector<std::size_t>& split = split_[tier];
    split.assign(static_cast<std::size_t>(nt) + 1, end);
    split[0] = begin;
    uint64_t total = end - begin;
    for (std::size_t e = begin; e < end; ++e) total += kPairContactCost * touching[e];
    uint64_t run = 0;
    int t = 1;
    for (std::size_t e = begin; e < end && t < nt; ++e) {
      run += 1 + kPairContactCost * touching[e];
      while (t < nt && run * static_cast<uint64_t>(nt) >= total * static_cast<uint64_t>(t)) split[t++] = e + 1;
    }
    // The particle-index span each thread's pairs touch (zones).
    for (int q = 0; q < nt; ++q) {
      ThreadForces& tf = threads_[static_cast<std::size_t>(q)];
      std::size_t lo = particles, hi = 0;
      for (std::size_t e = split[static_cast<std::size_t>(q)]; e < split[static_cast<std::size_t>(q) + 1]; ++e) {
        lo = std::min<std::size_t>(lo, std::min(li[e], lj[e]));
        hi = std::max<std::size_t>(hi, std::max(li[e], lj[e]) + 1u);
      }
      tf.span[tier][0] = lo < hi ? lo : 0;
      tf.span[tier][1] = lo < hi ? hi : 0;
    }
  }
  split_builds_ = list.builds();
}

std::size_t ForcePartition::bytes() const {
  std::size_t b = 0;
  for (const ThreadForces& tf : threads_)
    b += (tf.fx.capacity() + tf.fy.capacity() + tf.fz.capacity() + tf.tx.capacity() + tf.ty.capacity() +
          tf.tz.capacity()) * sizeof(double);
  return b;
}

}  // namespace domel::platform

// ---- checkpoints ----------------------------------------------------------

namespace domel::platform {

void ForcePartition::fields(CheckpointFields& f) {
  const bool load = f.loading();
  std::uint64_t threads = threads_.size();
  f("threads", threads);
  if (load && threads != threads_.size())
    f.reader().fail(f.prefix() + "threads", "was written by a run on another thread count");
  for (int tier = 0; tier < 2; ++tier) {
    std::vector<std::uint64_t> v(split_[tier].begin(), split_[tier].end());
    f("split" + std::to_string(tier), v);
    split_[tier].assign(v.begin(), v.end());
  }
  f("split_builds", split_builds_);
  std::vector<std::uint64_t> spans;
  for (const ThreadForces& tf : threads_)
    for (const auto& tier : tf.span) spans.insert(spans.end(), {tier[0], tier[1]});
  f("spans", spans);
  std::vector<std::uint32_t> wall_particle;
  std::vector<double> wall_cost;
  for (const auto& [k, c] : wall_work_) {
    wall_particle.push_back(k);
    wall_cost.push_back(c);
  }
  f("wall_particle", wall_particle);
  f("wall_cost", wall_cost);
  if (!load) return;
  if (spans.size() != 4 * threads_.size()) f.reader().fail(f.prefix() + "spans", "does not hold 4 values per thread");
  for (std::size_t t = 0; t < threads_.size(); ++t)
    for (int tier = 0; tier < 2; ++tier)
      for (int e = 0; e < 2; ++e) threads_[t].span[tier][e] = spans[4 * t + 2 * tier + e];
  if (wall_particle.size() != wall_cost.size())
    f.reader().fail(f.prefix() + "wall_cost", "disagrees with wall_particle in length");
  wall_work_.clear();
  for (std::size_t e = 0; e < wall_particle.size(); ++e) wall_work_.emplace_back(wall_particle[e], wall_cost[e]);
}

void ForcePartition::save(ArchiveWriter& w, const std::string& p) const {
  save_fields(w, p, [&](CheckpointFields& f) { const_cast<ForcePartition*>(this)->fields(f); });
}

void ForcePartition::load(const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f); });
}

}  // namespace domel::platform
