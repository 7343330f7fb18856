// SPDX-License-Identifier: MIT
// Force evaluation and velocity-Verlet integration of one subdomain.
//
// Contact geometry (docs/physics.md notation): n points from j to i,
// overlap delta = R_i + R_j - |x_i - x_j|. The lever arm from a particle
// centre to the contact point is c_i = R_i - delta/2 for a particle pair
// (the middle of the overlap, as LIGGGHTS' c_ri) and c_i = R_i - delta for a
// wall (the contact point lies on the wall surface).
// Relative velocity of the contact points: v_c = (v_i + w_i x (-c_i n)) - (v_j + w_j x (c_j n)).
// Forces: F_i = F_n n + F_t, F_j = -F_i. Torques: T_i = -c_i n x F_t + M,
// T_j = -c_j n x F_t - M (M: rolling/twisting couple on i).
#include "subdomain/subdomain.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <sstream>
#include <tuple>
#include <utility>

namespace domel::platform {

Subdomain::Subdomain(std::string name, double coarse_grain, std::size_t material,
                     std::unique_ptr<ContactPipeline> pipeline)
    : name_(std::move(name)), coarse_grain_(coarse_grain), material_(material), pipeline_(std::move(pipeline)) {
  set_threads(default_thread_count());
}

void Subdomain::set_threads(int threads) {
  if (pool_) synchronize();  // a pending force sum lives in the scratch being replaced
  pool_ = std::make_unique<ThreadPool>(threads);
  scratch_.clear();
  scratch_.resize(static_cast<std::size_t>(std::max(1, threads)));
  for (auto& ts : scratch_) {
    ts.ws = pipeline_->make_workspace();
    ts.entry.resize(ContactPipeline::kBatchSize);
    ts.ci.resize(ContactPipeline::kBatchSize);
    ts.cj.resize(ContactPipeline::kBatchSize);
  }
}

void Subdomain::set_environment(const std::vector<Material>& materials,
                                const std::vector<PairCoefficients>& wall_pairs, const PairCoefficients& self_pair,
                                const std::vector<WallPrimitive>* walls, const double gravity[3]) {
  own_material_ = materials.at(material_);
  walls_ = walls;
  self_pair_ = make_pair(own_material_, own_material_, self_pair, false, coarse_grain_);
  wall_pairs_.clear();
  for (std::size_t w = 0; w < walls->size(); ++w)
    wall_pairs_.push_back(make_pair(own_material_, materials.at((*walls)[w].material), wall_pairs.at(w), true,
                                    coarse_grain_));
  wall_lists_.assign(walls->size(), WallNeighbors{});
  walls_now_ = *walls;
  any_moving_ = std::any_of(walls_now_.begin(), walls_now_.end(), [](const WallPrimitive& w) { return w.moving; });
  for (int a = 0; a < 3; ++a) gravity_[a] = gravity[a];
}

TimeStepReport Subdomain::estimate_time_step(double impact_velocity) {
  synchronize();
  TimeStepReport rep;
  if (store_.size() == 0) return rep;
  std::size_t smallest = 0;
  for (std::size_t k = 1; k < store_.size(); ++k)
    if (store_.radius[k] < store_.radius[smallest]) smallest = k;
  const double r = store_.radius[smallest];
  const double m = store_.mass[smallest];
  // Rayleigh time, docs/physics.md §1.3.
  const double nu = own_material_.poisson_ratio;
  const double g_mod = own_material_.youngs_modulus / (2.0 * (1.0 + nu));
  rep.rayleigh = M_PI * r * std::sqrt(own_material_.density / g_mod) / (0.1631 * nu + 0.8766);

  auto& buf = pipeline_->buffers();
  // i_red: rotational inertia of the relative rolling mode (pair of equal
  // spheres: I/2; sphere on a wall: I), for the rolling spring's own limit
  // 2(sqrt(1+zeta^2) - zeta)/omega_theta, omega_theta = sqrt(k_theta/I_red)
  // (docs/physics.md §3.6).
  auto collide = [&](const domel_pair_v2& pair, double r_i, double r_j, double m_eff, double i_red,
                     double& t_contact, double& dt_crit, bool& rolling_sets_limit) {
    const double r_eff = r_j > 0 ? r_i * r_j / (r_i + r_j) : r_i;
    // Integrate delta'' = -F_n(delta, delta')/m* from first touch until the
    // contact opens, with a step refined until the duration converges.
    double h = 1e-3 * r_eff / impact_velocity;
    double previous = -1.0;
    for (int refine = 0; refine < 12; ++refine) {
      double delta = 0.0, v = impact_velocity, t = 0.0, crit = 1e300;
      bool rolling = false;
      auto force = [&](double d, double vel) {
        buf.overlap[0] = std::max(d, 1e-300);
        buf.r_eff[0] = r_eff; buf.m_eff[0] = m_eff; buf.radius_i[0] = r_i; buf.radius_j[0] = r_j;
        buf.mass_i[0] = r_j > 0 ? 2.0 * m_eff : m_eff; buf.mass_j[0] = r_j > 0 ? 2.0 * m_eff : 0.0;  // equal spheres or a wall
        buf.nx[0] = 0; buf.ny[0] = 0; buf.nz[0] = 1; buf.vn[0] = vel;
        buf.vtx[0] = buf.vty[0] = buf.vtz[0] = 0; buf.wx[0] = buf.wy[0] = buf.wz[0] = 0;
        std::fill(buf.history.begin(), buf.history.end(), 0.0);
        pipeline_->evaluate(pair, h, 1);
        const double k = buf.kn_tangent[0];
        if (k > 0) {
          const double omega = std::sqrt(k / m_eff);
          const double zeta = buf.eta_n[0] / (2.0 * std::sqrt(m_eff * k));
          crit = std::min(crit, 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta) / omega);
        }
        const double k_roll = buf.rolling_stiffness[0];
        if (k_roll > 0) {
          const double omega = std::sqrt(k_roll / i_red);
          const double zeta = buf.rolling_damping[0] / (2.0 * std::sqrt(i_red * k_roll));
          const double limit = 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta) / omega;
          if (limit < crit) {
            crit = limit;
            rolling = true;
          }
        }
        return buf.fn[0];
      };
      double a = -force(delta, v) / m_eff;
      std::size_t n = 0;
      do {
        v += 0.5 * h * a;
        delta += h * v;
        a = -force(delta, v) / m_eff;
        v += 0.5 * h * a;
        t += h;
        ++n;
      } while (delta > 0.0 && n < 2000000);
      t_contact = t;
      dt_crit = crit;
      rolling_sets_limit = rolling;
      if (previous > 0 && std::fabs(t - previous) < 1e-3 * t) break;
      previous = t;
      if (n > 4000) break;  // resolved well enough
      h *= 0.25;
    }
    std::fill(buf.history.begin(), buf.history.end(), 0.0);
  };
  const double inertia = 0.4 * m * r * r;  // solid sphere
  double tc, crit;
  bool rolling = false;
  collide(self_pair_, r, r, 0.5 * m, 0.5 * inertia, tc, crit, rolling);
  rep.contact_time = tc;
  rep.critical = crit;
  rep.critical_of = rolling ? "rolling spring of the particle-particle contact" : "particle-particle contact";
  for (std::size_t w = 0; w < wall_pairs_.size(); ++w) {
    collide(wall_pairs_[w], r, 0.0, m, inertia, tc, crit, rolling);
    rep.contact_time = std::min(rep.contact_time, tc);
    if (crit < rep.critical) {
      rep.critical = crit;
      rep.critical_of = std::string(rolling ? "rolling spring of the " : "") + "contact with wall '" +
                        (*walls_)[w].name + "'";
    }
  }
  return rep;
}

void Subdomain::setup() {
  synchronize();
  const uint32_t stride = pipeline_->history_stride();
  nlist_.configure(skin_, stride);
  update_walls(time_);
  rebuild_lists();
  compute_forces();
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
  nlist_.build(store_, pool_.get());
  far_active_ = false;
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
    const WallPrimitive& wall = walls_now_[w];
    wall_lists_[w].build(store_, wall, skin_, pipeline_->history_stride(), wall.active(time_));
    wall_lists_[w].built_elapsed = wall.elapsed(wall_time_);
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
        list.build(store_, wall, skin_, stride, true);
        list.built_elapsed = wall.elapsed(t);
      }
    } else if (active && wall.moving &&
               wall.displacement_bound(list.built_elapsed, wall.elapsed(t)) > 0.5 * skin_) {
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

namespace {
// The integration passes as free functions: GCC honours __restrict on
// parameters (not on local pointers), and with ~20 arrays the alias checks it
// would otherwise need exceed its versioning limit, so the loops would stay
// scalar. With restrict parameters both passes vectorise.

/// Pass 1 of a step, fused: half kick, drift, displacement since the last list
/// build (kCheck), and the force/torque reset to gravity. Returns the number of
/// particles that moved farther than sqrt(limit2) (a sum of 0/1 in double:
/// GCC 12 vectorises it, but not a floating-point max without -ffast-math,
/// nor an integer OR of a double comparison).
/// With kFinish it first does the previous step's second half kick (of
/// half_prev, with the same forces) and its finiteness check (see
/// kick_check), counted into `bad`: one sweep over the store per step
/// instead of two. The arithmetic is that of the two passes, value by value.
/// 1 for a particle whose position or velocity is inf or NaN, else 0, with
/// no branch: !(|x + y + ...| <= max) holds for inf and NaN.
inline double nonfinite(double sum_of_coordinates) {
  return std::fabs(sum_of_coordinates) <= std::numeric_limits<double>::max() ? 0.0 : 1.0;
}

template <bool kCheck, bool kFinish>
double kick_drift_reset(std::size_t first, std::size_t last, double dt, double half, double half_prev,
                        const double g[3], double* __restrict x, double* __restrict y, double* __restrict z,
                        double* __restrict vx, double* __restrict vy, double* __restrict vz, double* __restrict wx,
                        double* __restrict wy, double* __restrict wz, double* __restrict fx, double* __restrict fy,
                        double* __restrict fz, double* __restrict tx, double* __restrict ty, double* __restrict tz,
                        const double* __restrict im, const double* __restrict ii, const double* __restrict m,
                        const double* __restrict x0, const double* __restrict y0,
                        const double* __restrict z0, double limit2, double limit2_far, double& far_tier,
                        double& bad) {
  const double g0 = g[0], g1 = g[1], g2 = g[2];
  double far = 0.0, tier = 0.0, bad_count = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    double ux = vx[k], uy = vy[k], uz = vz[k], ox = wx[k], oy = wy[k], oz = wz[k];
    const double gx = fx[k], gy = fy[k], gz = fz[k], qx = tx[k], qy = ty[k], qz = tz[k];
    double px = x[k], py = y[k], pz = z[k];
    if constexpr (kFinish) {
      const double hm = half_prev * im[k], hi = half_prev * ii[k];
      ux += hm * gx; uy += hm * gy; uz += hm * gz;
      ox += hi * qx; oy += hi * qy; oz += hi * qz;
      bad_count += nonfinite(px + py + pz + ux + uy + uz);
    }
    const double hm = half * im[k], hi = half * ii[k];
    ux += hm * gx; uy += hm * gy; uz += hm * gz;
    ox += hi * qx; oy += hi * qy; oz += hi * qz;
    px += dt * ux; py += dt * uy; pz += dt * uz;
    vx[k] = ux; vy[k] = uy; vz[k] = uz;
    wx[k] = ox; wy[k] = oy; wz[k] = oz;
    x[k] = px; y[k] = py; z[k] = pz;
    if constexpr (kCheck) {
      const double dx = px - x0[k], dy = py - y0[k], dz = pz - z0[k];
      const double d2 = dx * dx + dy * dy + dz * dz;
      far += (d2 > limit2) ? 1.0 : 0.0;
      tier += (d2 > limit2_far) ? 1.0 : 0.0;
    }
    fx[k] = m[k] * g0; fy[k] = m[k] * g1; fz[k] = m[k] * g2;
    tx[k] = 0.0; ty[k] = 0.0; tz[k] = 0.0;
  }
  far_tier = tier;
  bad = bad_count;
  return far;
}

/// Pass 2 on its own (synchronize()): the second half kick and the
/// finiteness check. Returns the count of non-finite particles.
double kick_check(std::size_t first, std::size_t last, double half, const double* __restrict x,
                  const double* __restrict y, const double* __restrict z, double* __restrict vx,
                  double* __restrict vy, double* __restrict vz, double* __restrict wx, double* __restrict wy,
                  double* __restrict wz, const double* __restrict fx, const double* __restrict fy,
                  const double* __restrict fz, const double* __restrict tx, const double* __restrict ty,
                  const double* __restrict tz, const double* __restrict im, const double* __restrict ii) {
  double bad = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    const double hm = half * im[k], hi = half * ii[k];
    vx[k] += hm * fx[k]; vy[k] += hm * fy[k]; vz[k] += hm * fz[k];
    wx[k] += hi * tx[k]; wy[k] += hi * ty[k]; wz[k] += hi * tz[k];
    bad += nonfinite(x[k] + y[k] + z[k] + vx[k] + vy[k] + vz[k]);
  }
  return bad;
}

bool any_nonzero(const std::vector<double>& v) {
  return std::any_of(v.begin(), v.end(), [](double f) { return f != 0.0; });
}
}  // namespace

std::pair<std::size_t, std::size_t> Subdomain::finish_forces(int t, bool reduce, std::size_t n) {
  if (!reduce) return pool_->range(n, t);
  // the other threads' pair forces, then the wall contacts of this thread's
  // particles (each wall contact touches one particle)
  const std::size_t first = pass2_split_[static_cast<std::size_t>(t)];
  const std::size_t last = pass2_split_[static_cast<std::size_t>(t) + 1];
  reduce_partials(first, last);
  ThreadScratch& ts = scratch_[static_cast<std::size_t>(t)];
  ts.wall_contacts = 0;
  ts.wall_max_ratio = 0.0;
  wall_range(ts, first, last);
  return {first, last};
}

void Subdomain::finish_wall_stats() {
  last_wall_contacts_ = 0;
  for (const auto& ts : scratch_) {
    last_wall_contacts_ += ts.wall_contacts;
    last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.wall_max_ratio);
  }
}

void Subdomain::throw_nonfinite() const {
  std::ostringstream os;
  os << "subdomain '" << name_ << "': a particle position or velocity became non-finite at t = " << time_
     << " s (step " << steps_ << "); the time step " << dt_ << " s is probably too large for the contact model";
  throw RuntimeError(os.str());
}

bool Subdomain::take_pending_reduce(std::size_t n) {
  const bool reduce = reduce_pending_;
  reduce_pending_ = false;
  if (reduce) reduce_split(n);
  return reduce;
}

void Subdomain::synchronize() {
  if (!kick_pending_) return;
  kick_pending_ = false;
  const std::size_t n = store_.size();
  ParticleStore& s = store_;
  const bool reduce = take_pending_reduce(n);
  std::vector<double>& bad = bad_partial_;
  bad.assign(static_cast<std::size_t>(threads()), 0.0);
  pool_->run([&](int t) {
    const auto [first, last] = finish_forces(t, reduce, n);
    bad[static_cast<std::size_t>(t)] =
        kick_check(first, last, pending_half_, s.x.data(), s.y.data(), s.z.data(), s.vx.data(), s.vy.data(),
                   s.vz.data(), s.wx.data(), s.wy.data(), s.wz.data(), s.fx.data(), s.fy.data(), s.fz.data(),
                   s.tx.data(), s.ty.data(), s.tz.data(), s.inv_mass.data(), s.inv_inertia.data());
  });
  if (reduce) finish_wall_stats();
  if (any_nonzero(bad)) throw_nonfinite();
}

void Subdomain::step_deferred() {
  const std::size_t n = store_.size();
  const double dt = dt_, half = 0.5 * dt_;
  ParticleStore& s = store_;
  const std::size_t nt = static_cast<std::size_t>(threads());
  std::vector<double>& partial = partial_;
  partial.assign(nt, 0.0);
  std::vector<double>& tier = tier_partial_;
  tier.assign(nt, 0.0);
  std::vector<double>& bad = bad_partial_;
  bad.assign(nt, 0.0);
  // Pass 1 (one sweep over the store instead of the five of a textbook
  // step: the last step's second half kick (unless synchronize() did it),
  // this step's half kick and drift, rebuild check, force reset;
  // docs/performance.md). With threads, the last step's force sums and
  // wall contacts are finished first, per particle range.
  const bool stale = nlist_.layout_stale(s);
  const bool finish = kick_pending_;
  kick_pending_ = false;
  const bool reduce = take_pending_reduce(n);  // pending only with a pending kick
  pool_->run([&](int t) {
    const auto [first, last] = finish_forces(t, reduce, n);
    auto pass = stale ? (finish ? &kick_drift_reset<false, true> : &kick_drift_reset<false, false>)
                      : (finish ? &kick_drift_reset<true, true> : &kick_drift_reset<true, false>);
    const auto q = static_cast<std::size_t>(t);
    partial[q] = pass(first, last, dt, half, pending_half_, gravity_, s.x.data(), s.y.data(), s.z.data(),
                      s.vx.data(), s.vy.data(), s.vz.data(), s.wx.data(), s.wy.data(), s.wz.data(), s.fx.data(),
                      s.fy.data(), s.fz.data(), s.tx.data(), s.ty.data(), s.tz.data(), s.inv_mass.data(),
                      s.inv_inertia.data(), s.mass.data(), nlist_.x0(), nlist_.y0(), nlist_.z0(),
                      nlist_.rebuild_displacement2(), nlist_.far_tier_displacement2(), tier[q], bad[q]);
  });
  if (reduce) finish_wall_stats();
  // reported as at the end of the last step, where the two-pass step found it
  if (finish && any_nonzero(bad)) throw_nonfinite();
  update_walls(time_ + dt);
  if (stale || walls_force_rebuild_ || any_nonzero(partial)) {
    walls_force_rebuild_ = false;
    rebuild_lists();
  } else if (any_nonzero(tier)) {
    far_active_ = true;  // latched until the next build: far entries are screened from now on
  }
  // The forces; with threads, the other threads' sums and the wall contacts
  // are left to the next pass 1 (or synchronize()), as is the second half
  // kick: one fork/join and one sweep less per step.
  contact_forces(true);
  kick_pending_ = true;
  pending_half_ = half;
  time_ += dt;
  ++steps_;
}

void Subdomain::compute_forces() {
  ParticleStore& s = store_;
  pool_->for_range(s.size(), [&](std::size_t first, std::size_t last, int) {
    for (std::size_t k = first; k < last; ++k) {
      s.fx[k] = s.mass[k] * gravity_[0];
      s.fy[k] = s.mass[k] * gravity_[1];
      s.fz[k] = s.mass[k] * gravity_[2];
      s.tx[k] = s.ty[k] = s.tz[k] = 0.0;
    }
  });
  contact_forces();
}

std::vector<const std::vector<ContactRecord>*> Subdomain::contact_records() const {
  synchronize_logically_const();  // the deferred wall contacts add records
  std::vector<const std::vector<ContactRecord>*> out;
  for (const auto& ts : scratch_) out.push_back(&ts.records);
  return out;
}

void Subdomain::contact_forces(bool defer_reduce) {
  forces_time_ = time_;
  contacts_counted_ = false;
  last_max_overlap_ratio_ = 0;
  for (auto& ts : scratch_) ts.records.clear();
  pair_forces(defer_reduce);
  if (reduce_pending_) {
    prune_removed_walls();  // the walls' forces follow in the next pass 1 or synchronize(), per particle range
  } else {
    wall_forces();
  }
}

void Subdomain::pair_forces(bool defer_reduce) {
  ParticleStore& s = store_;
  const int nt = threads();
  const bool far = far_active_;
  const Accumulator direct{s.fx.data(), s.fy.data(), s.fz.data(), s.tx.data(), s.ty.data(), s.tz.data()};
  if (nt > 1) {
    balance_pairs(nt);  // reads the threads' contact counts of the last evaluation
    thread_zones(far);
  }
  for (auto& ts : scratch_) {
    ts.n_contacts = 0;
    ts.max_ratio = 0.0;
  }
  if (nt == 1) {
    ThreadScratch& ts = scratch_[0];
    ts.own_lo = 0;
    ts.own_hi = s.size();
    const auto range = pair_kernel(false);
    (this->*range)(0, nlist_.near_size(), ts, direct, direct);
    if (far) (this->*range)(nlist_.near_size(), nlist_.size(), ts, direct, direct);
  } else {
    // Each thread owns a fixed, contiguous range of each tier of the pair
    // list (so each list entry and its history has one writer). Thread 0 adds
    // into the store. The others add into the store too for the particles
    // that no other thread's pairs touch (thread_zones), and into their own
    // arrays for the rest, which are summed in thread order
    // (reduce_partials): the same floating-point sums every run for a given
    // thread count.
    const std::size_t n = s.size();
    pool_->run([&](int t) {
      const std::size_t q = static_cast<std::size_t>(t);
      ThreadScratch& ts = scratch_[q];
      Accumulator shared = direct;
      if (t > 0) {
        if (ts.fx.size() != n)
          for (auto* v : {&ts.fx, &ts.fy, &ts.fz, &ts.tx, &ts.ty, &ts.tz}) v->assign(n, 0.0);
        for (const auto& [lo, hi] : ts.shared_ranges()) {
          const auto a = static_cast<std::ptrdiff_t>(lo), b = static_cast<std::ptrdiff_t>(hi);
          for (auto* v : {&ts.fx, &ts.fy, &ts.fz, &ts.tx, &ts.ty, &ts.tz}) std::fill(v->begin() + a, v->begin() + b, 0.0);
        }
        shared = {ts.fx.data(), ts.fy.data(), ts.fz.data(), ts.tx.data(), ts.ty.data(), ts.tz.data()};
      }
      const auto range = pair_kernel(t > 0);  // thread 0 adds all its forces into the store
      (this->*range)(split_[0][q], split_[0][q + 1], ts, direct, shared);
      if (far) (this->*range)(split_[1][q], split_[1][q + 1], ts, direct, shared);
    });
    if (defer_reduce) {
      reduce_pending_ = true;  // folded into the next pass 1 or synchronize()
    } else {
      pool_->for_range(n, [&](std::size_t first, std::size_t last, int) { reduce_partials(first, last); });
    }
  }
  last_contacts_ = 0;
  for (const auto& ts : scratch_) {
    last_contacts_ += ts.n_contacts;
    last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.max_ratio);
  }
}

void Subdomain::thread_zones(bool far) {
  // Each thread's particle-index span this step: its near-tier span, widened
  // by its far-tier span while the far tier is screened.
  const int nt = threads();
  for (ThreadScratch& ts : scratch_) {
    ts.lo = ts.span[0][0];
    ts.hi = ts.span[0][1];
    if (far && ts.span[1][1] > ts.span[1][0]) {
      ts.lo = ts.hi > ts.lo ? std::min(ts.lo, ts.span[1][0]) : ts.span[1][0];
      ts.hi = std::max(ts.hi, ts.span[1][1]);
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
    ThreadScratch& ts = scratch_[static_cast<std::size_t>(t)];
    std::size_t a = ts.lo, b = ts.hi;
    for (int u = 0; u < nt && a < b; ++u) {
      const ThreadScratch& other = scratch_[static_cast<std::size_t>(u)];
      if (u == t || other.hi <= other.lo || other.hi <= a || other.lo >= b) continue;
      if (other.lo <= a) a = other.hi;
      else if (other.hi >= b) b = other.lo;
      else if (other.lo - a >= b - other.hi) b = other.lo;  // keep the larger side
      else a = other.hi;
    }
    if (a < b) {
      ts.own_lo = a;
      ts.own_hi = b;
    } else {
      ts.own_lo = ts.own_hi = ts.hi;
    }
  }
}

void Subdomain::refresh_wall_work() {
  // The wall contacts of a particle are evaluated by the thread whose
  // pass-2 range holds it. They sit where the walls are, at one end of the
  // spatially ordered store (a floor: the first particles), so they weigh in
  // the split. Per wall-list entry: its gap test, and for a contact the
  // batch gather, the contact kernels and the scatter; a particle's kick
  // costs 1 (weights from the measured pass-1 imbalance on S2 at 10k,
  // docs/performance.md). Kept as (particle, cost of the entries up to this
  // one) in particle order, refreshed with the pair split (balance_pairs):
  // after each list build and every kBalanceEvery steps. Only the split
  // depends on it, never a result.
  constexpr double kWallEntryCost = 1.0;
  constexpr double kWallContactCost = 6.0;
  std::vector<std::pair<uint32_t, double>>& ev = wall_work_;
  ev.clear();
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
    if (!walls_now_[w].active(time_)) continue;
    const WallNeighbors& list = wall_lists_[w];
    const auto mid = static_cast<std::ptrdiff_t>(ev.size());
    for (std::size_t e = 0; e < list.particle.size(); ++e)  // ascending particle order
      ev.emplace_back(list.particle[e], kWallEntryCost + (list.touching[e] ? kWallContactCost : 0.0));
    std::inplace_merge(ev.begin(), ev.begin() + mid, ev.end(),
                       [](const auto& x, const auto& y) { return x.first < y.first; });
  }
  for (std::size_t e = 1; e < ev.size(); ++e) ev[e].second += ev[e - 1].second;  // costs -> running sums
}

void Subdomain::reduce_split(std::size_t n) {
  // Split [0, n) for the second half kick so that each thread has the same
  // estimated cost: a particle costs 1, plus kReduceCost for each other
  // thread whose force span covers it (the reduction's loads and adds), plus
  // its wall contacts (refresh_wall_work). Equal particle counts would leave
  // the whole reduction to the threads whose share overlaps the spans, and
  // the floor's contacts to the first thread. Deterministic: from the spans
  // and the lists only.
  constexpr double kReduceCost = 1.5;
  const int nt = threads();
  std::vector<std::size_t>& cuts = split_cuts_;  // members: no allocation per step
  cuts.assign({0, n});
  for (int t = 1; t < nt; ++t) {
    const ThreadScratch& ts = scratch_[static_cast<std::size_t>(t)];
    for (std::size_t c : {ts.lo, ts.own_lo, ts.own_hi, ts.hi}) cuts.push_back(std::min(c, n));
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  auto weight = [&](std::size_t k) {
    double w = 1.0;
    for (int t = 1; t < nt; ++t)
      for (const auto& [lo, hi] : scratch_[static_cast<std::size_t>(t)].shared_ranges())
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

void Subdomain::reduce_partials(std::size_t first, std::size_t last) {
  ParticleStore& s = store_;
  for (int t = 1; t < threads(); ++t) {
    const ThreadScratch& ts = scratch_[static_cast<std::size_t>(t)];
    for (const auto& [lo, hi] : ts.shared_ranges()) {
      const std::size_t a = std::max(first, lo), b = std::min(last, hi);
      for (std::size_t k = a; k < b; ++k) {
        s.fx[k] += ts.fx[k]; s.fy[k] += ts.fy[k]; s.fz[k] += ts.fz[k];
        s.tx[k] += ts.tx[k]; s.ty[k] += ts.ty[k]; s.tz[k] += ts.tz[k];
      }
    }
  }
}

namespace {
// History rows are a few doubles (3 for Mindlin, 6 with a rolling model):
// copy them inline; std::copy_n becomes a memmove call that costs more than
// the copy itself at these sizes (perf: 6 % of a settle step).
inline void copy_row(const double* __restrict src, double* __restrict dst, uint32_t n) {
  switch (n) {
    case 0: return;
    case 1: dst[0] = src[0]; return;
    case 2: dst[0] = src[0]; dst[1] = src[1]; return;
    case 3: dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; return;
    case 4: dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; dst[3] = src[3]; return;
    case 5: dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; dst[3] = src[3]; dst[4] = src[4]; return;
    case 6:
      dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; dst[3] = src[3]; dst[4] = src[4]; dst[5] = src[5];
      return;
    default: std::copy_n(src, n, dst);
  }
}
}  // namespace

void Subdomain::balance_pairs(int nt) {
  // Contiguous ranges of each tier of the pair list with near-equal estimated
  // cost: an entry costs 1 (the overlap screen) and a contact kContactCost
  // more (the contact kernels and the scatter). Two threads, 2026-12-01:
  // 12 ran S2 with sd_critical_angle at 50k 4 % faster than 8 (its contacts
  // carry a rolling kernel), S1 and the dense bed 1-2 % faster; 16 and 24
  // were no better. Even entry counts leave the thread with the
  // dense, settled bottom of a column with most of the work. The split
  // depends only on the list and its contact flags, never on timings, so a
  // run is bit-identical for a given thread count. Recomputed after each
  // list build, and every kBalanceEvery steps when the threads' estimated
  // costs in the last force evaluation (their ranges' entries, and their
  // contacts as counted there) differ by more than kRebalanceAt: the two
  // serial scans of the list are then skipped while the contacts stay put
  // (at 10k they cost ~2 % of a two-thread step when done every 32 steps).
  constexpr uint64_t kContactCost = 12;
  constexpr std::uint64_t kBalanceEvery = 32;
  constexpr double kRebalanceAt = 0.01;
  const std::size_t tiers[3] = {0, nlist_.near_size(), nlist_.size()};
  if (split_[0].size() == static_cast<std::size_t>(nt) + 1 && split_builds_ == nlist_.builds()) {
    if (steps_ % kBalanceEvery != 0) return;
    double lo = 0, hi = 0;
    for (std::size_t q = 0; q < static_cast<std::size_t>(nt); ++q) {
      std::size_t entries = split_[0][q + 1] - split_[0][q];
      if (far_active_) entries += split_[1][q + 1] - split_[1][q];
      const double cost = static_cast<double>(entries + kContactCost * scratch_[q].n_contacts);
      lo = q == 0 ? cost : std::min(lo, cost);
      hi = q == 0 ? cost : std::max(hi, cost);
    }
    if (hi - lo <= kRebalanceAt * hi) return;
  }
  refresh_wall_work();
  const uint8_t* touching = nlist_.touching.data();
  const uint32_t* li = nlist_.i.data();
  const uint32_t* lj = nlist_.j.data();
  for (int tier = 0; tier < 2; ++tier) {
    const std::size_t begin = tiers[tier], end = tiers[tier + 1];
    std::vector<std::size_t>& split = split_[tier];
    split.assign(static_cast<std::size_t>(nt) + 1, end);
    split[0] = begin;
    uint64_t total = end - begin;
    for (std::size_t e = begin; e < end; ++e) total += kContactCost * touching[e];
    uint64_t run = 0;
    int t = 1;
    for (std::size_t e = begin; e < end && t < nt; ++e) {
      run += 1 + kContactCost * touching[e];
      while (t < nt && run * static_cast<uint64_t>(nt) >= total * static_cast<uint64_t>(t)) split[t++] = e + 1;
    }
    // The particle-index span each thread's pairs touch (thread_zones).
    for (int q = 0; q < nt; ++q) {
      ThreadScratch& ts = scratch_[static_cast<std::size_t>(q)];
      std::size_t lo = store_.size(), hi = 0;
      for (std::size_t e = split[static_cast<std::size_t>(q)]; e < split[static_cast<std::size_t>(q) + 1]; ++e) {
        lo = std::min<std::size_t>(lo, std::min(li[e], lj[e]));
        hi = std::max<std::size_t>(hi, std::max(li[e], lj[e]) + 1u);
      }
      ts.span[tier][0] = lo < hi ? lo : 0;
      ts.span[tier][1] = lo < hi ? hi : 0;
    }
  }
  split_builds_ = nlist_.builds();
}

Subdomain::PairRange Subdomain::pair_kernel(bool zoned) const {
  if (pipeline_->has_torque()) return zoned ? &Subdomain::pair_range<true, true> : &Subdomain::pair_range<false, true>;
  return zoned ? &Subdomain::pair_range<true, false> : &Subdomain::pair_range<false, false>;
}

template <bool kZoned, bool kTorque>
void Subdomain::pair_range(std::size_t first, std::size_t last, ThreadScratch& ts, const Accumulator& own,
                           const Accumulator& shared) {
  const ParticleStore& s = store_;
  auto& buf = ts.ws->buf;
  const uint32_t stride = nlist_.stride();
  std::size_t contacts = 0;
  double max_ratio = 0.0;

  const uint32_t* __restrict li = nlist_.i.data();
  const uint32_t* __restrict lj = nlist_.j.data();
  uint8_t* __restrict touching = nlist_.touching.data();
  double* __restrict list_history = nlist_.history.data();
  const double* __restrict px = s.x.data(); const double* __restrict py = s.y.data();
  const double* __restrict pz = s.z.data(); const double* __restrict pr = s.radius.data();
  const double* __restrict pvx = s.vx.data(); const double* __restrict pvy = s.vy.data();
  const double* __restrict pvz = s.vz.data();
  const double* __restrict pwx = s.wx.data(); const double* __restrict pwy = s.wy.data();
  const double* __restrict pwz = s.wz.data();
  const double* __restrict pm = s.mass.data();
  uint32_t* __restrict entry = ts.entry.data();
  double* __restrict lever_i = ts.ci.data();
  double* __restrict lever_j = ts.cj.data();
  double* __restrict b_overlap = buf.overlap.data();
  double* __restrict b_nx = buf.nx.data(); double* __restrict b_ny = buf.ny.data();
  double* __restrict b_nz = buf.nz.data();
  double* __restrict b_ri = buf.radius_i.data(); double* __restrict b_rj = buf.radius_j.data();
  double* __restrict b_reff = buf.r_eff.data(); double* __restrict b_meff = buf.m_eff.data();
  double* __restrict b_mi = buf.mass_i.data(); double* __restrict b_mj = buf.mass_j.data();
  double* __restrict b_vn = buf.vn.data();
  double* __restrict b_vtx = buf.vtx.data(); double* __restrict b_vty = buf.vty.data();
  double* __restrict b_vtz = buf.vtz.data();
  double* __restrict b_wx = buf.wx.data(); double* __restrict b_wy = buf.wy.data();
  double* __restrict b_wz = buf.wz.data();
  double* __restrict b_hist = buf.history.data();
  constexpr uint32_t kBatch = ContactPipeline::kBatchSize;
  // unsigned k - zone_lo < zone_width: k in [own_lo, own_hi)
  const auto zone_lo = static_cast<uint32_t>(ts.own_lo);
  const auto zone_width = static_cast<uint32_t>(ts.own_hi - ts.own_lo);
  const Accumulator own_acc = own, shared_acc = shared;
  // a - b and a + (-b) are the same IEEE operation, so both sides use one add
  const auto add = [](const Accumulator& a, uint32_t k, double fx, double fy, double fz, double tx, double ty,
                      double tz) {
    a.fx[k] += fx; a.fy[k] += fy; a.fz[k] += fz;
    a.tx[k] += tx; a.ty[k] += ty; a.tz[k] += tz;
  };

  std::size_t e = first;
  while (e < last) {
    // Phase A: screen list entries for overlap, branch-free except for the
    // rare contact that just opened, until a batch is full. Most entries of a
    // Verlet list are not in contact (S1: ~5 of 6), so a data-dependent
    // branch here mispredicts often.
    uint32_t c = 0;
    for (; e < last && c < kBatch; ++e) {
      const uint32_t i = li[e], j = lj[e];
      const double dx = px[i] - px[j], dy = py[i] - py[j], dz = pz[i] - pz[j];
      const double rsum = pr[i] + pr[j];
      const uint32_t in = (dx * dx + dy * dy + dz * dz < rsum * rsum) ? 1u : 0u;
      if (touching[e] > in) {  // the contact opened: its history ends
        touching[e] = 0;
        for (uint32_t h = 0; h < stride; ++h) list_history[e * stride + h] = 0.0;
      }
      entry[c] = static_cast<uint32_t>(e);
      c += in;
    }
    if (c == 0) continue;
    // Phase B: contact geometry and relative velocities of the batch.
    for (uint32_t q = 0; q < c; ++q) {
      const uint32_t le = entry[q];
      const uint32_t i = li[le], j = lj[le];
      const double ri = pr[i], rj = pr[j];
      const double dx = px[i] - px[j], dy = py[i] - py[j], dz = pz[i] - pz[j];
      const double rsum = ri + rj, inv_rsum = 1.0 / rsum;
      const double dist = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double inv = 1.0 / dist;
      const double nx = dx * inv, ny = dy * inv, nz = dz * inv;
      const double delta = rsum - dist;
      const double ci = ri - 0.5 * delta, cj = rj - 0.5 * delta;
      // contact-point velocities: v_i + w_i x (-ci n) and v_j + w_j x (cj n)
      const double wix = pwx[i], wiy = pwy[i], wiz = pwz[i];
      const double wjx = pwx[j], wjy = pwy[j], wjz = pwz[j];
      const double vix = pvx[i] - ci * (wiy * nz - wiz * ny);
      const double viy = pvy[i] - ci * (wiz * nx - wix * nz);
      const double viz = pvz[i] - ci * (wix * ny - wiy * nx);
      const double vjx = pvx[j] + cj * (wjy * nz - wjz * ny);
      const double vjy = pvy[j] + cj * (wjz * nx - wjx * nz);
      const double vjz = pvz[j] + cj * (wjx * ny - wjy * nx);
      const double rx = vix - vjx, ry = viy - vjy, rz = viz - vjz;
      const double vdotn = rx * nx + ry * ny + rz * nz;
      b_overlap[q] = delta;
      b_nx[q] = nx; b_ny[q] = ny; b_nz[q] = nz;
      b_ri[q] = ri;
      b_rj[q] = rj;
      b_reff[q] = ri * rj * inv_rsum;  // one division for R* and the overlap ratio
      b_meff[q] = pm[i] * pm[j] / (pm[i] + pm[j]);
      b_mi[q] = pm[i]; b_mj[q] = pm[j];
      b_vn[q] = -vdotn;
      b_vtx[q] = rx - vdotn * nx; b_vty[q] = ry - vdotn * ny; b_vtz[q] = rz - vdotn * nz;
      b_wx[q] = wix - wjx; b_wy[q] = wiy - wjy; b_wz[q] = wiz - wjz;
      copy_row(list_history + static_cast<std::size_t>(le) * stride, b_hist + static_cast<std::size_t>(q) * stride,
               stride);
      touching[le] = 1;
      lever_i[q] = ci;
      lever_j[q] = cj;
      max_ratio = std::max(max_ratio, delta * inv_rsum);
    }
    pipeline_->evaluate(*ts.ws, self_pair_, dt_, c);
    // Scatter: forces and torques onto both particles, history back to the list.
    const double* __restrict fn_ = buf.fn.data();
    const double* __restrict ftx_ = buf.ftx.data(); const double* __restrict fty_ = buf.fty.data();
    const double* __restrict ftz_ = buf.ftz.data();
    const double* __restrict tqx_ = buf.tqx.data(); const double* __restrict tqy_ = buf.tqy.data();
    const double* __restrict tqz_ = buf.tqz.data();
    for (uint32_t q = 0; q < c; ++q) {
      const uint32_t le = entry[q];
      const uint32_t i = li[le], j = lj[le];
      const double nx = b_nx[q], ny = b_ny[q], nz = b_nz[q];
      const double fn = fn_[q];
      const double ftx = ftx_[q], fty = fty_[q], ftz = ftz_[q];
      const double fx = fn * nx + ftx, fy = fn * ny + fty, fz = fn * nz + ftz;
      // n x F_t
      const double cx = ny * ftz - nz * fty, cy = nz * ftx - nx * ftz, cz = nx * fty - ny * ftx;
      const double ci = lever_i[q], cj = lever_j[q];
      double tix = -ci * cx, tiy = -ci * cy, tiz = -ci * cz;
      double tjx = -cj * cx, tjy = -cj * cy, tjz = -cj * cz;
      if constexpr (kTorque) {  // else the couple is zero, and adding it would change no bit (sums start at +0)
        tix += tqx_[q]; tiy += tqy_[q]; tiz += tqz_[q];
        tjx -= tqx_[q]; tjy -= tqy_[q]; tjz -= tqz_[q];
      }
      // A branch, not a select of the accumulator: it is taken the same way
      // for all but the few particles of the band other threads share, and
      // the own path keeps its pointers in registers (one writer: always).
      if (!kZoned || i - zone_lo < zone_width) add(own_acc, i, fx, fy, fz, tix, tiy, tiz);
      else add(shared_acc, i, fx, fy, fz, tix, tiy, tiz);
      if (!kZoned || j - zone_lo < zone_width) add(own_acc, j, -fx, -fy, -fz, tjx, tjy, tjz);
      else add(shared_acc, j, -fx, -fy, -fz, tjx, tjy, tjz);
      copy_row(b_hist + static_cast<std::size_t>(q) * stride, list_history + static_cast<std::size_t>(le) * stride,
               stride);
    }
    if (record_)
      for (uint32_t q = 0; q < c; ++q) {
        const uint32_t le = entry[q];
        const double fn = fn_[q];
        ts.records.push_back({li[le], lj[le], fn * b_nx[q] + ftx_[q], fn * b_ny[q] + fty_[q], fn * b_nz[q] + ftz_[q],
                              0.0, 0.0, 0.0});
      }
    contacts += c;
  }
  ts.n_contacts += contacts;
  ts.max_ratio = std::max(ts.max_ratio, max_ratio);
}

void Subdomain::count_contacts() {
  // From the contact flags the last force evaluation left in the lists (the
  // screened part of the pair list; the walls active then), in the layout it
  // ran on: store() calls this before anyone can change the layout.
  ParticleStore& s = store_;
  s.contacts.assign(s.size(), 0u);
  const std::size_t screened = far_active_ ? nlist_.size() : nlist_.near_size();
  if (!nlist_.layout_stale(s))
    for (std::size_t e = 0; e < screened; ++e)
      if (nlist_.touching[e]) {
        ++s.contacts[nlist_.i[e]];
        ++s.contacts[nlist_.j[e]];
      }
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
    if (!walls_now_[w].active(forces_time_)) continue;
    const WallNeighbors& list = wall_lists_[w];
    for (std::size_t e = 0; e < list.particle.size(); ++e)
      if (list.touching[e] && list.particle[e] < s.size()) ++s.contacts[list.particle[e]];
  }
  contacts_counted_ = true;
}

void Subdomain::prune_removed_walls() {
  for (std::size_t w = 0; w < wall_lists_.size(); ++w)
    if (!walls_now_[w].active(time_) && wall_lists_[w].built)  // removed: contacts open for good
      wall_lists_[w].clear();
}

void Subdomain::wall_forces() {
  prune_removed_walls();
  ThreadScratch& ts = scratch_[0];
  ts.wall_contacts = 0;
  ts.wall_max_ratio = 0.0;
  wall_range(ts, 0, store_.size());
  last_wall_contacts_ = ts.wall_contacts;
  last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.wall_max_ratio);
}

void Subdomain::wall_range(ThreadScratch& ts, std::size_t first, std::size_t last) {
  // Wall contacts of the particles with index in [first, last). Each touches
  // one particle, so threads with disjoint particle ranges may run this at
  // once (finish_forces() does). Wall lists are in index order.
  ParticleStore& s = store_;
  auto& buf = ts.ws->buf;
  const uint32_t stride = pipeline_->history_stride();
  std::size_t contacts = 0;
  double max_ratio = 0.0;
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
    WallNeighbors& list = wall_lists_[w];
    const WallPrimitive& wall = walls_now_[w];
    // pruned by prune_removed_walls() / update_walls(); the time of the force
    // evaluation, as the walls' contacts may be finished in the next step
    if (!wall.active(forces_time_)) continue;
    const auto lo = std::lower_bound(list.particle.begin(), list.particle.end(), static_cast<uint32_t>(first));
    const auto hi = std::lower_bound(lo, list.particle.end(), static_cast<uint32_t>(std::min<std::size_t>(last, UINT32_MAX)));
    const std::size_t e_first = static_cast<std::size_t>(lo - list.particle.begin());
    const std::size_t e_last = static_cast<std::size_t>(hi - list.particle.begin());
    uint32_t c = 0;
    auto flush = [&]() {
      if (c == 0) return;
      pipeline_->evaluate(*ts.ws, wall_pairs_[w], dt_, c);
      for (uint32_t q = 0; q < c; ++q) {
        const uint32_t e = ts.entry[q];
        const uint32_t i = list.particle[e];
        const double nx = buf.nx[q], ny = buf.ny[q], nz = buf.nz[q];
        const double fn = buf.fn[q];
        const double ftx = buf.ftx[q], fty = buf.fty[q], ftz = buf.ftz[q];
        s.fx[i] += fn * nx + ftx; s.fy[i] += fn * ny + fty; s.fz[i] += fn * nz + ftz;
        const double cx = ny * ftz - nz * fty, cy = nz * ftx - nx * ftz, cz = nx * fty - ny * ftx;
        const double ci = ts.ci[q];
        s.tx[i] += -ci * cx + buf.tqx[q]; s.ty[i] += -ci * cy + buf.tqy[q]; s.tz[i] += -ci * cz + buf.tqz[q];
        copy_row(buf.history.data() + q * stride, list.history.data() + e * stride, stride);
        if (record_)  // the contact point lies on the wall, ci from the centre along -n
          ts.records.push_back({i, ContactRecord::kWall, fn * nx + ftx, fn * ny + fty, fn * nz + ftz,
                                s.x[i] - ci * nx, s.y[i] - ci * ny, s.z[i] - ci * nz});
      }
      contacts += c;
      c = 0;
    };
    // One contact into the batch: entry e of the list, particle i, centre
    // distance d from the contact point, unit normal n (wall -> centre).
    const bool moving = wall.moving;
    auto push = [&](std::size_t e, uint32_t i, double d, double nx, double ny, double nz) {
      const double delta = s.radius[i] - d;
      const double ci = s.radius[i] - delta;
      double rx = s.vx[i] - ci * (s.wy[i] * nz - s.wz[i] * ny);
      double ry = s.vy[i] - ci * (s.wz[i] * nx - s.wx[i] * nz);
      double rz = s.vz[i] - ci * (s.wx[i] * ny - s.wy[i] * nx);
      if (moving) {  // relative to the wall's surface velocity at the contact point x_i - ci n
        double ux, uy, uz;
        wall.surface_velocity(wall_time_, s.x[i] - ci * nx, s.y[i] - ci * ny, s.z[i] - ci * nz, ux, uy, uz);
        rx -= ux; ry -= uy; rz -= uz;
      }
      const double vdotn = rx * nx + ry * ny + rz * nz;
      buf.overlap[c] = delta;
      buf.nx[c] = nx; buf.ny[c] = ny; buf.nz[c] = nz;
      buf.radius_i[c] = s.radius[i];
      buf.radius_j[c] = 0.0;
      buf.r_eff[c] = s.radius[i];
      buf.m_eff[c] = s.mass[i];
      buf.mass_i[c] = s.mass[i]; buf.mass_j[c] = 0.0;
      buf.vn[c] = -vdotn;
      buf.vtx[c] = rx - vdotn * nx; buf.vty[c] = ry - vdotn * ny; buf.vtz[c] = rz - vdotn * nz;
      buf.wx[c] = s.wx[i]; buf.wy[c] = s.wy[i]; buf.wz[c] = s.wz[i];
      copy_row(list.history.data() + e * stride, buf.history.data() + c * stride, stride);
      list.touching[e] = 1;
      ts.entry[c] = static_cast<uint32_t>(e);
      ts.ci[c] = ci;
      max_ratio = std::max(max_ratio, delta / (2.0 * s.radius[i]));
      if (++c == ContactPipeline::kBatchSize) flush();
    };
    if (wall.shape == WallPrimitive::Shape::mesh) {
      // Per particle: the counted features of its candidate triangles
      // (resolve_mesh_contacts). A contact that moves from one triangle to
      // a neighbour (a sphere crossing a seam) keeps its history: a newly
      // counted entry takes the history of an entry of the same particle
      // that stopped counting this step.
      for (std::size_t e = e_first; e < e_last;) {
        const uint32_t i = list.particle[e];
        std::size_t e_end = e + 1;
        while (e_end < e_last && list.particle[e_end] == i) ++e_end;
        const std::size_t count = e_end - e;
        const double p[3] = {s.x[i], s.y[i], s.z[i]};
        resolve_mesh_contacts(*wall.mesh, wall.verts.data(), p, s.radius[i], list.triangle.data() + e, count,
                              ts.mesh, ts.mesh_out, wall.tri_bounds.empty() ? nullptr : wall.tri_bounds.data());
        ts.counted.assign(count, 0);
        for (const MeshContact& mc : ts.mesh_out) ts.counted[mc.slot] = 1;
        std::size_t released = SIZE_MAX;
        for (std::size_t k = 0; k < count; ++k) {
          if (!list.touching[e + k] || ts.counted[k]) continue;
          list.touching[e + k] = 0;
          if (released == SIZE_MAX) released = e + k;
          else std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>((e + k) * stride), stride, 0.0);
        }
        for (const MeshContact& mc : ts.mesh_out) {
          const std::size_t entry = e + mc.slot;
          if (!list.touching[entry] && released != SIZE_MAX) {
            std::copy_n(list.history.begin() + static_cast<std::ptrdiff_t>(released * stride), stride,
                        list.history.begin() + static_cast<std::ptrdiff_t>(entry * stride));
            std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>(released * stride), stride, 0.0);
            released = SIZE_MAX;
          }
          push(entry, i, mc.d, mc.n[0], mc.n[1], mc.n[2]);
        }
        if (released != SIZE_MAX)
          std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>(released * stride), stride, 0.0);
        e = e_end;
      }
      flush();
      continue;
    }
    for (std::size_t e = e_first; e < e_last; ++e) {
      const uint32_t i = list.particle[e];
      double d, nx, ny, nz;
      const bool has = wall.gap(s.x[i], s.y[i], s.z[i], d, nx, ny, nz);
      if (!has || d >= s.radius[i]) {
        if (list.touching[e]) {
          list.touching[e] = 0;
          std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>(e * stride), stride, 0.0);
        }
        continue;
      }
      push(e, i, d, nx, ny, nz);
    }
    flush();
  }
  ts.wall_contacts += contacts;
  ts.wall_max_ratio = std::max(ts.wall_max_ratio, max_ratio);
}

MemoryUse Subdomain::memory_use() const {
  MemoryUse m;
  m.particles = store_.bytes();
  m.neighbor_lists = nlist_.bytes_without_history();
  m.contact_history = nlist_.history_bytes();
  for (const WallNeighbors& w : wall_lists_) {
    m.neighbor_lists += w.bytes_without_history();
    m.contact_history += w.history_bytes();
  }
  for (const ThreadScratch& ts : scratch_)
    m.threads += (ts.fx.capacity() + ts.fy.capacity() + ts.fz.capacity() + ts.tx.capacity() + ts.ty.capacity() +
                  ts.tz.capacity()) * sizeof(double);
  return m;
}

SubdomainStats Subdomain::stats() const {
  synchronize_logically_const();
  SubdomainStats st;
  const ParticleStore& s = store_;
  st.particles = s.size();
  st.contacts = last_contacts_;
  st.wall_contacts = last_wall_contacts_;
  st.max_overlap_ratio = last_max_overlap_ratio_;
  double sum_w = 0, sum_slow = 0;
  std::size_t slow = 0;
  std::vector<double> speeds;
  speeds.reserve(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (s.fixed(k)) {
      ++st.fixed;
      continue;
    }
    st.kinetic_translational += 0.5 * s.mass[k] * (s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k] + s.vz[k] * s.vz[k]);
    const double w2 = s.wx[k] * s.wx[k] + s.wy[k] * s.wy[k] + s.wz[k] * s.wz[k];
    st.kinetic_rotational += 0.5 * w2 / s.inv_inertia[k];
    const double speed = std::sqrt(w2);
    speeds.push_back(speed);
    sum_w += speed;
    if (speed < 1.0) {
      sum_slow += speed;
      ++slow;
    }
  }
  if (!speeds.empty()) {
    st.mean_angular_speed = sum_w / speeds.size();
    const std::size_t mid = speeds.size() / 2;
    std::nth_element(speeds.begin(), speeds.begin() + mid, speeds.end());
    double median = speeds[mid];
    if (speeds.size() % 2 == 0) median = 0.5 * (median + *std::max_element(speeds.begin(), speeds.begin() + mid));
    st.median_angular_speed = median;
  }
  if (slow) st.trimmed_mean_angular_speed = sum_slow / slow;
  return st;
}

}  // namespace domel::platform
