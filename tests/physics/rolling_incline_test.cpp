// Guards the single-parameter rolling model end to end (scenario JSON ->
// plugins -> Subdomain), issue acceptance 6(a) and docs/physics.md §9
// target 1: a sphere on a rough incline (sliding prevented: mu = 2 >
// tan(beta) for every beta used) with rolling "sd_critical_angle" stays at
// rest at beta = theta_c - 1 deg and rolls away at beta = theta_c + 1 deg,
// for theta_c = 10, 20, 30 deg, with Hertz+Mindlin and linear+linear.
//
// Why (§3.1, §3.2): at rest the tangential force is T = m g sin(beta) and the
// rolling spring must carry T times the lever arm c = R - delta (the wall
// contact point lies on the wall, subdomain.cpp); it can give at most
// M_ref = R* tan(theta_c) F_n,el with R* = R (wall) and F_n,el = m g cos(beta).
// So the sphere holds iff tan(beta) (1 - delta/R) <= tan(theta_c). Here
// delta/R = 4e-4 (linear) and 1.2e-3 (Hertz) at rest, which moves the
// threshold by < 0.03 deg, far inside the +-1 deg of the issue (§9 target 1
// suggests +-0.5 deg).
//
// Start: the plane is z = 0 and the slope is made by tilting gravity (as
// incline_rolling_test.cpp). The sphere starts at rest AT ITS STATIC NORMAL
// OVERLAP delta_s (F_n,el(delta_s) = m g cos(beta)). Dropped from zero
// overlap instead, the normal spring would overshoot to ~2 delta_s and ring
// until its dashpot stops it (a few contact times at e = 0.5); F_n,el, and
// with it the cap M_ref, would swing between ~0 and ~2 m g cos(beta) while
// the tangential and rolling springs are being loaded, so the spring could
// yield early in the low phase. (Tried: with these parameters that start
// only lengthens the settling below, by 0-13 %, and the sphere still holds,
// but the resting start keeps the normal impact out of what is measured.)
// Settling with gravity normal first and tilting afterwards is not
// possible without resetting the wall's contact history (gravity is set
// together with the walls in Subdomain::set_environment, which clears the
// wall lists), and that would re-apply the tangential and rolling load as a
// step anyway. What remains is the step load of the tangential and rolling
// springs (their history starts at 0): the lightly damped rolling mode
// overshoots, so below theta_c the first swing yields briefly and the
// sphere rolls a little before the spring holds (afterwards |M| oscillates
// between M_ref and 2 M_app - M_ref > -M_ref, so it never yields again).
// Undamped, this elastic-plastic settling can be estimated in the slope
// coordinate x with the tangential force F: the rolling spring and the
// tangential spring act in series, compliance C = c^2/k_theta + 1/k_t
// (k_theta = k_n R^2 tan^2(theta_c)/4, §3.3, k_n tangent; k_t = 2/7 k_n
// linear, 8 G* sqrt(R delta) Mindlin). The step load F_a = m g sin(beta)
// reaches the yield force F_y = M_ref/c at x_y = C F_y with kinetic energy
// F_a x_y - F_y x_y/2, which the plastic phase brakes with F_y - F_a; the
// sphere then rings about its new rest point, which lies at
//   x_rest = x_y (F_a - F_y/2)/(F_y - F_a) + C F_a.
// Damping only shortens it (measured 0.83-0.97 x_rest); the displacement is
// asserted below 1.1 x_rest (0.02-0.04 d here; 10 % because the two springs
// carry different inertias, so the energy balance is not exactly 1-D). This
// settling is not "drift": the at-rest check measures the motion over the
// 1 s that follows a 1.5 s settling period.
//
// Tolerances:
//  - drift < 1e-3 d over 1 s (issue 6(a)).
//  - final |omega| < 1e-3 rad/s: a sphere rolling at that rate moves
//    R * 1e-3 = 1.4 um/s = 5e-4 d per second, i.e. the same "at rest"
//    criterion as the drift bound. The residual elastic rolling oscillation
//    about the contact point (I_c = 7/5 m R^2) decays as exp(-n_theta t/(2 I_c)),
//    n_theta = eta_n a^2/4: 5.1 /s (linear) and 3.2 /s (Hertz, softer dashpot
//    at the resting overlap) at theta_c = 10 deg, e = 0.5, faster for larger
//    theta_c; from ~3 rad/s during the settling to < 1e-3 rad/s by 2.5 s.
//    Hence the 1.5 s settling period.
//  - rolling away: > 5 d in 1 s (issue: "several d"). Expected: once the
//    spring is saturated the torque is M_ref, so the sphere rolls without
//    slipping with a = c (m g sin(beta) c - M_ref)/(I + m c^2), c = R - delta_s
//    (~20 d in 1 s); with c = R this is (5/7) g (sin(beta) - tan(theta_c)
//    cos(beta)), but the small difference of two close torques makes the
//    delta/R correction 0.4-3 % of a. The measured acceleration over
//    [0.5, 1] s is compared with the formula with c within 1 %: the tangential
//    spring's stick-slip ringing averages out over 0.5 s (incline_rolling_test).
//  - time step: the estimator's contact time / 50 at 0.1 m/s (issue 2; the
//    rolling mode is slower than the normal one for theta_c <= 30 deg, §3.6).
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace dt = domel::test;
using domel::platform::Subdomain;

namespace {

constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kE = 5e6, kNu = 0.3, kG = 9.81;
constexpr double kMu = 2.0, kE_rest = 0.5, kLinearStiffness = 500.0;
constexpr double kDeg = M_PI / 180.0;

enum class Law { hertz, linear };

nlohmann::json contact_block(Law law, double theta_c) {
  nlohmann::json c = law == Law::hertz ? dt::hertz_mindlin() : dt::linear_spring(kLinearStiffness);
  c["rolling"] = {{"model", "sd_critical_angle"}, {"critical_angle", theta_c}};
  return c;
}

/// Overlap at which the elastic normal force carries m g cos(beta).
double static_overlap(Law law, double weight_normal) {
  if (law == Law::linear) return weight_normal / kLinearStiffness;
  // Hertz, sphere on a wall of the same material: F = 4/3 E* sqrt(R) delta^{3/2}
  const double e_star = 1.0 / (2.0 * (1.0 - kNu * kNu) / kE);
  return std::pow(weight_normal / (4.0 / 3.0 * e_star * std::sqrt(kR)), 2.0 / 3.0);
}

struct Run {
  double x_settle = 0;  ///< position along the slope at t_settle (from the start) [m]
  double x_end = 0;     ///< at the end [m]
  double v_mid = 0, v_end = 0, t_mid = 0, t_end = 0;
  double w_end = 0;     ///< |omega| at the end [rad/s]
  double dt = 0;
};

Run incline(Law law, double theta_c, double beta_deg, double t_settle, double duration) {
  const double beta = beta_deg * kDeg;
  auto doc = dt::scenario(contact_block(law, theta_c), 1e-6, kE_rest, kMu, kE, kNu, kRho);
  doc["gravity"] = {kG * std::sin(beta), 0.0, -kG * std::cos(beta)};
  dt::add_plane(doc, "slope", {0, 0, 0}, {0, 0, 1});
  auto sim = dt::build(doc);
  Subdomain& sd = *sim->subdomains[0];
  auto& s = sd.store();
  const double m = kRho * 4.0 / 3.0 * M_PI * kR * kR * kR;
  s.add(1, 0, 0, kR - static_overlap(law, m * kG * std::cos(beta)), kR, kRho);
  const auto rep = sd.estimate_time_step(0.1);
  sd.set_time_step(std::min(rep.contact_time / 50.0, 0.5 * rep.critical));
  sd.set_skin(0.2 * kD);
  sd.setup();
  Run r;
  r.dt = sd.time_step();
  const double x0 = s.x[0];
  bool have_settle = t_settle <= 0, have_mid = false;
  const double t_mid = 0.5 * duration;
  while (sd.time() < duration - 0.5 * r.dt) {
    sd.step();
    if (!have_settle && sd.time() >= t_settle) {
      r.x_settle = s.x[0] - x0;
      have_settle = true;
    }
    if (!have_mid && sd.time() >= t_mid) {
      r.v_mid = s.vx[0];
      r.t_mid = sd.time();
      have_mid = true;
    }
  }
  r.x_end = s.x[0] - x0;
  r.v_end = s.vx[0];
  r.t_end = sd.time();
  r.w_end = std::sqrt(s.wx[0] * s.wx[0] + s.wy[0] * s.wy[0] + s.wz[0] * s.wz[0]);
  return r;
}

/// Tangent normal stiffness dF/d(delta) at the static overlap (what sets k_theta, §3.3).
double resting_stiffness(Law law, double weight_normal) {
  if (law == Law::linear) return kLinearStiffness;
  const double e_star = 1.0 / (2.0 * (1.0 - kNu * kNu) / kE);
  return 2.0 * e_star * std::sqrt(kR * static_overlap(law, weight_normal));
}

/// Tangential spring stiffness at the static overlap: linear k_t = 2/7 k_n,
/// Mindlin 8 G* sqrt(R delta) (§1.1; wall of the same material).
double resting_tangential_stiffness(Law law, double weight_normal) {
  if (law == Law::linear) return 2.0 / 7.0 * kLinearStiffness;
  const double g_star = 1.0 / (2.0 * 2.0 * (2.0 - kNu) * (1.0 + kNu) / kE);
  return 8.0 * g_star * std::sqrt(kR * static_overlap(law, weight_normal));
}

void check_critical_angle(Law law, const char* name) {
  const double m = kRho * 4.0 / 3.0 * M_PI * kR * kR * kR, inertia = 0.4 * m * kR * kR;
  for (double theta_c : {10.0, 20.0, 30.0}) {
    ASSERT_LT(std::tan((theta_c + 1.0) * kDeg), kMu) << "set-up: sliding must be prevented";
    const double tan_c = std::tan(theta_c * kDeg);
    // below: at rest
    {
      const double beta = theta_c - 1.0, b = beta * kDeg;
      const double fn = m * kG * std::cos(b);
      const double c = kR - static_overlap(law, fn);
      const double a_arm = kR * tan_c;
      const double k_theta = 0.25 * resting_stiffness(law, fn) * a_arm * a_arm;
      const double compliance = c * c / k_theta + 1.0 / resting_tangential_stiffness(law, fn);
      const double f_y = a_arm * fn / c, f_a = m * kG * std::sin(b);
      const double x_y = compliance * f_y;
      const double settle_estimate = x_y * (f_a - 0.5 * f_y) / (f_y - f_a) + compliance * f_a;
      const Run r = incline(law, theta_c, beta, 1.5, 2.5);
      const double drift = std::fabs(r.x_end - r.x_settle);
      std::printf("[%s theta_c=%2.0f beta=%2.0f] dt=%.3g s: settling displacement %.3e d (undamped estimate %.3e d), "
                  "drift over the next 1 s %.3e d, final |omega| %.3e rad/s, v %.2e m/s\n",
                  name, theta_c, beta, r.dt, r.x_settle / kD, settle_estimate / kD, drift / kD, r.w_end, r.v_end);
      EXPECT_LT(drift, 1e-3 * kD) << name << " theta_c " << theta_c << ": should stay at rest at beta " << beta;
      EXPECT_LT(r.w_end, 1e-3) << name << " theta_c " << theta_c << ": omega should decay to 0";
      EXPECT_LT(std::fabs(r.x_end), 1.1 * settle_estimate)
          << name << " theta_c " << theta_c << ": settling should be bounded";
    }
    // above: rolls away
    {
      const double beta = theta_c + 1.0, b = beta * kDeg;
      const double fn = m * kG * std::cos(b);
      const double c = kR - static_overlap(law, fn);
      const double a_expected = c * (m * kG * std::sin(b) * c - kR * tan_c * fn) / (inertia + m * c * c);
      const double a_textbook = 5.0 / 7.0 * kG * (std::sin(b) - tan_c * std::cos(b));
      const Run r = incline(law, theta_c, beta, 0.0, 1.0);
      const double a_measured = (r.v_end - r.v_mid) / (r.t_end - r.t_mid);
      std::printf("[%s theta_c=%2.0f beta=%2.0f] dt=%.3g s: displacement in 1 s %.2f d; acceleration %.5f m/s^2 "
                  "vs %.5f with lever R - delta_s (%+.2f %%), (5/7) g (sin b - tan tc cos b) = %.5f (%+.2f %%)\n",
                  name, theta_c, beta, r.dt, r.x_end / kD, a_measured, a_expected,
                  100.0 * (a_measured / a_expected - 1.0), a_textbook, 100.0 * (a_measured / a_textbook - 1.0));
      EXPECT_GT(r.x_end, 5.0 * kD) << name << " theta_c " << theta_c << ": should roll away at beta " << beta;
      EXPECT_GT(r.v_end, r.v_mid) << "velocity along the slope should grow";
      EXPECT_NEAR(a_measured, a_expected, 0.01 * a_expected) << name << " theta_c " << theta_c;
    }
  }
}

}  // namespace

TEST(RollingIncline, HertzMindlinHoldsBelowAndRollsAboveCriticalAngle) {
  check_critical_angle(Law::hertz, "hertz");
}

TEST(RollingIncline, LinearHoldsBelowAndRollsAboveCriticalAngle) {
  check_critical_angle(Law::linear, "linear");
}
