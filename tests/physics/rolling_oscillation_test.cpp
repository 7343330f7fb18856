// Guards the stiffness (and damping) of the sd_critical_angle rolling spring
// through the full stack, issue acceptance 6(c) and docs/physics.md §9
// target 4: a free rolling-mode oscillation has the angular frequency
// omega_theta = sqrt(k_theta / I) with k_theta = k_n a^2/4, a = R* tan(theta_c)
// (§3.3), and for the linear law on a wall, I about the centre,
// omega_theta = sqrt(5/8) tan(theta_c) omega_n, omega_n = sqrt(k_n/m) (§3.5).
//
// Set-up, chosen so that the rolling spring is the ONLY restoring torque: a
// sphere rests on the plane z = 0 at its static overlap under gravity normal
// to the plane (nothing along it), with interaction friction mu = 0. The
// tangential slot then caps the tangential force at mu |F_n| = 0, so the
// tangential spring cannot couple rolling to sliding: the contact couple
// M = -k_theta theta_r acts alone, the centre does not move, and the sphere
// rotates about its centre (I = 2/5 m R^2, R* = R for a wall). It is started
// with a small angular velocity omega_0 about an in-plane axis (y), chosen so
// that the peak spring torque k_theta omega_0/omega_theta is 30 % of the cap
// R tan(theta_c) m g (no yielding). The period is measured from the zero
// crossings of omega_y(t) (linear interpolation) over ~10 periods.
// With e = 1 the restitution dashpot eta_n is 0, hence n_theta = eta_n a^2/4 = 0
// and the oscillation is undamped.
//
// Tolerances: 2 % (issue 6(c); §9 target 4 suggests < 1 %, which is what the
// measured errors show). Time step: T_theta/200 (and at most contact time/50):
// velocity Verlet's (symplectic leapfrog's) phase error is
// (omega dt)^2/24 = (2 pi/200)^2/24 = 4e-5 relative, and the interpolated
// zero crossings are accurate to O((omega dt)^2) too, so the discretisation is
// far below the tolerance (>= 100 steps per period, as the issue asks).
// The damped variant (e = 0.5, zeta_theta = sqrt(5/8) tan(theta_c) zeta_n,
// §3.5) checks n_theta via the logarithmic decrement of successive same-sign
// peaks of omega_y, within 3 %: the dashpot sees the half-step angular velocity,
// a lag of dt/2 that changes the decrement by ~zeta omega dt ~ 0.3 %; the peaks
// are sampled, an error ~(omega dt)^2/8 ~ 1e-4.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace dt = domel::test;
using domel::platform::Subdomain;

namespace {

constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kE = 5e6, kNu = 0.3, kG = 9.81;
constexpr double kK = 500.0;  // linear normal stiffness [N/m]
constexpr double kDeg = M_PI / 180.0;
const double kMass = kRho * 4.0 / 3.0 * M_PI * kR * kR * kR;
const double kInertia = 0.4 * kMass * kR * kR;
const double kEStar = 1.0 / (2.0 * (1.0 - kNu * kNu) / kE);  // sphere on a wall of the same material

enum class Law { linear, hertz_tangent, hertz_secant };

struct Oscillation {
  double omega_measured = 0;  ///< 2 pi / period [rad/s]
  double zeta_measured = 0;   ///< from the logarithmic decrement (0 if too few peaks)
  double dt = 0;
  double steps_per_period = 0;
  double max_centre_motion = 0;  ///< max |x - x0| in the plane [m]
};

/// k_n that sets k_theta for the resting contact (tangent dF/d delta unless secant).
double normal_stiffness(Law law) {
  if (law == Law::linear) return kK;
  const double delta = std::pow(kMass * kG / (4.0 / 3.0 * kEStar * std::sqrt(kR)), 2.0 / 3.0);
  const double tangent = 2.0 * kEStar * std::sqrt(kR * delta);
  return law == Law::hertz_tangent ? tangent : tangent * 2.0 / 3.0;
}

double static_overlap(Law law) {
  if (law == Law::linear) return kMass * kG / kK;
  return std::pow(kMass * kG / (4.0 / 3.0 * kEStar * std::sqrt(kR)), 2.0 / 3.0);
}

Oscillation oscillate(Law law, double theta_c, double restitution, double periods) {
  nlohmann::json contact = law == Law::linear ? dt::linear_spring(kK) : dt::hertz_mindlin();
  contact["rolling"] = {{"model", "sd_critical_angle"}, {"critical_angle", theta_c}};
  if (law == Law::hertz_secant) contact["rolling"]["normal_stiffness"] = "secant";
  auto doc = dt::scenario(contact, 1e-6, restitution, 0.0, kE, kNu, kRho);
  doc["gravity"] = {0.0, 0.0, -kG};
  dt::add_plane(doc, "wall", {0, 0, 0}, {0, 0, 1});
  auto sim = dt::build(doc);
  Subdomain& sd = *sim->subdomains[0];
  auto& s = sd.store();
  s.add(1, 0, 0, kR - static_overlap(law), kR, kRho);
  const double a = kR * std::tan(theta_c * kDeg);
  const double k_theta = 0.25 * normal_stiffness(law) * a * a;
  const double omega_theta = std::sqrt(k_theta / kInertia);
  const double period = 2 * M_PI / omega_theta;
  const double m_ref = a * kMass * kG;
  const double omega0 = 0.3 * m_ref / k_theta * omega_theta;  // peak torque 30 % of the cap
  s.wy[0] = omega0;
  const auto rep = sd.estimate_time_step(0.1);
  sd.set_time_step(std::min(period / 200.0, rep.contact_time / 50.0));
  sd.set_skin(0.2 * kD);
  sd.setup();
  Oscillation o;
  o.dt = sd.time_step();
  o.steps_per_period = period / o.dt;
  std::vector<double> crossings;  // times where omega_y changes sign
  std::vector<double> peaks;      // |omega_y| at extrema of one sign (maxima)
  double prev = s.wy[0], prev2 = prev;
  const double x0 = s.x[0], y0 = s.y[0];
  while (sd.time() < periods * period) {
    const double t0 = sd.time();
    sd.step();
    const double w = s.wy[0];
    if ((prev > 0) != (w > 0)) crossings.push_back(t0 + o.dt * prev / (prev - w));
    if (prev > prev2 && prev >= w && prev > 0) peaks.push_back(prev);
    prev2 = prev;
    prev = w;
    o.max_centre_motion = std::max(o.max_centre_motion, std::hypot(s.x[0] - x0, s.y[0] - y0));
  }
  if (crossings.size() >= 3) {
    const double half = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    o.omega_measured = M_PI / half;
  }
  if (peaks.size() >= 3) {
    const double decrement = std::log(peaks.front() / peaks.back()) / static_cast<double>(peaks.size() - 1);
    o.zeta_measured = decrement / std::sqrt(4 * M_PI * M_PI + decrement * decrement);
  }
  return o;
}

}  // namespace

TEST(RollingOscillation, LinearLawFrequencyIsSqrtKThetaOverI) {
  for (double theta_c : {10.0, 20.0, 30.0, 45.0, 60.0}) {
    const Oscillation o = oscillate(Law::linear, theta_c, 1.0, 10.0);
    const double a = kR * std::tan(theta_c * kDeg);
    const double expected = std::sqrt(0.25 * kK * a * a / kInertia);
    const double closed_form = std::sqrt(5.0 / 8.0) * std::tan(theta_c * kDeg) * std::sqrt(kK / kMass);
    std::printf("[linear theta_c=%2.0f] %.0f steps/period: omega measured %.3f rad/s, sqrt(k_theta/I) %.3f "
                "(%+.4f %%), sqrt(5/8) tan(theta_c) omega_n %.3f; centre moved %.1e d\n",
                theta_c, o.steps_per_period, o.omega_measured, expected, 100 * (o.omega_measured / expected - 1),
                closed_form, o.max_centre_motion / kD);
    EXPECT_NEAR(o.omega_measured, expected, 0.02 * expected) << "theta_c " << theta_c;
    EXPECT_NEAR(o.omega_measured, closed_form, 0.02 * closed_form) << "theta_c " << theta_c;
    EXPECT_GE(o.steps_per_period, 100.0);
    EXPECT_LT(o.max_centre_motion, 1e-6 * kD) << "the couple alone must not move the centre";
  }
}

TEST(RollingOscillation, HertzUsesTangentStiffnessOrSecantOnRequest) {
  // k_n of the resting Hertz contact: tangent S_n = 2 E* sqrt(R delta_s) by
  // default, secant (4/3) E* sqrt(R delta_s) = 2/3 S_n with "secant" (§1.1, §3.3).
  for (Law law : {Law::hertz_tangent, Law::hertz_secant})
    for (double theta_c : {15.0, 30.0}) {
      const Oscillation o = oscillate(law, theta_c, 1.0, 10.0);
      const double a = kR * std::tan(theta_c * kDeg);
      const double expected = std::sqrt(0.25 * normal_stiffness(law) * a * a / kInertia);
      std::printf("[hertz %s theta_c=%2.0f] %.0f steps/period: omega measured %.3f rad/s, expected %.3f (%+.4f %%)\n",
                  law == Law::hertz_tangent ? "tangent" : "secant ", theta_c, o.steps_per_period, o.omega_measured,
                  expected, 100 * (o.omega_measured / expected - 1));
      EXPECT_NEAR(o.omega_measured, expected, 0.02 * expected) << "theta_c " << theta_c;
    }
}

TEST(RollingOscillation, DashpotGivesZetaThetaFromZetaN) {
  const double e = 0.5;
  const double le = std::log(e);
  const double zeta_n = -le / std::sqrt(M_PI * M_PI + le * le);
  for (double theta_c : {20.0, 30.0}) {
    const double zeta = std::sqrt(5.0 / 8.0) * std::tan(theta_c * kDeg) * zeta_n;
    const Oscillation o = oscillate(Law::linear, theta_c, e, 6.0);
    const double a = kR * std::tan(theta_c * kDeg);
    const double omega_d = std::sqrt(0.25 * kK * a * a / kInertia) * std::sqrt(1 - zeta * zeta);
    std::printf("[linear e=0.5 theta_c=%2.0f] zeta_theta measured %.5f vs sqrt(5/8) tan(theta_c) zeta_n %.5f "
                "(%+.2f %%); damped omega %.3f vs %.3f (%+.4f %%)\n",
                theta_c, o.zeta_measured, zeta, 100 * (o.zeta_measured / zeta - 1), o.omega_measured, omega_d,
                100 * (o.omega_measured / omega_d - 1));
    EXPECT_NEAR(o.zeta_measured, zeta, 0.03 * zeta) << "theta_c " << theta_c;
    EXPECT_NEAR(o.omega_measured, omega_d, 0.02 * omega_d) << "theta_c " << theta_c;
  }
}
