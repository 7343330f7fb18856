// SPDX-License-Identifier: MIT
// The time-step estimate (time_step.hpp).
#include "contact/time_step.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace domel::platform {

TimeStepReport estimate_time_step(const TimeStepInputs& in, const ParticleStore& s, double impact_velocity) {
  TimeStepReport rep;
  if (s.size() == 0) return rep;
  const std::size_t n_mat = in.materials->size();
  // the smallest particle of each material present
  std::vector<std::size_t> smallest(n_mat, SIZE_MAX);
  for (std::size_t k = 0; k < s.size(); ++k) {
    std::size_t& q = smallest[s.material[k]];
    if (q == SIZE_MAX || s.radius[k] < s.radius[q]) q = k;
  }
  // Rayleigh time, docs/physics.md §1.3: the shortest of the materials present.
  bool first = true;
  for (std::size_t a = 0; a < n_mat; ++a) {
    if (smallest[a] == SIZE_MAX) continue;
    const Material& mat = (*in.materials)[a];
    const double nu = mat.poisson_ratio;
    const double g_mod = mat.youngs_modulus / (2.0 * (1.0 + nu));
    const double t = M_PI * s.radius[smallest[a]] * std::sqrt(mat.density / g_mod) / (0.1631 * nu + 0.8766);
    rep.rayleigh = first ? t : std::min(rep.rayleigh, t);
    first = false;
  }

  auto& buf = in.pipeline->buffers();
  // i_red: rotational inertia of the relative rolling mode (pair of equal
  // spheres: I/2; sphere on a wall: I), for the rolling spring's own limit
  // 2(sqrt(1+zeta^2) - zeta)/omega_theta, omega_theta = sqrt(k_theta/I_red)
  // (docs/physics.md §3.6).
  auto collide = [&](const domel_pair_v2& pair, const ModelInstance* rolling_model, double r_i, double r_j, double m_i, double m_j, double m_eff,
                     double i_red, double& t_contact, double& dt_crit, bool& rolling_sets_limit, bool& through) {
    const double r_eff = r_j > 0 ? r_i * r_j / (r_i + r_j) : r_i;
    // The overlap at which the spheres' centres meet (a wall: the centre
    // reaches its surface). A contact still approaching there has not stopped
    // the impact: the collision ends there, reported as passing through (a
    // contact far too soft for the impact velocity would otherwise be
    // integrated for the step cap without ending).
    const double delta_through = r_j > 0 ? r_i + r_j : r_i;
    // Integrate delta'' = -F_n(delta, delta')/m* from first touch until the
    // contact opens, with a step refined until the duration converges.
    double h = 1e-3 * r_eff / impact_velocity;
    double previous = -1.0;
    for (int refine = 0; refine < 12; ++refine) {
      double delta = 0.0, v = impact_velocity, t = 0.0, crit = 1e300;
      bool rolling = false;
      through = false;
      auto force = [&](double d, double vel) {
        buf.overlap[0] = std::max(d, 1e-300);
        buf.r_eff[0] = r_eff; buf.m_eff[0] = m_eff; buf.radius_i[0] = r_i; buf.radius_j[0] = r_j;
        buf.mass_i[0] = m_i; buf.mass_j[0] = m_j;  // m_j = 0: a wall
        buf.nx[0] = 0; buf.ny[0] = 0; buf.nz[0] = 1; buf.vn[0] = vel;
        buf.vtx[0] = buf.vty[0] = buf.vtz[0] = 0; buf.wx[0] = buf.wy[0] = buf.wz[0] = 0;
        std::fill(buf.history.begin(), buf.history.end(), 0.0);
        in.pipeline->evaluate(pair, rolling_model, h, 1);
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
        if (!(delta < delta_through)) {  // NaN included
          through = true;
          break;
        }
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
  double tc, crit;
  bool rolling = false, through = false;
  first = true;
  // "particle-particle contact", or with several materials the pair's names
  auto pair_name = [&](std::size_t a, std::size_t b) {
    return n_mat == 1 ? std::string("particle-particle contact")
                      : "contact of " + (*in.materials)[a].name + " with " + (*in.materials)[b].name;
  };
  auto keep = [&](const std::string& what) {
    if (through) rep.passes_through += (rep.passes_through.empty() ? "" : ", ") + what;
    if (first || tc < rep.contact_time) rep.contact_time = tc;
    if (first || crit < rep.critical) {
      rep.critical = crit;
      rep.critical_of = (rolling ? "rolling spring of the " : "") + what;
    }
    first = false;
  };
  for (std::size_t a = 0; a < n_mat; ++a) {
    if (smallest[a] == SIZE_MAX) continue;
    const double ra = s.radius[smallest[a]], ma = s.mass[smallest[a]];
    const double ia = 0.4 * ma * ra * ra;  // solid sphere
    for (std::size_t b = a; b < n_mat; ++b) {
      if (smallest[b] == SIZE_MAX) continue;
      if (b == a) {  // a pair of equal spheres: m* = m/2, the relative rolling mode's inertia I/2
        collide((*in.pairs)[a * n_mat + a], (*in.pair_rolling)[a * n_mat + a], ra, ra, ma, ma, 0.5 * ma, 0.5 * ia, tc, crit, rolling, through);
      } else {
        const double rb = s.radius[smallest[b]], mb = s.mass[smallest[b]];
        const double ib = 0.4 * mb * rb * rb;
        collide((*in.pairs)[a * n_mat + b], (*in.pair_rolling)[a * n_mat + b], ra, rb, ma, mb, ma * mb / (ma + mb), ia * ib / (ia + ib), tc, crit,
                rolling, through);
      }
      keep(pair_name(a, b));
    }
  }
  for (std::size_t w = 0; w < in.walls->size(); ++w)
    for (std::size_t a = 0; a < n_mat; ++a) {
      if (smallest[a] == SIZE_MAX) continue;
      const double ra = s.radius[smallest[a]], ma = s.mass[smallest[a]];
      collide((*in.wall_pairs)[w * n_mat + a], (*in.wall_pair_rolling)[w * n_mat + a], ra, 0.0, ma, 0.0, ma, 0.4 * ma * ra * ra, tc, crit, rolling, through);
      keep(std::string("contact with wall '") + (*in.walls)[w].name + "'" +
           (n_mat == 1 ? "" : " (" + (*in.materials)[a].name + ")"));
    }
  return rep;
}

namespace {
std::string seconds(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}
}  // namespace

TimeStepProblem choose_time_step(const std::string& subdomain, TimeStepReport& rep, std::optional<double> given,
                                 bool estimated, double impact_velocity) {
  if (!estimated) {
    if (!given)
      return {"cannot choose a time step automatically for a subdomain without particles", "give time_step in seconds"};
    rep.chosen = *given;
    rep.reason = "given (no particles to check it against)";
    return {};
  }
  if (given) {
    rep.chosen = *given;
    rep.reason = "given";
    if (rep.chosen > rep.critical)
      return {"time step " + seconds(rep.chosen) + " s exceeds the explicit stability limit " + seconds(rep.critical) +
                  " s set by the " + rep.critical_of + " (impact velocity " + seconds(impact_velocity) +
                  " m/s, contact time " + seconds(rep.contact_time) + " s)",
              "use at most " + seconds(rep.critical) + " s, or \"auto\""};
    if (rep.chosen > rep.contact_time / 20.0)
      spdlog::warn("subdomain '{}': time step {:.3g} s resolves a collision ({:.3g} s) with only {:.0f} steps; "
                   "expect inaccurate restitution (20-50 steps per contact are usual)",
                   subdomain, rep.chosen, rep.contact_time, rep.contact_time / rep.chosen);
    return {};
  }
  // 0.2 x Rayleigh: the middle of common practice's 0.1-0.3 (docs/physics.md §1.3); 50 steps per
  // collision; half the stability limit of the stiffest contact.
  const double by_rayleigh = 0.2 * rep.rayleigh, by_contact = rep.contact_time / 50.0;
  rep.chosen = std::min({by_rayleigh, by_contact, 0.5 * rep.critical});
  rep.reason = rep.chosen == by_rayleigh  ? "auto: 0.2 x Rayleigh time"
               : rep.chosen == by_contact ? "auto: contact time / 50"
                                          : "auto: half the stability limit of the " + rep.critical_of;
  // particles so small that their times underflow (a diameter of 5e-324 m:
  // the run-time fuzzer) give a step of 0 s, which no run can take
  if (!(rep.chosen > 0) || !std::isfinite(rep.chosen))
    return {"the automatic time step is " + seconds(rep.chosen) + " s (0.2 x Rayleigh time " + seconds(rep.rayleigh) +
                " s, contact time " + seconds(rep.contact_time) + " s at " + seconds(impact_velocity) +
                " m/s): no run can step with it",
            "check the particles' diameters (SI units: metres) and the contact's stiffness, or give time_step"};
  return {};
}

}  // namespace domel::platform
