// SPDX-License-Identifier: MIT
// A subdomain's step through its phases (step_phases.hpp), its set-up and
// its observers. The contact geometry and force conventions are in
// contact/contact_sweep.hpp; the integration kernels in integrator.cpp.
// One file of about 650 lines: the fused and the in-order step share their
// private helpers (the deferred force sum, the rebuild decision, the packed
// positions) and are meant to be read side by side.
#include "subdomain/subdomain.hpp"

#include "core/archive.hpp"
#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace domel::platform {

Subdomain::Subdomain(std::string name, double coarse_grain, std::size_t material,
                     std::unique_ptr<ContactPipeline> pipeline)
    : name_(std::move(name)), coarse_grain_(coarse_grain), material_(material), materials_{material},
      pipeline_(std::move(pipeline)) {
  set_threads(default_thread_count());
}

std::uint8_t Subdomain::local_material(std::size_t global) {
  for (std::size_t k = 0; k < materials_.size(); ++k)
    if (materials_[k] == global) return static_cast<std::uint8_t>(k);
  if (materials_.size() == ParticleStore::kMaxMaterials)
    throw std::length_error("subdomain '" + name_ + "': more than " + std::to_string(ParticleStore::kMaxMaterials) +
                            " materials");
  materials_.push_back(global);
  return static_cast<std::uint8_t>(materials_.size() - 1);
}

void Subdomain::set_threads(int threads) {
  if (pool_) synchronize();  // a pending force sum lives in the arrays being replaced
  pool_ = std::make_unique<ThreadPool>(threads);
  scratch_.clear();
  for (int t = 0; t < pool_->size(); ++t) scratch_.emplace_back(*pipeline_);
  partition_.set_threads(pool_->size());
}

void Subdomain::set_environment(const std::vector<Material>& materials, const void* table,
                                CoefficientsOf coefficients, const std::vector<WallPrimitive>* walls,
                                const double gravity[3]) {
  walls_ = walls;
  const std::size_t n = materials_.size();
  local_materials_.clear();
  for (std::size_t g : materials_) local_materials_.push_back(materials.at(g));
  pairs_.assign(n * n, domel_pair_v2{});
  pair_rolling_.assign(n * n, nullptr);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      const PairCoefficients c = coefficients(table, materials_[a], materials_[b]);
      pairs_[a * n + b] = make_pair(local_materials_[a], local_materials_[b], c, false, coarse_grain_);
      pair_rolling_[a * n + b] = pipeline_->rolling_model(c.rolling_model);
    }
  wall_pairs_.assign(walls->size() * n, domel_pair_v2{});
  wall_pair_rolling_.assign(walls->size() * n, nullptr);
  for (std::size_t w = 0; w < walls->size(); ++w) {
    const std::size_t wm = (*walls)[w].material;
    for (std::size_t a = 0; a < n; ++a) {
      const PairCoefficients c = coefficients(table, materials_[a], wm);
      wall_pairs_[w * n + a] = make_pair(local_materials_[a], materials.at(wm), c, true, coarse_grain_);
      wall_pair_rolling_[w * n + a] = pipeline_->rolling_model(c.rolling_model);
    }
  }
  // classes of pairs that act alike
  auto same = [](const domel_pair_v2& p, const ModelInstance* pr, const domel_pair_v2& q, const ModelInstance* qr) {
    return pr == qr && p.is_wall == q.is_wall && p.youngs_eff == q.youngs_eff && p.shear_eff == q.shear_eff &&
           p.restitution == q.restitution && p.friction == q.friction && p.coarse_grain == q.coarse_grain &&
           p.has_rolling_friction == q.has_rolling_friction && p.rolling_friction == q.rolling_friction;
  };
  pair_class_.assign(n * n, 0);
  class_pairs_.clear();
  class_rolling_.clear();
  for (std::size_t k = 0; k < n * n; ++k) {
    std::size_t c = 0;
    while (c < class_pairs_.size() && !same(class_pairs_[c], class_rolling_[c], pairs_[k], pair_rolling_[k])) ++c;
    if (c == class_pairs_.size()) {
      class_pairs_.push_back(pairs_[k]);
      class_rolling_.push_back(pair_rolling_[k]);
    }
    pair_class_[k] = static_cast<uint16_t>(c);  // at most n (n + 1) / 2 classes, n <= 256 (uint8 materials)
  }
  wall_uniform_.assign(walls->size(), 1);
  for (std::size_t w = 0; w < walls->size(); ++w)
    for (std::size_t a = 1; a < n; ++a)
      if (!same(wall_pairs_[w * n], wall_pair_rolling_[w * n], wall_pairs_[w * n + a], wall_pair_rolling_[w * n + a]))
        wall_uniform_[w] = 0;
  wall_lists_.assign(walls->size(), WallNeighbors{});
  walls_now_ = *walls;
  for (int a = 0; a < 3; ++a) body_forces_.gravity[a] = gravity[a];
}

TimeStepReport Subdomain::estimate_time_step(double impact_velocity) {
  synchronize();
  return platform::estimate_time_step({pipeline_.get(), &local_materials_, &pairs_, &wall_pairs_, &walls_now_,
                                       &pair_rolling_, &wall_pair_rolling_}, store_,
                                      impact_velocity);
}

void Subdomain::add_hook(Phase phase, StepHook hook) {
  synchronize();  // a pending step finishes the fused way; the next one runs in phase order
  hooks_.add(phase, std::move(hook));
}

void Subdomain::set_gravity(std::shared_ptr<const GravitySchedule> g) {
  synchronize();
  if (g) g->at(time_, body_forces_.gravity);
  gravity_ = g && g->varies() ? std::move(g) : nullptr;
}

void Subdomain::wall_load(std::size_t wall, double f[3]) const {
  synchronize_logically_const();  // the deferred wall contacts
  f[0] = f[1] = f[2] = 0.0;
  for (const auto& ts : scratch_)
    for (std::size_t w = 0; w < walls_now_.size() && 3 * w + 2 < ts.wall_load.size(); ++w)
      if (walls_now_[w].wall == wall && walls_now_[w].track_load)
        for (int a = 0; a < 3; ++a) f[a] -= ts.wall_load[3 * w + a];  // the sums are the forces on the particles
}

void Subdomain::set_rank_exchange(std::unique_ptr<RankExchange> ranks) {
  synchronize();
  ranks_ = std::move(ranks);
  ghosts_ = 0;
  ghosts_end_ = store_.size();
  nlist_.set_periodic(ranks_->pair_box(box_));
}

void Subdomain::reset_forces() {
  const std::size_t n = owned();
  pool_->for_range(n, [&](std::size_t first, std::size_t last, int) { body_forces_.apply(store_, first, last); });
  for (auto* f : {&store_.fx, &store_.fy, &store_.fz, &store_.tx, &store_.ty, &store_.tz})
    std::fill(f->begin() + static_cast<std::ptrdiff_t>(n), f->end(), 0.0);
}

std::vector<std::uint64_t> Subdomain::rank_costs() const {
  // the threads' weights (ForcePartition's costs), per particle that leads
  // the work; every particle costs at least 1. Particles added since the
  // build (a pour) count 1.
  using FP = ForcePartition;
  const std::size_t n = owned();
  std::vector<std::uint64_t> cost(n, 1);
  if (nlist_.layout_stale(store_)) return cost;
  for (std::size_t e = 0; e < nlist_.size(); ++e)
    if (nlist_.i[e] < n) cost[nlist_.i[e]] += 1 + FP::kPairContactCost * nlist_.touching[e];
  for (const WallNeighbors& w : wall_lists_)
    for (std::size_t e = 0; e < w.particle.size(); ++e)
      if (w.particle[e] < n) cost[w.particle[e]] += FP::kWallEntryCost + FP::kWallContactCost * w.touching[e];
  return cost;
}

void Subdomain::apply_body_forces(std::size_t first, std::size_t last) {
  synchronize();
  body_forces_.apply(store_, first, last);
}

ParticleStore& Subdomain::store() {
  synchronize();
  if (!contacts_counted_) {
    count_contacts(store_, nlist_, far_active_ ? nlist_.size() : nlist_.near_size(), wall_lists_, walls_now_,
                   forces_time_);
    contacts_counted_ = true;
  }
  return store_;
}

ParticleStore& Subdomain::particles_to_edit() {
  ParticleStore& s = store();
  if (ghosts_ != 0) {  // only a rank holds ghosts
    s.truncate(owned());  // the layout changes: the next step rebuilds the lists (on every rank)
    ghosts_ = 0;
    edited_ = true;
  }
  return s;
}

void Subdomain::collect_contact_counts() {
  store();  // counts on owned and ghosts
  if (contacts_collected_) return;
  ranks_->reverse_counts(store_);
  contacts_collected_ = true;
}

void Subdomain::setup() {
  synchronize();
  const uint32_t stride = pipeline_->history_stride();
  nlist_.configure(skin_, stride);
  update_walls(time_);
  exchange();
  rebuild_lists();
  if (gravity_) gravity_->at(time_, body_forces_.gravity);
  reset_forces();
  try {
    contact_forces(false);
  } catch (const PluginError& e) {
    rethrow_with_context(e, "the initial force evaluation");
  }
  ranks_->reverse(store_);
  const std::size_t n = owned();
  // Coinciding particles (two lines of a state file with one position)
  // have no contact normal: their forces are NaN, and the first step would
  // blame the time step.
  for (std::size_t k = 0; k < n; ++k) {
    if (std::isfinite(store_.fx[k] + store_.fy[k] + store_.fz[k] + store_.tx[k] + store_.ty[k] + store_.tz[k]))
      continue;
    std::ostringstream os;
    os << "subdomain '" << name_ << "': the initial force on particle id " << store_.id[k] << " at ("
       << store_.x[k] << ", " << store_.y[k] << ", " << store_.z[k] << ") m is not finite";
    for (std::size_t e = 0; e < nlist_.size(); ++e) {
      const uint32_t i = nlist_.i[e], j = nlist_.j[e];
      if (i != k && j != k) continue;
      const uint32_t o = i == k ? j : i;
      const double dx = store_.x[k] - store_.x[o], dy = store_.y[k] - store_.y[o], dz = store_.z[k] - store_.z[o];
      if (dx * dx + dy * dy + dz * dz == 0.0) {
        os << ": it coincides with particle id " << store_.id[o] << " (no contact normal)";
        break;
      }
    }
    if (!initial_source_.empty()) os << "; the particles came from " << initial_source_;
    throw RuntimeError(os.str() + "; separate or remove the overlapping particles");
  }
}


void Subdomain::exchange() {
  // One process moves no particle to another: periodic boundaries are its
  // whole migration (particles that left through a periodic face re-enter
  // at the other), and the lists keep their histories in place
  if (!ranks_->over_ranks()) {
    if (box_.any()) box_.wrap(store_);
    return;
  }
  // Over ranks: drop the ghosts, share space out by cost, move particles
  // with the histories of the pairs they lead and of their wall contacts
  // (their new rank computes those contacts)
  const uint32_t stride = pipeline_->history_stride();
  std::vector<PairHistories> h(1 + wall_lists_.size());
  h[0] = nlist_.live_histories();
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) h[1 + w] = wall_lists_[w].live_histories(stride);
  std::vector<PairHistories*> sets;
  for (auto& set : h) sets.push_back(&set);
  ranks_->migrate(store_, owned(), rank_costs(), sets);
  nlist_.adopt_histories(std::move(h[0]));
  for (std::size_t w = 0; w < wall_lists_.size(); ++w)
    if (wall_lists_[w].built) wall_lists_[w].adopt_histories(std::move(h[1 + w]));
  ghosts_ = 0;
  ghosts_end_ = store_.size();
}

void Subdomain::rebuild_lists() {
  // Spatial re-ordering (docs/performance.md): particles that
  // were inserted in random order (pours, random fills) or have mixed are put
  // back in cell order every reorder_every_ builds, so that the pair loop's
  // partners sit close in memory. Small systems are left alone (their arrays
  // fit the cache, and tests may address particles by index).
  if (reorder_every_ > 0 && store_.size() >= kReorderMinParticles &&
      (builds_since_reorder_ >= reorder_every_ || store_.size() > reordered_size_ + reordered_size_ / 10)) {
    double rmax = 0.0;
    for (double r : store_.radius) rmax = std::max(rmax, r);
    store_.permute(store_.spatial_order(2.0 * rmax + skin_));
    builds_since_reorder_ = 0;
    reordered_size_ = store_.size();
  }
  ++builds_since_reorder_;
  const std::size_t own = owned();
  ranks_->build_ghosts(store_, own, skin_);  // every particle that can meet an owned one before the next build
  ghosts_ = store_.size() - own;
  ghosts_end_ = store_.size();
  nlist_.build(store_, pool_.get(), owned());
  far_active_ = false;
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
    const WallPrimitive& wall = walls_now_[w];
    wall_lists_[w].build(store_, wall, skin_, pipeline_->history_stride(), wall.active(time_), owned());
    wall_lists_[w].built_time = wall_time_;
  }
}

void Subdomain::update_walls(double t) {
  wall_time_ = t;
  const uint32_t stride = pipeline_->history_stride();
  for (std::size_t w = 0; w < walls_now_.size(); ++w) {
    WallPrimitive& wall = walls_now_[w];
    WallNeighbors& list = wall_lists_[w];
    if (wall.moving) wall.place((*walls_)[w], t);
    const bool active = wall.active(time_);
    if (active != list.built) {
      // activation: a fresh list, contacts start with zero history;
      // removal: contacts open for good
      list.clear();
      if (active) {
        list.build(store_, wall, skin_, stride, true, owned());
        list.built_time = t;
      }
    } else if (active && wall.moving &&
               (std::isnan(list.built_time) || wall.displacement_bound(list.built_time, t) > 0.5 * skin_)) {
      // The wall moved half the skin since its list was built. Rebuilding this
      // list alone would not do: a particle may by now have moved up to half
      // the skin from where the last full build saw it, and may move another
      // half before the next, so wall and particle could close more than the
      // skin. A full build resets both references (particle <= skin/2 + wall
      // <= skin/2 until the next one).
      walls_force_rebuild_ = true;
    }
  }
}

void Subdomain::prune_removed_walls() {
  for (std::size_t w = 0; w < wall_lists_.size(); ++w)
    if (!walls_now_[w].active(time_) && wall_lists_[w].built)  // removed: contacts open for good
      wall_lists_[w].clear();
}

void Subdomain::rethrow_with_context(const std::exception& e, const char* during) const {
  std::ostringstream os;
  os << "subdomain '" << name_ << "', step " << steps_ << ", t = " << time_ << " s, during " << during << ": "
     << e.what();
  throw PluginError(os.str());
}

void Subdomain::throw_nonfinite(const char* when, double t, std::uint64_t step) const {
  std::ostringstream os;
  os.precision(6);
  os << "subdomain '" << name_ << "': a particle position or velocity became non-finite " << when << " at t = "
     << t << " s (step " << step << ")";
  const std::size_t k = first_nonfinite(store_);
  if (k < store_.size()) {
    const ParticleStore& s = store_;
    os << "; the first is particle id " << s.id[k] << " (radius " << s.radius[k] << " m, mass " << s.mass[k]
       << " kg): x = (" << s.x[k] << ", " << s.y[k] << ", " << s.z[k] << ") m, v = (" << s.vx[k] << ", " << s.vy[k]
       << ", " << s.vz[k] << ") m/s, w = (" << s.wx[k] << ", " << s.wy[k] << ", " << s.wz[k] << ") rad/s, f = ("
       << s.fx[k] << ", " << s.fy[k] << ", " << s.fz[k] << ") N, " << s.contacts[k] << " contact(s) at the last count";
  }
  os << "; the time step " << dt_ << " s is probably too large for the contact model";
  throw RuntimeError(os.str());
}

bool Subdomain::take_pending_reduce(std::size_t n) {
  const bool reduce = reduce_pending_;
  reduce_pending_ = false;
  if (reduce) partition_.split_for_reduce(n);
  return reduce;
}

std::pair<std::size_t, std::size_t> Subdomain::finish_forces(int t, bool reduce, std::size_t n) {
  if (!reduce) return pool_->range(n, t);
  // the other threads' pair forces, then the wall contacts of this thread's
  // particles (each wall contact touches one particle)
  const auto [first, last] = partition_.reduce_range(t);
  partition_.reduce(store_, first, last);
  ContactScratch& ts = scratch_[static_cast<std::size_t>(t)];
  ts.wall_contacts = 0;
  ts.wall_max_ratio = 0.0;
  std::fill(ts.wall_load.begin(), ts.wall_load.end(), 0.0);
  wall_range(wall_sweep(), ts, first, last);
  return {first, last};
}

void Subdomain::finish_wall_stats() {
  last_wall_contacts_ = 0;
  for (const auto& ts : scratch_) {
    last_wall_contacts_ += ts.wall_contacts;
    last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.wall_max_ratio);
  }
}

void Subdomain::synchronize() {
  if (!kick_pending_) return;
  kick_pending_ = false;
  const std::size_t n = store_.size();
  try {
    const bool reduce = take_pending_reduce(n);
    nonfinite_counts_.assign(static_cast<std::size_t>(threads()), 0.0);
    pool_->run([&](int t) {
      const auto [first, last] = finish_forces(t, reduce, n);
      nonfinite_counts_[static_cast<std::size_t>(t)] = kick_check(store_, first, last, pending_half_);
    });
    if (reduce) finish_wall_stats();
  } catch (const PluginError& e) {
    rethrow_with_context(e, "the wall contacts");
  }
  for (double bad : nonfinite_counts_)
    if (bad != 0.0) throw_nonfinite("in the second half kick", time_, steps_);
}

void Subdomain::grow(std::size_t k, double to, double rate) {
  synchronize();
  if (k >= store_.size()) throw std::out_of_range("Subdomain::grow: no particle " + std::to_string(k));
  if (!(to > 0) || !(rate > 0) || !std::isfinite(to) || !std::isfinite(rate))
    throw std::invalid_argument("Subdomain::grow: the radius to grow to and the rate must be positive and finite");
  enable_growth();
  store_.aux[grow_to_][k] = to;
  store_.aux[grow_rate_][k] = rate;
  growing_ = growing_ || store_.radius[k] < to;
}

void Subdomain::enable_growth() {
  if (grow_to_ != SIZE_MAX) return;
  grow_to_ = store_.add_field("grow_to", ParticleStore::kCarried);
  grow_rate_ = store_.add_field("grow_rate", ParticleStore::kCarried);
}

void Subdomain::find_growth() {
  grow_to_ = grow_rate_ = SIZE_MAX;
  const auto& names = store_.aux_names();
  for (std::size_t a = 0; a < names.size(); ++a) {
    if (names[a] == "grow_to") grow_to_ = a;
    if (names[a] == "grow_rate") grow_rate_ = a;
  }
  growing_ = false;
  if (grow_to_ == SIZE_MAX || grow_rate_ == SIZE_MAX) return;
  for (std::size_t k = 0; k < store_.size() && !growing_; ++k) growing_ = store_.radius[k] < store_.aux[grow_to_][k];
}

void Subdomain::grow_step() {
  // every particle of the store, ghosts included: a ghost carries its
  // owner's target and rate and grows as the owner does, so the two stay equal
  // between builds without an exchange
  const double* to = store_.aux[grow_to_].data();
  const double* rate = store_.aux[grow_rate_].data();
  double* r = store_.radius.data();
  const std::size_t n = store_.size();
  // each particle's largest overlap with a pair partner now: one that
  // presses into its neighbours by more than grow_overlap_ of its diameter
  // waits for them to make room (a packing grown faster than it can
  // rearrange jams and then bursts)
  overlap_.assign(n, 0.0);
  if (grow_overlap_ > 0) {
    double L[3], inv_L[3];
    nlist_.periodic().periods(L, inv_L);
    for (std::size_t e = 0; e < nlist_.size(); ++e) {
      const std::uint32_t i = nlist_.i[e], j = nlist_.j[e];
      if (i >= n || j >= n) continue;
      const double dx = min_image(store_.x[i] - store_.x[j], L[0], inv_L[0]);
      const double dy = min_image(store_.y[i] - store_.y[j], L[1], inv_L[1]);
      const double dz = min_image(store_.z[i] - store_.z[j], L[2], inv_L[2]);
      const double ov = r[i] + r[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
      overlap_[i] = std::max(overlap_[i], ov);
      overlap_[j] = std::max(overlap_[j], ov);
    }
    // and with the walls their lists name (a mesh's triangles are left out: its overlaps with a growing
    // particle also press the particle's pair partners, which the pairs above see)
    for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
      const WallPrimitive& wall = walls_now_[w];
      if (!wall_lists_[w].built || wall.shape == WallPrimitive::Shape::mesh) continue;
      for (std::uint32_t q : wall_lists_[w].particle) {
        if (q >= n) continue;
        double d, nx, ny, nz;
        if (wall.gap(store_.x[q], store_.y[q], store_.z[q], d, nx, ny, nz)) overlap_[q] = std::max(overlap_[q], r[q] - d);
      }
    }
  }
  double most = 0;
  bool left = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (!(r[k] < to[k])) continue;
    if (grow_overlap_ > 0 && overlap_[k] > grow_overlap_ * 2 * to[k]) {
      left = true;
      continue;
    }
    const double next = std::min(to[k], r[k] + rate[k] * dt_);
    most = std::max(most, next - r[k]);
    r[k] = next;
    left = left || next < to[k];
  }
  nlist_.add_growth(most);
  growing_ = left;
}

void Subdomain::step_deferred() {
  if (growing_) {
    // the last step's deferred work (with threads: its wall contacts) at the radii it ended with
    synchronize();
    grow_step();
  }
  // the fused step owns every particle of the store; a rank completes its
  // step in phase order, the exchanges between them
  if (hooks_.empty() && !ranks_->over_ranks()) step_fused();
  else step_in_order();
}

bool Subdomain::rebuild_due(bool stale) {
  bool beyond_skin = false, beyond_near = false;
  for (const DriftCounts& c : drift_counts_) {
    beyond_skin = beyond_skin || c.beyond_skin != 0.0;
    beyond_near = beyond_near || c.beyond_near != 0.0;
  }
  // the same decision on every rank: a ghost moves as far as its owner
  bool flags[2] = {stale || beyond_skin, beyond_near};
  ranks_->any(flags, 2);
  beyond_skin = flags[0];
  beyond_near = flags[1];
  if (stale || walls_force_rebuild_ || beyond_skin) {
    walls_force_rebuild_ = false;
    return true;
  }
  if (beyond_near) far_active_ = true;  // latched until the next build: far entries are screened from now on
  return false;
}

void Subdomain::step_fused() {
  // Pass 1, one sweep over the store instead of the five of a textbook
  // step: the last step's second half kick (unless synchronize() did it),
  // this step's half kick and drift, the rebuild check and the reset to the
  // body forces (docs/performance.md). With threads, the last step's force
  // sums and wall contacts are finished first, per particle range.
  const std::size_t n = store_.size();
  const double dt = dt_, half = 0.5 * dt_;
  drift_counts_.assign(static_cast<std::size_t>(threads()), DriftCounts{});
  const bool stale = nlist_.layout_stale(store_);
  const bool finish = kick_pending_;
  kick_pending_ = false;
  if (gravity_) gravity_->at(time_ + dt, body_forces_.gravity);  // the reset below is to the forces at t + dt
  try {
    const bool reduce = take_pending_reduce(n);  // pending only with a pending kick
    packed_.resize(n);
    const KickDrift how{dt, half, pending_half_, finish, stale ? nullptr : &nlist_, &body_forces_,
                        packed_.xyzr.data()};
    pool_->run([&](int t) {
      const auto [first, last] = finish_forces(t, reduce, n);
      drift_counts_[static_cast<std::size_t>(t)] = kick_drift(store_, first, last, how);
    });
    if (reduce) finish_wall_stats();
    // reported as at the end of the last step, where the two-pass step found it
    if (finish)
      for (const DriftCounts& c : drift_counts_)
        if (c.nonfinite != 0.0) throw_nonfinite("in the second half kick", time_, steps_);
    update_walls(time_ + dt);
    bool packed_filled = true;
    if (rebuild_due(stale)) {
      exchange();
      rebuild_lists();
      packed_filled = false;  // the store may have been re-ordered
    }
    // The forces; with threads, the other threads' sums and the wall
    // contacts are left to the next pass 1 (or synchronize()), as is the
    // second half kick: one fork/join and one sweep less per step.
    contact_forces(true, packed_filled);
  } catch (const PluginError& e) {
    rethrow_with_context(e, "the contact forces");
  }
  kick_pending_ = true;
  pending_half_ = half;
  time_ += dt;
  ++steps_;
}

void Subdomain::run_hooks(Phase phase) {
  const auto& list = hooks_.at(phase);
  if (list.empty()) return;
  StepContext ctx{*this, store_, steps_, time_ + dt_, dt_, phase};
  for (const StepHook& h : list) {
    try {
      h.run(ctx);
    } catch (const std::exception& e) {
      std::ostringstream os;
      os << "subdomain '" << name_ << "', step " << steps_ << ", t = " << time_ + dt_ << " s: the "
         << kPhaseNames[static_cast<std::size_t>(phase)] << " hook '" << h.name << "' failed: " << e.what();
      throw RuntimeError(os.str());
    }
  }
}

void Subdomain::step_in_order() {
  synchronize();  // a step left pending before the first hook was added
  edited_ = false;  // the dropped ghosts: the lists are stale, this step rebuilds them
  if (ghosts_ != 0 && store_.size() != ghosts_end_)
    throw RuntimeError("subdomain '" + name_ + "': particles were added or removed between steps of a distributed "
                       "run other than through particles_to_edit()");
  const double dt = dt_, half = 0.5 * dt_;
  const std::size_t nt = static_cast<std::size_t>(threads());
  // initial_integrate: half kick and drift of the owned particles,
  // displacements since the last build
  drift_counts_.assign(nt, DriftCounts{});
  const bool stale = nlist_.layout_stale(store_);
  const KickDrift how{dt, half, 0.0, false, stale ? nullptr : &nlist_, nullptr};
  pool_->for_range(owned(), [&](std::size_t first, std::size_t last, int t) {
    drift_counts_[static_cast<std::size_t>(t)] = kick_drift(store_, first, last, how);
  });
  run_hooks(Phase::initial_integrate);
  update_walls(time_ + dt);
  if (rebuild_due(stale)) {
    exchange();
    run_hooks(Phase::exchange);
    rebuild_lists();
    run_hooks(Phase::neighbor);
  } else {
    ranks_->update_ghosts(store_);  // ghost_update (a rebuild made fresh ghosts)
  }
  run_hooks(Phase::ghost_update);
  // body_force: after the exchange, so that particles it brought get theirs
  if (gravity_) gravity_->at(time_ + dt, body_forces_.gravity);
  reset_forces();
  run_hooks(Phase::body_force);
  try {
    contact_forces(false);
  } catch (const PluginError& e) {
    rethrow_with_context(e, "the contact forces");
  }
  run_hooks(Phase::contact_force);
  ranks_->reverse(store_);
  run_hooks(Phase::reverse_exchange);
  run_hooks(Phase::post_force);
  // final_integrate
  nonfinite_counts_.assign(nt, 0.0);
  pool_->for_range(owned(), [&](std::size_t first, std::size_t last, int t) {
    nonfinite_counts_[static_cast<std::size_t>(t)] = kick_check(store_, first, last, half);
  });
  for (double bad : nonfinite_counts_)
    if (bad != 0.0) throw_nonfinite("in the second half kick", time_ + dt, steps_ + 1);
  // the hooks of a completed step see its index and its end time
  run_hooks(Phase::final_integrate);
  run_hooks(Phase::end_of_step);
  time_ += dt;
  ++steps_;
}

PairSweep Subdomain::pair_sweep() const {
  return {&store_, const_cast<NeighborList*>(&nlist_), pipeline_.get(), class_pairs_.data(), class_rolling_.data(),
          pair_class_.data(), static_cast<uint32_t>(class_pairs_.size()), static_cast<uint32_t>(materials_.size()),
          dt_, record_, packed_.xyzr.data()};
}

WallSweep Subdomain::wall_sweep() {
  return {&store_, &wall_lists_, &walls_now_, wall_pairs_.data(), wall_pair_rolling_.data(), wall_uniform_.data(),
          static_cast<uint32_t>(materials_.size()),
          pipeline_.get(), dt_, forces_time_, wall_time_, record_};
}

void Subdomain::contact_forces(bool defer_reduce, bool packed_filled) {
  forces_time_ = time_;
  contacts_counted_ = false;
  contacts_collected_ = false;
  last_max_overlap_ratio_ = 0;
  for (auto& ts : scratch_) ts.records.clear();
  pair_forces(defer_reduce, packed_filled);
  if (reduce_pending_) {
    prune_removed_walls();  // the walls' forces follow in the next pass 1 or synchronize(), per particle range
  } else {
    wall_forces();
  }
}

void Subdomain::pair_forces(bool defer_reduce, bool packed_filled) {
  ParticleStore& s = store_;
  const int nt = threads();
  const bool far = far_active_;
  if (!packed_filled) {
    packed_.resize(s.size());
    pool_->for_range(s.size(), [&](std::size_t first, std::size_t last, int) { packed_.fill(s, first, last); });
  }
  const ForceAccumulator direct = ForceAccumulator::of(s);
  const PairSweep sweep = pair_sweep();
  if (nt > 1) {
    // reads the threads' contact counts of the last evaluation
    partition_.balance(nlist_, far, scratch_, wall_lists_, walls_now_, time_, steps_, s.size());
    partition_.zones(far);
  }
  for (auto& ts : scratch_) {
    ts.pair_contacts = 0;
    ts.pair_max_ratio = 0.0;
  }
  if (nt == 1) {
    const PairRangeFn range = pair_kernel(*pipeline_, false, class_pairs_.size() > 1, nlist_.periodic().any());
    range(sweep, 0, nlist_.near_size(), scratch_[0], 0, s.size(), direct, direct);
    if (far) range(sweep, nlist_.near_size(), nlist_.size(), scratch_[0], 0, s.size(), direct, direct);
  } else {
    // Each thread owns a fixed, contiguous range of each tier of the pair
    // list (so each list entry and its history has one writer). Thread 0 adds
    // into the store. The others add into the store too for the particles
    // that no other thread's pairs touch (ForcePartition::zones), and into
    // their own arrays for the rest, which are summed in thread order
    // (ForcePartition::reduce): the same floating-point sums every run for a
    // given thread count.
    const std::size_t n = s.size();
    pool_->run([&](int t) {
      ContactScratch& ts = scratch_[static_cast<std::size_t>(t)];
      const ForceAccumulator shared = t > 0 ? partition_.private_accumulator(t, n) : direct;
      const ForcePartition::ThreadForces& tf = partition_.thread(t);
      // thread 0 adds all its forces into the store
      const PairRangeFn range = pair_kernel(*pipeline_, t > 0, class_pairs_.size() > 1, nlist_.periodic().any());
      const auto [near_first, near_last] = partition_.entries(0, t);
      range(sweep, near_first, near_last, ts, tf.own_lo, tf.own_hi, direct, shared);
      if (far) {
        const auto [far_first, far_last] = partition_.entries(1, t);
        range(sweep, far_first, far_last, ts, tf.own_lo, tf.own_hi, direct, shared);
      }
    });
    if (defer_reduce) {
      reduce_pending_ = true;  // folded into the next pass 1 or synchronize()
    } else {
      pool_->for_range(n, [&](std::size_t first, std::size_t last, int) { partition_.reduce(s, first, last); });
    }
  }
  last_contacts_ = 0;
  for (const auto& ts : scratch_) {
    last_contacts_ += ts.pair_contacts;
    last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.pair_max_ratio);
  }
}

void Subdomain::wall_forces() {
  prune_removed_walls();
  for (auto& other : scratch_) std::fill(other.wall_load.begin(), other.wall_load.end(), 0.0);
  ContactScratch& ts = scratch_[0];
  ts.wall_contacts = 0;
  ts.wall_max_ratio = 0.0;
  wall_range(wall_sweep(), ts, 0, store_.size());
  last_wall_contacts_ = ts.wall_contacts;
  last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.wall_max_ratio);
}

std::vector<const std::vector<ContactRecord>*> Subdomain::contact_records() const {
  synchronize_logically_const();  // the deferred wall contacts add records
  std::vector<const std::vector<ContactRecord>*> out;
  for (const auto& ts : scratch_) out.push_back(&ts.records);
  return out;
}

MemoryUse Subdomain::memory_use() const {
  MemoryUse m = list_memory(store_, nlist_, wall_lists_);
  m.particles += packed_.bytes();
  m.threads = partition_.bytes();
  return m;
}

SubdomainStats Subdomain::stats() const {
  synchronize_logically_const();
  SubdomainStats st = kinetic_stats(store_, owned());
  st.contacts = last_contacts_;
  st.wall_contacts = last_wall_contacts_;
  st.max_overlap_ratio = last_max_overlap_ratio_;
  return st;
}

}  // namespace domel::platform
