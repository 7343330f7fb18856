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
#include <sstream>

namespace domel::platform {

Subdomain::Subdomain(std::string name, double coarse_grain, std::size_t material,
                     std::unique_ptr<ContactPipeline> pipeline)
    : name_(std::move(name)), coarse_grain_(coarse_grain), material_(material), pipeline_(std::move(pipeline)) {
  set_threads(1);
}

void Subdomain::set_threads(int threads) {
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
  for (int a = 0; a < 3; ++a) gravity_[a] = gravity[a];
}

TimeStepReport Subdomain::estimate_time_step(double impact_velocity) {
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
  auto collide = [&](const domel_pair_v1& pair, double r_i, double r_j, double m_eff, double i_red,
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
  const uint32_t stride = pipeline_->history_stride();
  nlist_.configure(skin_, stride);
  rebuild_lists();
  compute_forces();
}

void Subdomain::rebuild_lists() {
  nlist_.build(store_);
  for (std::size_t w = 0; w < wall_lists_.size(); ++w)
    if (time_ < (*walls_)[w].remove_at) wall_lists_[w].build(store_, (*walls_)[w], skin_, pipeline_->history_stride());
}

void Subdomain::step() {
  const std::size_t n = store_.size();
  const double dt = dt_, half = 0.5 * dt_;
  ParticleStore& s = store_;
  pool_->for_range(n, [&](std::size_t first, std::size_t last, int) {
    for (std::size_t k = first; k < last; ++k) {
      const double hm = half * s.inv_mass[k], hi = half * s.inv_inertia[k];
      s.vx[k] += hm * s.fx[k]; s.vy[k] += hm * s.fy[k]; s.vz[k] += hm * s.fz[k];
      s.wx[k] += hi * s.tx[k]; s.wy[k] += hi * s.ty[k]; s.wz[k] += hi * s.tz[k];
      s.x[k] += dt * s.vx[k]; s.y[k] += dt * s.vy[k]; s.z[k] += dt * s.vz[k];
    }
  });
  if (nlist_.needs_rebuild(s)) rebuild_lists();
  compute_forces();
  std::vector<char> finite_part(static_cast<std::size_t>(threads()), 1);
  pool_->for_range(n, [&](std::size_t first, std::size_t last, int t) {
    bool ok = true;
    for (std::size_t k = first; k < last; ++k) {
      const double hm = half * s.inv_mass[k], hi = half * s.inv_inertia[k];
      s.vx[k] += hm * s.fx[k]; s.vy[k] += hm * s.fy[k]; s.vz[k] += hm * s.fz[k];
      s.wx[k] += hi * s.tx[k]; s.wy[k] += hi * s.ty[k]; s.wz[k] += hi * s.tz[k];
      ok = ok && std::isfinite(s.x[k] + s.y[k] + s.z[k] + s.vx[k] + s.vy[k] + s.vz[k]);
    }
    finite_part[static_cast<std::size_t>(t)] = ok;
  });
  const bool finite = std::all_of(finite_part.begin(), finite_part.end(), [](char c) { return c != 0; });
  time_ += dt;
  ++steps_;
  if (!finite) {
    std::ostringstream os;
    os << "subdomain '" << name_ << "': a particle position or velocity became non-finite at t = " << time_
       << " s (step " << steps_ << "); the time step " << dt_ << " s is probably too large for the contact model";
    throw RuntimeError(os.str());
  }
}

void Subdomain::compute_forces() {
  ParticleStore& s = store_;
  pool_->for_range(s.size(), [&](std::size_t first, std::size_t last, int) {
    for (std::size_t k = first; k < last; ++k) {
      s.fx[k] = s.mass[k] * gravity_[0];
      s.fy[k] = s.mass[k] * gravity_[1];
      s.fz[k] = s.mass[k] * gravity_[2];
      s.tx[k] = s.ty[k] = s.tz[k] = 0.0;
      s.contacts[k] = 0;
    }
  });
  last_max_overlap_ratio_ = 0;
  pair_forces();
  wall_forces();
}

void Subdomain::pair_forces() {
  ParticleStore& s = store_;
  const std::size_t npairs = nlist_.size();
  const int nt = threads();
  const Accumulator direct{s.fx.data(), s.fy.data(), s.fz.data(), s.tx.data(), s.ty.data(), s.tz.data(),
                           s.contacts.data()};
  if (nt == 1) {
    pair_range(0, npairs, scratch_[0], direct);
  } else {
    // Each thread owns a fixed, contiguous range of the pair list (so each
    // list entry and its history has one writer). Thread 0 adds into the
    // store; the others into their own arrays, summed below in thread order:
    // the same floating-point sums every run for a given thread count.
    const std::size_t n = s.size();
    pool_->run([&](int t) {
      ThreadScratch& ts = scratch_[static_cast<std::size_t>(t)];
      Accumulator acc = direct;
      if (t > 0) {
        for (auto* v : {&ts.fx, &ts.fy, &ts.fz, &ts.tx, &ts.ty, &ts.tz}) v->assign(n, 0.0);
        ts.contacts.assign(n, 0);
        acc = {ts.fx.data(), ts.fy.data(), ts.fz.data(), ts.tx.data(), ts.ty.data(), ts.tz.data(),
               ts.contacts.data()};
      }
      const auto r = pool_->range(npairs, t);
      pair_range(r.first, r.second, ts, acc);
    });
    pool_->for_range(n, [&](std::size_t first, std::size_t last, int) {
      for (std::size_t k = first; k < last; ++k)
        for (int t = 1; t < nt; ++t) {
          const ThreadScratch& ts = scratch_[static_cast<std::size_t>(t)];
          s.fx[k] += ts.fx[k]; s.fy[k] += ts.fy[k]; s.fz[k] += ts.fz[k];
          s.tx[k] += ts.tx[k]; s.ty[k] += ts.ty[k]; s.tz[k] += ts.tz[k];
          s.contacts[k] += ts.contacts[k];
        }
    });
  }
  last_contacts_ = 0;
  for (const auto& ts : scratch_) {
    last_contacts_ += ts.n_contacts;
    last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, ts.max_ratio);
  }
}

void Subdomain::pair_range(std::size_t first, std::size_t last, ThreadScratch& ts, const Accumulator& acc) {
  const ParticleStore& s = store_;
  auto& buf = ts.ws->buf;
  const uint32_t stride = nlist_.stride();
  std::size_t contacts = 0;
  double max_ratio = 0.0;
  uint32_t c = 0;

  auto flush = [&]() {
    if (c == 0) return;
    pipeline_->evaluate(*ts.ws, self_pair_, dt_, c);
    for (uint32_t q = 0; q < c; ++q) {
      const uint32_t e = ts.entry[q];
      const uint32_t i = nlist_.i[e], j = nlist_.j[e];
      const double nx = buf.nx[q], ny = buf.ny[q], nz = buf.nz[q];
      const double fn = buf.fn[q];
      const double ftx = buf.ftx[q], fty = buf.fty[q], ftz = buf.ftz[q];
      const double fx = fn * nx + ftx, fy = fn * ny + fty, fz = fn * nz + ftz;
      acc.fx[i] += fx; acc.fy[i] += fy; acc.fz[i] += fz;
      acc.fx[j] -= fx; acc.fy[j] -= fy; acc.fz[j] -= fz;
      // n x F_t
      const double cx = ny * ftz - nz * fty, cy = nz * ftx - nx * ftz, cz = nx * fty - ny * ftx;
      const double ci = ts.ci[q], cj = ts.cj[q];
      acc.tx[i] += -ci * cx + buf.tqx[q]; acc.ty[i] += -ci * cy + buf.tqy[q]; acc.tz[i] += -ci * cz + buf.tqz[q];
      acc.tx[j] += -cj * cx - buf.tqx[q]; acc.ty[j] += -cj * cy - buf.tqy[q]; acc.tz[j] += -cj * cz - buf.tqz[q];
      ++acc.contacts[i];
      ++acc.contacts[j];
      if (stride) std::copy_n(buf.history.begin() + q * stride, stride, nlist_.history.begin() + e * stride);
    }
    contacts += c;
    c = 0;
  };

  for (std::size_t e = first; e < last; ++e) {
    const uint32_t i = nlist_.i[e], j = nlist_.j[e];
    const double dx = s.x[i] - s.x[j], dy = s.y[i] - s.y[j], dz = s.z[i] - s.z[j];
    const double rsum = s.radius[i] + s.radius[j];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 >= rsum * rsum) {
      if (nlist_.touching[e]) {
        nlist_.touching[e] = 0;
        std::fill_n(nlist_.history.begin() + e * stride, stride, 0.0);
      }
      continue;
    }
    const double dist = std::sqrt(d2);
    const double inv = 1.0 / dist;
    const double nx = dx * inv, ny = dy * inv, nz = dz * inv;
    const double delta = rsum - dist;
    const double ci = s.radius[i] - 0.5 * delta, cj = s.radius[j] - 0.5 * delta;
    // contact-point velocities: v_i + w_i x (-ci n) and v_j + w_j x (cj n)
    const double vix = s.vx[i] - ci * (s.wy[i] * nz - s.wz[i] * ny);
    const double viy = s.vy[i] - ci * (s.wz[i] * nx - s.wx[i] * nz);
    const double viz = s.vz[i] - ci * (s.wx[i] * ny - s.wy[i] * nx);
    const double vjx = s.vx[j] + cj * (s.wy[j] * nz - s.wz[j] * ny);
    const double vjy = s.vy[j] + cj * (s.wz[j] * nx - s.wx[j] * nz);
    const double vjz = s.vz[j] + cj * (s.wx[j] * ny - s.wy[j] * nx);
    const double rx = vix - vjx, ry = viy - vjy, rz = viz - vjz;
    const double vdotn = rx * nx + ry * ny + rz * nz;
    buf.overlap[c] = delta;
    buf.nx[c] = nx; buf.ny[c] = ny; buf.nz[c] = nz;
    buf.radius_i[c] = s.radius[i];
    buf.radius_j[c] = s.radius[j];
    buf.r_eff[c] = s.radius[i] * s.radius[j] / rsum;
    buf.m_eff[c] = s.mass[i] * s.mass[j] / (s.mass[i] + s.mass[j]);
    buf.vn[c] = -vdotn;
    buf.vtx[c] = rx - vdotn * nx; buf.vty[c] = ry - vdotn * ny; buf.vtz[c] = rz - vdotn * nz;
    buf.wx[c] = s.wx[i] - s.wx[j]; buf.wy[c] = s.wy[i] - s.wy[j]; buf.wz[c] = s.wz[i] - s.wz[j];
    if (stride) std::copy_n(nlist_.history.begin() + e * stride, stride, buf.history.begin() + c * stride);
    nlist_.touching[e] = 1;
    ts.entry[c] = static_cast<uint32_t>(e);
    ts.ci[c] = ci;
    ts.cj[c] = cj;
    max_ratio = std::max(max_ratio, delta / rsum);
    if (++c == ContactPipeline::kBatchSize) flush();
  }
  flush();
  ts.n_contacts = contacts;
  ts.max_ratio = max_ratio;
}

void Subdomain::wall_forces() {
  ParticleStore& s = store_;
  ThreadScratch& ts = scratch_[0];
  auto& buf = ts.ws->buf;
  const uint32_t stride = pipeline_->history_stride();
  std::size_t contacts = 0;
  double max_ratio = 0.0;
  for (std::size_t w = 0; w < wall_lists_.size(); ++w) {
    WallNeighbors& list = wall_lists_[w];
    const WallPrimitive& wall = (*walls_)[w];
    if (time_ >= wall.remove_at) {  // removed: its contacts open for good
      if (!list.particle.empty()) list = WallNeighbors{};
      continue;
    }
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
        ++s.contacts[i];
        if (stride) std::copy_n(buf.history.begin() + q * stride, stride, list.history.begin() + e * stride);
      }
      contacts += c;
      c = 0;
    };
    for (std::size_t e = 0; e < list.particle.size(); ++e) {
      const uint32_t i = list.particle[e];
      double d, nx, ny, nz;
      const bool has = wall.gap(s.x[i], s.y[i], s.z[i], d, nx, ny, nz);
      if (!has || d >= s.radius[i]) {
        if (list.touching[e]) {
          list.touching[e] = 0;
          std::fill_n(list.history.begin() + e * stride, stride, 0.0);
        }
        continue;
      }
      const double delta = s.radius[i] - d;
      const double ci = s.radius[i] - delta;
      const double rx = s.vx[i] - ci * (s.wy[i] * nz - s.wz[i] * ny);
      const double ry = s.vy[i] - ci * (s.wz[i] * nx - s.wx[i] * nz);
      const double rz = s.vz[i] - ci * (s.wx[i] * ny - s.wy[i] * nx);
      const double vdotn = rx * nx + ry * ny + rz * nz;
      buf.overlap[c] = delta;
      buf.nx[c] = nx; buf.ny[c] = ny; buf.nz[c] = nz;
      buf.radius_i[c] = s.radius[i];
      buf.radius_j[c] = 0.0;
      buf.r_eff[c] = s.radius[i];
      buf.m_eff[c] = s.mass[i];
      buf.vn[c] = -vdotn;
      buf.vtx[c] = rx - vdotn * nx; buf.vty[c] = ry - vdotn * ny; buf.vtz[c] = rz - vdotn * nz;
      buf.wx[c] = s.wx[i]; buf.wy[c] = s.wy[i]; buf.wz[c] = s.wz[i];
      if (stride) std::copy_n(list.history.begin() + e * stride, stride, buf.history.begin() + c * stride);
      list.touching[e] = 1;
      ts.entry[c] = static_cast<uint32_t>(e);
      ts.ci[c] = ci;
      max_ratio = std::max(max_ratio, delta / (2.0 * s.radius[i]));
      if (++c == ContactPipeline::kBatchSize) flush();
    }
    flush();
  }
  last_wall_contacts_ = contacts;
  last_max_overlap_ratio_ = std::max(last_max_overlap_ratio_, max_ratio);
}

SubdomainStats Subdomain::stats() const {
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
