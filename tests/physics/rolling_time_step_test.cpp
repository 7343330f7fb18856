// Guards the time-step check's rolling part, issue acceptance 5 and
// docs/physics.md §3.6: the explicit stability limit of a subdomain includes
// the rolling spring of its contacts (ABI 1.1 rolling_stiffness /
// rolling_damping), 2 (sqrt(1 + z^2) - z) / omega with omega = sqrt(k_theta /
// I_red), z = n_theta / (2 sqrt(I_red k_theta)); a given time step above it
// is refused (ConfigError at /subdomains/k/time_step naming the limit and
// "rolling spring"), and "auto" stays below it.
//
// Stiffness ratio (§3.5, §3.6), linear law, equal spheres of mass m, radius R:
//  - wall:  R* = R, I_red = I = 2/5 m R^2, m* = m:
//           omega_theta/omega_n = sqrt(5/8) tan(theta_c) = 0.79 tan(theta_c)
//  - pair:  R* = R/2, I_red = I/2 (torque couple +-M on two spheres), m* = m/2:
//           k_theta = k_n R^2 tan^2/16, omega_theta^2 = (5/16) tan^2 k_n/m,
//           omega_n^2 = 2 k_n/m, so omega_theta/omega_n = sqrt(5/32) tan(theta_c)
//           = 0.40 tan(theta_c): relative to its own normal mode the pair's
//           rolling mode is SOFTER than the wall's (the halved R* enters squared,
//           the halved inertia only once). It binds for tan(theta_c) > 2.53
//           (theta_c > 68.4 deg; the wall's for theta_c > 51.7 deg).
//  Damping ratios: z_n = |ln e|/sqrt(pi^2 + ln^2 e); z_theta = 0.40 tan(theta_c) z_n
//  (pair), 0.79 tan(theta_c) z_n (wall).
// theta_c = 80 deg (tan = 5.67) makes the rolling spring binding in both
// cases. The scenario is built in memory with particles from the lattice
// inserter, so the estimate runs on real particles.
// Tolerances: for the linear law k_n, k_theta and both damping ratios are
// constant along the estimator's simulated collision, so its limit must equal
// the closed form to round-off (relative 1e-9). For Hertz (e = 1, no damping)
// the estimator takes the stiffest point of a collision at the impact
// velocity, delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^{2/5} (Johnson §11.4),
// sampled at the estimator's integration steps: 1 % covers the sampling
// (k ~ delta^{1/2}, limit ~ delta^{-1/4}).
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

namespace dt = domel::test;
using domel::platform::ConfigError;

namespace {

constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kE = 5e6, kNu = 0.3;
constexpr double kK = 500.0;  // linear normal stiffness [N/m]
constexpr double kDeg = M_PI / 180.0;
const double kMass = kRho * 4.0 / 3.0 * M_PI * kR * kR * kR;
const double kInertia = 0.4 * kMass * kR * kR;

double stability(double omega, double zeta) { return 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta) / omega; }

double zeta_of(double e) {
  const double le = std::log(e);
  return -le / std::sqrt(M_PI * M_PI + le * le);
}

struct Limits {
  double normal, rolling;
};

/// Closed-form limits for the linear law (restitution damping: eta_n = 2 z_n sqrt(m* k_n)).
Limits linear_limits(double theta_c, double e, bool wall) {
  const double r_eff = wall ? kR : 0.5 * kR, m_eff = wall ? kMass : 0.5 * kMass;
  const double i_red = wall ? kInertia : 0.5 * kInertia;
  const double z = zeta_of(e), eta_n = 2.0 * z * std::sqrt(m_eff * kK);
  const double a = r_eff * std::tan(theta_c * kDeg);
  const double k_th = 0.25 * kK * a * a, n_th = 0.25 * eta_n * a * a;
  return {stability(std::sqrt(kK / m_eff), z),
          stability(std::sqrt(k_th / i_red), n_th / (2.0 * std::sqrt(i_red * k_th)))};
}

/// 3 x 3 x 3 spheres on a lattice (spacing 1.02 d: none touching), linear or Hertz law.
nlohmann::json scenario(const nlohmann::json& contact, double theta_c, double e, const nlohmann::json& time_step,
                        bool wall) {
  nlohmann::json c = contact;
  c["rolling"] = {{"model", "sd_critical_angle"}, {"critical_angle", theta_c}};
  auto doc = dt::scenario(c, 1e-6, e, 0.5, kE, kNu, kRho);
  doc["subdomains"][0]["time_step"] = time_step;
  const double a = 1.02 * kD;
  doc["subdomains"][0]["insert"] = nlohmann::json::array(
      {{{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.02},
        {"region", {{"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {3 * a, 3 * a, 3 * a}}}}}}}});
  if (wall) dt::add_plane(doc, "floor", {0, 0, -0.01}, {0, 0, 1});
  return doc;
}

std::string fmt4(double v) {  // as the diagnostic prints numbers
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

/// Load with time_step "auto" and return the time-step report of subdomain 0.
domel::platform::TimeStepReport auto_report(const nlohmann::json& contact, double theta_c, double e, bool wall) {
  auto sim = dt::build(scenario(contact, theta_c, e, "auto", wall));
  EXPECT_EQ(sim->subdomains[0]->store().size(), 27u) << "lattice insertion";
  return sim->time_steps.at(0);
}

}  // namespace

TEST(RollingTimeStep, LinearLimitIsTheRollingSpringsClosedForm) {
  const double theta_c = 80.0, e = 0.5;
  for (bool wall : {false, true}) {
    const Limits pair = linear_limits(theta_c, e, false), on_wall = linear_limits(theta_c, e, true);
    const double expected = wall ? std::min(pair.rolling, on_wall.rolling) : pair.rolling;
    const double translational = wall ? std::min(pair.normal, on_wall.normal) : pair.normal;
    const auto rep = auto_report(dt::linear_spring(kK), theta_c, e, wall);
    std::printf("[linear theta_c=80 e=0.5 %s] limit %.6e s (closed form %.6e, rel %.1e) set by '%s'; "
                "translational limit %.6e s; pair rolling %.6e, wall rolling %.6e; auto dt %.4e (%s)\n",
                wall ? "with wall" : "no wall  ", rep.critical, expected, rep.critical / expected - 1,
                rep.critical_of.c_str(), translational, pair.rolling, on_wall.rolling, rep.chosen, rep.reason.c_str());
    EXPECT_LT(expected, translational) << "set-up: the rolling spring must bind";
    EXPECT_NEAR(rep.critical, expected, 1e-9 * expected);
    EXPECT_NE(rep.critical_of.find("rolling spring"), std::string::npos) << rep.critical_of;
    EXPECT_NE(rep.critical_of.find(wall ? "wall 'floor'" : "particle-particle"), std::string::npos)
        << rep.critical_of;
    EXPECT_LT(rep.chosen, expected) << "auto must stay below the rolling limit";
  }
}

TEST(RollingTimeStep, GivenStepAboveRollingLimitIsRefused) {
  const double theta_c = 80.0, e = 0.5;
  for (bool wall : {false, true}) {
    const Limits pair = linear_limits(theta_c, e, false), on_wall = linear_limits(theta_c, e, true);
    const double rolling = wall ? std::min(pair.rolling, on_wall.rolling) : pair.rolling;
    const double translational = wall ? std::min(pair.normal, on_wall.normal) : pair.normal;
    const double given = std::sqrt(rolling * translational);  // between the two limits
    const double critical = auto_report(dt::linear_spring(kK), theta_c, e, wall).critical;
    bool refused = false;
    try {
      dt::build(scenario(dt::linear_spring(kK), theta_c, e, given, wall));
    } catch (const ConfigError& err) {
      refused = true;
      ASSERT_EQ(err.diagnostics().size(), 1u) << err.what();
      const auto& d = err.diagnostics()[0];
      std::printf("[refused, %s] given %.4e s: %s: %s (hint: %s)\n", wall ? "with wall" : "no wall", given,
                  d.pointer.c_str(), d.message.c_str(), d.hint.c_str());
      EXPECT_EQ(d.pointer, "/subdomains/0/time_step");
      EXPECT_NE(d.message.find("rolling spring"), std::string::npos) << d.message;
      EXPECT_NE(d.message.find(fmt4(critical)), std::string::npos) << d.message << " should name " << fmt4(critical);
    }
    EXPECT_TRUE(refused) << "a step of " << given << " s exceeds the rolling limit " << rolling << " s";
    // the same step without the rolling model is accepted: the refusal is the rolling spring's
    auto doc = scenario(dt::linear_spring(kK), theta_c, e, given, wall);
    doc["subdomains"][0]["contact"].erase("rolling");
    EXPECT_NO_THROW(dt::build(doc));
    // and just below the rolling limit it is accepted with the rolling model
    EXPECT_NO_THROW(dt::build(scenario(dt::linear_spring(kK), theta_c, e, 0.99 * rolling, wall)));
  }
}

TEST(RollingTimeStep, ModerateAngleLeavesTheNormalContactBinding) {
  // theta_c = 30 deg: omega_theta/omega_n = 0.40 * 0.577 (pair), 0.79 * 0.577 (wall) < 1
  for (bool wall : {false, true}) {
    const auto rep = auto_report(dt::linear_spring(kK), 30.0, 0.5, wall);
    const Limits pair = linear_limits(30.0, 0.5, false), on_wall = linear_limits(30.0, 0.5, true);
    const double translational = wall ? std::min(pair.normal, on_wall.normal) : pair.normal;
    std::printf("[linear theta_c=30 %s] limit %.6e s set by '%s' (translational %.6e)\n",
                wall ? "with wall" : "no wall  ", rep.critical, rep.critical_of.c_str(), translational);
    EXPECT_EQ(rep.critical_of.find("rolling"), std::string::npos) << rep.critical_of;
    EXPECT_NEAR(rep.critical, translational, 1e-9 * translational);
  }
}

TEST(RollingTimeStep, AutoHalvesTheRollingLimitWhenItIsTheSmallest) {
  // theta_c = 89 deg: the rolling limit (heavily damped, ~2 I_red/n_theta) is
  // far below contact time/50, so "auto" takes half of it.
  const double theta_c = 89.0, e = 0.5;
  const auto rep = auto_report(dt::linear_spring(kK), theta_c, e, false);
  const double expected = linear_limits(theta_c, e, false).rolling;
  std::printf("[linear theta_c=89] limit %.6e s (closed form %.6e), contact time/50 %.4e, auto dt %.4e (%s)\n",
              rep.critical, expected, rep.contact_time / 50, rep.chosen, rep.reason.c_str());
  EXPECT_NEAR(rep.critical, expected, 1e-9 * expected);
  EXPECT_NEAR(rep.chosen, 0.5 * expected, 1e-9 * expected);
  EXPECT_NE(rep.reason.find("rolling spring"), std::string::npos) << rep.reason;
}

TEST(RollingTimeStep, HertzLimitAtTheImpactsMaximumOverlap) {
  // e = 1: no dashpots, limit 2/omega at the stiffest point of the collision.
  // Both the normal and the rolling stiffness use the tangent S_n there, so
  // the ratios above hold and the rolling spring binds at 80 deg.
  const double theta_c = 80.0, v = 1.0;  // impact_velocity default 1 m/s
  const double e_star = 1.0 / (2.0 * (1.0 - kNu * kNu) / kE);
  auto limit = [&](bool wall) {
    const double r_eff = wall ? kR : 0.5 * kR, m_eff = wall ? kMass : 0.5 * kMass;
    const double i_red = wall ? kInertia : 0.5 * kInertia;
    const double dmax = std::pow(15.0 * m_eff * v * v / (16.0 * e_star * std::sqrt(r_eff)), 0.4);
    const double s_n = 2.0 * e_star * std::sqrt(r_eff * dmax);
    const double a = r_eff * std::tan(theta_c * kDeg);
    return Limits{2.0 / std::sqrt(s_n / m_eff), 2.0 / std::sqrt(0.25 * s_n * a * a / i_red)};
  };
  for (bool wall : {false, true}) {
    const Limits p = limit(false), w = limit(true);
    const double expected = wall ? std::min(p.rolling, w.rolling) : p.rolling;
    const auto rep = auto_report(dt::hertz_mindlin(), theta_c, 1.0, wall);
    std::printf("[hertz theta_c=80 e=1 %s] limit %.6e s vs %.6e at delta_max (%+.3f %%) set by '%s'; "
                "translational %.6e\n",
                wall ? "with wall" : "no wall  ", rep.critical, expected, 100 * (rep.critical / expected - 1),
                rep.critical_of.c_str(), wall ? std::min(p.normal, w.normal) : p.normal);
    EXPECT_NEAR(rep.critical, expected, 0.01 * expected);
    EXPECT_NE(rep.critical_of.find("rolling spring"), std::string::npos) << rep.critical_of;
    // a step between the limits is refused for Hertz too
    const double given = std::sqrt(rep.critical * (wall ? std::min(p.normal, w.normal) : p.normal));
    EXPECT_THROW(dt::build(scenario(dt::hertz_mindlin(), theta_c, 1.0, given, wall)), ConfigError);
  }
}

TEST(TimeStepEstimate, AContactTooSoftToStopTheImpactEndsWhereTheSpheresPassThrough) {
  // Found by run-time fuzzing (docs/reliability.md): a linear stiffness of
  // 1e-6 N/m cannot stop an impact at 1 m/s; the estimate integrated every
  // contact for its step cap (2e6 steps) without the approach ending. It now
  // ends where the centres meet (a wall: where the centre reaches it) and
  // names the contacts. Expected contact time: the spheres keep their speed
  // (k = 1e-6 N/m, m* = m/2 = 1.4e-5 kg: omega = 0.27 rad/s, so over the 2.8 ms
  // to pass the speed changes by (omega t)^2/2 ~ 3e-7; e = 1, no dashpot):
  // t = (R + R)/v for the pair, R/v for the wall. Tolerance 1e-3: one step of
  // the estimator's coarsest integration is 1e-3 R*/v.
  const double v = 1.0;  // impact_velocity default
  for (bool wall : {false, true}) {
    const auto rep = auto_report(dt::linear_spring(1e-6), 10.0, 1.0, wall);
    const double expected = wall ? kR / v : kD / v;
    std::printf("[k = 1e-6 N/m %s] contact time %.6e s (pass-through %.6e), passes through: '%s'; auto dt %.4e (%s)\n",
                wall ? "with wall" : "no wall  ", rep.contact_time, expected, rep.passes_through.c_str(), rep.chosen,
                rep.reason.c_str());
    EXPECT_NEAR(rep.contact_time, expected, 1e-3 * expected);
    EXPECT_EQ(rep.passes_through,
              wall ? "particle-particle contact, contact with wall 'floor'" : "particle-particle contact");
  }
  // a contact that stops the impact is not reported
  EXPECT_EQ(auto_report(dt::linear_spring(kK), 10.0, 0.5, true).passes_through, "");
}
