// Guards the rolling-resistance kernels themselves, called directly on a
// hand-built domel_contact_batch_v2 (no platform in between), issue
// acceptance 6(b):
//  - sd_critical_angle (docs/physics.md §3.2–§3.4): driven at a constant
//    rolling angular velocity, the torque follows the spring–dashpot law
//    M = -k_theta theta_r - n_theta omega_r with k_theta = k_n a^2/4,
//    n_theta = eta_n a^2/4, a = R* tan(theta_c) (k_n the TANGENT normal
//    stiffness by default, the secant one with "normal_stiffness": "secant"),
//    and once the spring is fully mobilised |M| = R* tan(theta_c) |F_n,el|
//    (§9 target 3, "machine precision"); the dashpot is off at yield unless
//    "damping_at_yield"; the stored angle is carried onto a new tangent
//    plane with its length kept; the ABI 1.1 outputs rolling_stiffness and
//    rolling_damping equal k_theta and n_theta; the torque is ADDED to
//    tq* (abi.h); the twisting part of omega (along n) is ignored (§2).
//  - dct (§2.1, §3.8): |M| = mu_r R* F_n,el exactly, opposite omega_r, zero
//    for omega_r = 0, twisting part ignored, mu_r = tan(theta_c) from
//    "critical_angle".
//  - the out-of-tree example `epsd` (examples/third_party_rolling/epsd.cpp,
//    compiled into this test from its source; §2.2-2.3): k_r = 2.25 k_n
//    mu_r^2 R*^2 ("stiffness": "ai", LIGGGHTS epsd) or k_t R*^2 with
//    k_t = 8 G* sqrt(R* delta) ("iwashita_oda", LIGGGHTS epsd2), the dashpot
//    C_r = eta_r 2 sqrt(I_r k_r) below the cap or none ("dashpot": false),
//    |M| = mu_r R* F_n once capped.
// Tolerances: the cap is a single rescale m *= M_ref/|m|, so it holds to a
// few ulps: relative 1e-12 (§9 row 3). The elastic law accumulates theta_r as
// a sum of omega_r dt over up to a few thousand steps; its round-off is
// ~ steps * 1e-16, so relative 1e-11 is used there.
#include "plugins/rolling/dct.hpp"
#include "plugins/rolling/sd_critical_angle.hpp"
// The example is one source file with its class in an anonymous namespace;
// including it here tests the very code the example library is built from.
#include "examples/third_party_rolling/epsd.cpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using domel::plugins::rolling::Dct;
using domel::plugins::rolling::SdCriticalAngle;
using domel::sdk::ParameterError;
using domel::sdk::Params;
using nlohmann::json;

constexpr double kDeg = M_PI / 180.0;

using V3 = std::array<double, 3>;

double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const V3& a) { return std::sqrt(dot(a, a)); }
V3 unit(const V3& a) {
  const double l = norm(a);
  return {a[0] / l, a[1] / l, a[2] / l};
}
/// Component of a perpendicular to the unit vector n.
V3 in_plane(const V3& a, const V3& n) {
  const double p = dot(a, n);
  return {a[0] - p * n[0], a[1] - p * n[1], a[2] - p * n[2]};
}

/// A hand-built batch of n contacts: owns every array the ABI names.
struct Batch {
  explicit Batch(uint32_t n, uint32_t stride = 3)
      : overlap(n, 1e-6), nx(n), ny(n), nz(n), r_eff(n), m_eff(n, 1e-5), radius_i(n), radius_j(n), mass_i(n, 2e-5),
        mass_j(n, 2e-5), vn(n),
        vtx(n), vty(n), vtz(n), wx(n), wy(n), wz(n), fn_elastic(n), kn(n), kn_tangent(n), contact_radius(n),
        fn_damping(n), eta_n(n), fn(n), ftx(n), fty(n), ftz(n), tqx(n), tqy(n), tqz(n), history(n * stride),
        rolling_stiffness(n), rolling_damping(n) {
    pair.struct_size = sizeof pair;
    pair.is_wall = 0;
    pair.restitution = 0.5;
    pair.friction = 0.5;
    pair.coarse_grain = 1.0;
    b.struct_size = sizeof b;
    b.n = n;
    b.dt = 1e-6;
    b.pair = &pair;
    b.overlap = overlap.data();
    b.nx = nx.data(); b.ny = ny.data(); b.nz = nz.data();
    b.r_eff = r_eff.data(); b.m_eff = m_eff.data();
    b.radius_i = radius_i.data(); b.radius_j = radius_j.data();
    b.mass_i = mass_i.data(); b.mass_j = mass_j.data();
    b.vn = vn.data();
    b.vtx = vtx.data(); b.vty = vty.data(); b.vtz = vtz.data();
    b.wx = wx.data(); b.wy = wy.data(); b.wz = wz.data();
    b.fn_elastic = fn_elastic.data(); b.kn = kn.data(); b.kn_tangent = kn_tangent.data();
    b.contact_radius = contact_radius.data();
    b.fn_damping = fn_damping.data(); b.eta_n = eta_n.data(); b.fn = fn.data();
    b.ftx = ftx.data(); b.fty = fty.data(); b.ftz = ftz.data();
    b.tqx = tqx.data(); b.tqy = tqy.data(); b.tqz = tqz.data();
    b.history = history.data();
    b.history_stride = stride;
    b.rolling_stiffness = rolling_stiffness.data();
    b.rolling_damping = rolling_damping.data();
  }
  Batch(const Batch&) = delete;
  Batch& operator=(const Batch&) = delete;

  void set_normal(uint32_t c, const V3& n) { nx[c] = n[0]; ny[c] = n[1]; nz[c] = n[2]; }
  void set_omega(uint32_t c, const V3& w) { wx[c] = w[0]; wy[c] = w[1]; wz[c] = w[2]; }
  V3 torque(uint32_t c) const { return {tqx[c], tqy[c], tqz[c]}; }
  V3 theta(uint32_t c) const {
    const double* h = history.data() + c * b.history_stride;
    return {h[0], h[1], h[2]};
  }
  /// The host zeroes the torque accumulators and the rolling constants before the rolling stage.
  void clear_outputs() {
    std::fill(tqx.begin(), tqx.end(), 0.0); std::fill(tqy.begin(), tqy.end(), 0.0);
    std::fill(tqz.begin(), tqz.end(), 0.0);
    std::fill(rolling_stiffness.begin(), rolling_stiffness.end(), 0.0);
    std::fill(rolling_damping.begin(), rolling_damping.end(), 0.0);
  }

  domel_pair_v2 pair{};
  std::vector<double> overlap, nx, ny, nz, r_eff, m_eff, radius_i, radius_j, mass_i, mass_j, vn, vtx, vty, vtz, wx,
      wy, wz;
  std::vector<double> fn_elastic, kn, kn_tangent, contact_radius, fn_damping, eta_n, fn;
  std::vector<double> ftx, fty, ftz, tqx, tqy, tqz, history, rolling_stiffness, rolling_damping;
  domel_contact_batch_v2 b{};
};

/// One contact of the parameter sweep.
struct Case {
  double theta_c_deg, r_eff, fn_el, kn_secant, kn_tangent, eta_n;
  V3 n, omega;  // omega includes a twisting part along n on purpose
};

std::vector<Case> sweep(double theta_c_deg) {
  // R* from fine powder to a 5 cm parcel, F_n over 6 decades, Hertz-like
  // (tangent = 1.5 secant) and linear (tangent = secant) stiffness, normals
  // in arbitrary directions, omega with a twisting component.
  return {
      {theta_c_deg, 7e-4, 2.8e-4, 300.0, 450.0, 2e-3, unit({0, 0, 1}), {3.0, -1.0, 5.0}},
      {theta_c_deg, 1.4e-3, 1.0, 5e4, 5e4, 0.4, unit({1, 2, -2}), {-0.5, 2.0, 0.7}},
      {theta_c_deg, 2.5e-2, 300.0, 2e6, 3e6, 50.0, unit({-0.3, 0.1, 0.9}), {0.02, 0.05, -0.01}},
      {theta_c_deg, 5e-5, 1e-6, 10.0, 15.0, 1e-5, unit({0.6, -0.8, 0.0}), {40.0, 30.0, 12.0}},
  };
}

void load(Batch& bt, uint32_t c, const Case& k, double dt) {
  bt.b.dt = dt;
  bt.set_normal(c, k.n);
  bt.set_omega(c, k.omega);
  bt.r_eff[c] = k.r_eff;
  bt.radius_i[c] = k.r_eff;
  bt.fn_elastic[c] = k.fn_el;
  bt.kn[c] = k.kn_secant;
  bt.kn_tangent[c] = k.kn_tangent;
  bt.eta_n[c] = k.eta_n;
}

}  // namespace

// Elastic branch and saturation under a constant rolling angular velocity,
// for several theta_c, R*, F_n, both stiffness choices, dashpot off at yield.
TEST(RollingKernel, SpringDashpotLawThenCapAtRStarTanThetaCFn) {
  for (const char* stiffness : {"tangent", "secant"})
    for (double theta_c : {5.0, 10.0, 20.0, 30.0, 45.0, 70.0}) {
      const json params = {{"critical_angle", theta_c}, {"normal_stiffness", stiffness}};
      const SdCriticalAngle model{Params(params)};
      const auto cases = sweep(theta_c);
      const uint32_t nc = static_cast<uint32_t>(cases.size());
      Batch bt(nc);
      // dt is common to the batch; each contact's omega is scaled so that
      // it yields near step 1500 (yield at theta = M_ref/k_theta, i.e. after
      // 4 F_n,el / (k_n a |omega_r| dt) steps), the twisting part scaled alike.
      const double dt = 1e-5;
      std::vector<Case> scaled = cases;
      for (auto& k : scaled) {
        const double a = k.r_eff * std::tan(theta_c * kDeg);
        const double kn = std::string(stiffness) == "tangent" ? k.kn_tangent : k.kn_secant;
        const double steps = 4.0 * k.fn_el / (kn * a * norm(in_plane(k.omega, k.n)) * dt);
        for (auto& w : k.omega) w *= steps / 1500.0;
      }
      for (uint32_t c = 0; c < nc; ++c) load(bt, c, scaled[c], dt);
      std::vector<int> yielded_at(nc, -1);
      std::vector<double> worst_elastic(nc, 0.0), worst_cap(nc, 0.0);
      for (int step = 1; step <= 4000; ++step) {
        bt.clear_outputs();
        model.compute(bt.b);
        for (uint32_t c = 0; c < nc; ++c) {
          const Case& k = scaled[c];
          const double a = k.r_eff * std::tan(theta_c * kDeg);
          const double kn = std::string(stiffness) == "tangent" ? k.kn_tangent : k.kn_secant;
          const double k_th = 0.25 * kn * a * a, n_th = 0.25 * k.eta_n * a * a;
          const double m_ref = a * k.fn_el;
          ASSERT_NEAR(bt.rolling_stiffness[c], k_th, 1e-14 * k_th);
          ASSERT_NEAR(bt.rolling_damping[c], n_th, 1e-14 * n_th);
          const V3 wr = in_plane(k.omega, k.n);
          const V3 tq = bt.torque(c);
          ASSERT_NEAR(dot(tq, k.n), 0.0, 1e-12 * norm(tq)) << "the couple must lie in the tangent plane";
          // elastic prediction: theta = step * omega_r dt
          const double th = step * dt;  // times wr
          const V3 m_el = {-(k_th * th + n_th) * wr[0], -(k_th * th + n_th) * wr[1], -(k_th * th + n_th) * wr[2]};
          const double spring = k_th * th * norm(wr);
          if (spring <= m_ref * (1 - 1e-9)) {
            ASSERT_LT(yielded_at[c], 0) << "elastic again after yielding";
            for (int q = 0; q < 3; ++q)
              ASSERT_NEAR(tq[q], m_el[q], 1e-11 * norm(m_el)) << "theta_c " << theta_c << " contact " << c;
            worst_elastic[c] = std::max(worst_elastic[c], norm({tq[0] - m_el[0], tq[1] - m_el[1], tq[2] - m_el[2]}) / norm(m_el));
          } else if (spring > m_ref * (1 + 1e-9)) {
            if (yielded_at[c] < 0) yielded_at[c] = step;
            // saturated: |M| = R* tan(theta_c) F_n,el, direction -omega_r, no dashpot
            const double rel = std::fabs(norm(tq) - m_ref) / m_ref;
            worst_cap[c] = std::max(worst_cap[c], rel);
            ASSERT_LT(rel, 1e-12) << "theta_c " << theta_c << " contact " << c << " step " << step;
            ASSERT_NEAR(dot(tq, unit(wr)), -m_ref, 1e-12 * m_ref) << "must oppose omega_r";
            // the stored angle is rescaled so that k_theta |theta_r| = M_ref
            ASSERT_NEAR(k_th * norm(bt.theta(c)), m_ref, 1e-12 * m_ref);
          }
        }
      }
      for (uint32_t c = 0; c < nc; ++c) {
        EXPECT_GT(yielded_at[c], 0) << "contact " << c << " never saturated";
        std::printf("[sd %s theta_c=%4.1f] contact %u: R*=%.3g F_n,el=%.3g yielded at step %d; "
                    "max rel err elastic %.2e, cap %.2e\n",
                    stiffness, theta_c, c, cases[c].r_eff, cases[c].fn_el, yielded_at[c], worst_elastic[c],
                    worst_cap[c]);
      }
    }
}

// damping_at_yield: true keeps -n_theta omega_r on top of the capped spring.
TEST(RollingKernel, DampingAtYieldKeepsTheDashpot) {
  const double theta_c = 25.0;
  const auto cases = sweep(theta_c);
  const uint32_t nc = static_cast<uint32_t>(cases.size());
  for (bool keep : {false, true}) {
    const json params = {{"critical_angle", theta_c}, {"damping_at_yield", keep}};
    const SdCriticalAngle model{Params(params)};
    Batch bt(nc);
    for (uint32_t c = 0; c < nc; ++c) load(bt, c, cases[c], 1.0);  // dt = 1 s: saturated at once
    for (int step = 0; step < 3; ++step) {
      bt.clear_outputs();
      model.compute(bt.b);
      for (uint32_t c = 0; c < nc; ++c) {
        const Case& k = cases[c];
        const double a = k.r_eff * std::tan(theta_c * kDeg);
        const double n_th = 0.25 * k.eta_n * a * a, m_ref = a * k.fn_el;
        const V3 wr = in_plane(k.omega, k.n), e = unit(wr);
        const double d = keep ? n_th : 0.0;
        const V3 expect = {-m_ref * e[0] - d * wr[0], -m_ref * e[1] - d * wr[1], -m_ref * e[2] - d * wr[2]};
        ASSERT_GT(0.25 * k.kn_tangent * a * a * norm(wr), m_ref) << "test set-up: must be saturated";
        for (int q = 0; q < 3; ++q)
          EXPECT_NEAR(bt.torque(c)[q], expect[q], 1e-12 * norm(expect)) << "keep=" << keep << " contact " << c;
      }
    }
  }
}

// The couple is ADDED to tq* (abi.h), and a negative elastic force (a
// cohesive normal law) gives no cap, hence no torque.
TEST(RollingKernel, TorqueIsAddedAndCapUsesNonNegativeElasticForce) {
  const json params = {{"critical_angle", 30.0}};
  const SdCriticalAngle model{Params(params)};
  Batch bt(2);
  const Case k = sweep(30.0)[1];
  load(bt, 0, k, 1.0);
  load(bt, 1, k, 1.0);
  bt.fn_elastic[1] = -1.0;
  bt.eta_n[1] = 0.0;
  bt.tqx[0] = 1.0; bt.tqy[0] = 2.0; bt.tqz[0] = 3.0;
  model.compute(bt.b);
  const double a = k.r_eff * std::tan(30.0 * kDeg), m_ref = a * k.fn_el;
  const V3 e = unit(in_plane(k.omega, k.n));
  EXPECT_NEAR(bt.tqx[0], 1.0 - m_ref * e[0], 1e-12);
  EXPECT_NEAR(bt.tqy[0], 2.0 - m_ref * e[1], 1e-12);
  EXPECT_NEAR(bt.tqz[0], 3.0 - m_ref * e[2], 1e-12);
  EXPECT_EQ(norm(bt.torque(1)), 0.0);
  EXPECT_EQ(norm(bt.theta(1)), 0.0) << "zero cap: the spring is fully slipped, theta_r = 0";
}

// The twisting component (omega along n) leaves torque and history unchanged.
TEST(RollingKernel, TwistingPartIsIgnored) {
  const json params = {{"critical_angle", 20.0}};
  const SdCriticalAngle model{Params(params)};
  const Case k = sweep(20.0)[1];
  Batch with(1), without(1);
  load(with, 0, k, 1e-5);
  load(without, 0, k, 1e-5);
  without.set_omega(0, in_plane(k.omega, k.n));
  for (int step = 0; step < 50; ++step) {
    with.clear_outputs();
    without.clear_outputs();
    model.compute(with.b);
    model.compute(without.b);
    for (int q = 0; q < 3; ++q) {
      ASSERT_NEAR(with.torque(0)[q], without.torque(0)[q], 1e-13 * norm(without.torque(0)));
      ASSERT_NEAR(with.theta(0)[q], without.theta(0)[q], 1e-13 * norm(without.theta(0)));
    }
  }
  // pure twist: no rolling torque at all
  Batch twist(1);
  load(twist, 0, k, 1e-5);
  twist.set_omega(0, {7.0 * k.n[0], 7.0 * k.n[1], 7.0 * k.n[2]});
  twist.eta_n[0] = 1e3;
  model.compute(twist.b);
  EXPECT_LT(norm(twist.torque(0)), 1e-15 * 7.0 * 1e3);
}

// When the contact frame turns, the stored angle is projected onto the new
// tangent plane and rescaled to its old length (§3.4, "optionally rescale").
TEST(RollingKernel, HistoryProjectedOntoNewTangentPlaneKeepsItsLength) {
  const json params = {{"critical_angle", 30.0}};
  const SdCriticalAngle model{Params(params)};
  Batch bt(1);
  Case k = sweep(30.0)[0];  // n = +z
  k.fn_el = 1e3;            // far from the cap
  load(bt, 0, k, 1e-4);
  bt.set_omega(0, {2.0, -1.0, 0.0});
  for (int s = 0; s < 10; ++s) model.compute(bt.b);
  const V3 th0 = bt.theta(0);
  ASSERT_NEAR(th0[0], 10 * 2.0 * 1e-4, 1e-15);
  ASSERT_NEAR(th0[1], 10 * -1.0 * 1e-4, 1e-15);
  // turn the normal by 35 degrees about an axis in the plane, and stop rolling
  for (double tilt : {35.0, 80.0}) {
    Batch t(1);
    load(t, 0, k, 1e-4);
    const V3 n2 = unit({std::sin(tilt * kDeg), 0.3 * std::sin(tilt * kDeg), std::cos(tilt * kDeg)});
    t.set_normal(0, n2);
    t.set_omega(0, {0, 0, 0});
    for (int q = 0; q < 3; ++q) t.history[q] = th0[q];
    model.compute(t.b);
    const V3 th1 = t.theta(0);
    const V3 proj = in_plane(th0, n2);
    const double keep = norm(th0) / norm(proj);
    std::printf("[sd history] tilt %.0f deg: |theta| before %.6e after %.6e, theta.n2 = %.1e\n", tilt, norm(th0),
                norm(th1), dot(th1, n2));
    EXPECT_NEAR(norm(th1), norm(th0), 1e-14 * norm(th0)) << "length kept";
    EXPECT_NEAR(dot(th1, n2), 0.0, 1e-14 * norm(th0)) << "in the new tangent plane";
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(th1[q], keep * proj[q], 1e-14 * norm(th0)) << "along the projection";
    const double a = k.r_eff * std::tan(30.0 * kDeg), k_th = 0.25 * k.kn_tangent * a * a;
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(t.torque(0)[q], -k_th * th1[q], 1e-13 * k_th * norm(th1));
  }
}

TEST(RollingKernel, SdRefusesAnglesOutsideTheOpenInterval) {
  for (double bad : {0.0, -5.0, 90.0, 120.0}) {
    const json params = {{"critical_angle", bad}};
    EXPECT_THROW(SdCriticalAngle{Params(params)}, ParameterError) << bad;
  }
}

// DCT: |M| = mu_r R* F_n,el exactly, opposite omega_r, zero without rolling.
TEST(RollingKernel, DctConstantTorqueOpposesRollingVelocity) {
  for (double theta_c : {10.0, 20.0, 30.0, 45.0}) {
    const json by_angle = {{"critical_angle", theta_c}};
    const json by_mu = {{"rolling_friction", std::tan(theta_c * kDeg)}};
    const Dct a{Params(by_angle)}, b{Params(by_mu)};
    const auto cases = sweep(theta_c);
    const uint32_t nc = static_cast<uint32_t>(cases.size());
    for (const Dct* model : {&a, &b}) {
      Batch bt(nc, 0);
      for (uint32_t c = 0; c < nc; ++c) load(bt, c, cases[c], 1e-6);
      double worst = 0;
      for (int step = 0; step < 3; ++step) {  // no history: every step the same
        bt.clear_outputs();
        model->compute(bt.b);
        for (uint32_t c = 0; c < nc; ++c) {
          const Case& k = cases[c];
          const double m = std::tan(theta_c * kDeg) * k.r_eff * k.fn_el;
          const V3 tq = bt.torque(c), e = unit(in_plane(k.omega, k.n));
          const double rel = std::fabs(norm(tq) - m) / m;
          worst = std::max(worst, rel);
          EXPECT_LT(rel, 1e-12) << "theta_c " << theta_c << " contact " << c;
          EXPECT_NEAR(dot(tq, e), -m, 1e-12 * m) << "opposite omega_r";
          EXPECT_EQ(bt.rolling_stiffness[c], 0.0) << "no spring";
          EXPECT_EQ(bt.rolling_damping[c], 0.0) << "no dashpot";
        }
      }
      std::printf("[dct theta_c=%4.1f %s] max rel err of |M| vs mu_r R* F_n,el: %.2e\n", theta_c,
                  model == &a ? "critical_angle" : "rolling_friction", worst);
    }
  }
}

TEST(RollingKernel, DctZeroWithoutRollingAndIgnoresTwist) {
  const json params = {{"critical_angle", 20.0}};
  const Dct model{Params(params)};
  const Case k = sweep(20.0)[1];
  Batch bt(3, 0);
  load(bt, 0, k, 1e-6);
  bt.set_omega(0, {0, 0, 0});                                  // at rest
  load(bt, 1, k, 1e-6);
  bt.set_omega(1, {4.0 * k.n[0], 4.0 * k.n[1], 4.0 * k.n[2]});  // pure twist
  load(bt, 2, k, 1e-6);                                          // rolling + twist, magnitude independent of |omega|
  bt.set_omega(2, {1e-3 * k.omega[0], 1e-3 * k.omega[1], 1e-3 * k.omega[2]});
  bt.tqx[0] = 0.5;  // added to, not overwritten
  model.compute(bt.b);
  EXPECT_EQ(bt.tqx[0], 0.5);
  EXPECT_EQ(bt.tqy[0], 0.0);
  EXPECT_EQ(bt.tqz[0], 0.0);
  EXPECT_LT(norm(bt.torque(1)), 1e-14 * k.r_eff * k.fn_el);
  const double m = std::tan(20.0 * kDeg) * k.r_eff * k.fn_el;
  EXPECT_NEAR(norm(bt.torque(2)), m, 1e-12 * m);
  EXPECT_NEAR(dot(bt.torque(2), unit(in_plane(k.omega, k.n))), -m, 1e-12 * m);
}

TEST(RollingKernel, DctNeedsExactlyOneParameter) {
  const json both = {{"critical_angle", 20.0}, {"rolling_friction", 0.3}};
  const json none = json::object();
  EXPECT_THROW(Dct{Params(both)}, ParameterError);
  EXPECT_THROW(Dct{Params(none)}, ParameterError);
}

// Guards a fixed defect: for a pure twist omega = w n about a normal that is
// not axis-aligned, omega - (omega.n) n leaves a round-off residue ~1e-16 w
// in a random direction, and dct used to apply its FULL torque mu_r R* F_n,el
// in that direction (about half of random normals). A pure twist gives no
// rolling torque (§2: the twisting part is not the rolling model's);
// sd_critical_angle is not affected (its torque is proportional to omega_r).
TEST(RollingKernel, DctPureTwistAboutGenericNormalGivesNoTorque) {
  const json params = {{"critical_angle", 20.0}};
  const Dct model{Params(params)};
  const uint32_t n = 1000;
  Batch bt(n, 0);
  uint64_t state = 12345;
  auto uniform = [&]() {  // xorshift, deterministic
    state ^= state << 13; state ^= state >> 7; state ^= state << 17;
    return static_cast<double>(state >> 11) / 9007199254740992.0 * 2.0 - 1.0;
  };
  for (uint32_t c = 0; c < n; ++c) {
    const V3 nn = unit({uniform(), uniform(), uniform()});
    bt.set_normal(c, nn);
    bt.set_omega(c, {3.0 * nn[0], 3.0 * nn[1], 3.0 * nn[2]});
    bt.r_eff[c] = 1.4e-3;
    bt.fn_elastic[c] = 1.0;
  }
  model.compute(bt.b);
  const double full = std::tan(20.0 * kDeg) * 1.4e-3 * 1.0;
  int with_torque = 0;
  for (uint32_t c = 0; c < n; ++c)
    if (norm(bt.torque(c)) > 1e-12 * full) ++with_torque;
  std::printf("[dct pure twist] %d of %u random normals get a torque (full magnitude %.3e N m)\n", with_torque, n,
              full);
  EXPECT_EQ(with_torque, 0);
}

// Guards the per-pair rolling friction of ABI 2 (abi.h, domel_pair_v2):
// with has_rolling_friction set, dct and sd_critical_angle use the pair's
// mu_r (= tan theta_c) instead of their own parameter; unset, their own.
TEST(RollingKernel, PairRollingFrictionOverridesTheModelsOwn) {
  const Dct dct{Params(json{{"rolling_friction", 0.1}})};
  const SdCriticalAngle sd{Params(json{{"critical_angle", 30.0}})};
  for (const bool by_pair : {false, true}) {
    Batch bt(1, 3);
    bt.pair.has_rolling_friction = by_pair ? 1u : 0u;
    bt.pair.rolling_friction = 0.25;
    bt.set_normal(0, {0, 0, 1});
    bt.set_omega(0, {2.0, 0, 0});
    bt.r_eff[0] = 1e-3;
    bt.fn_elastic[0] = 2.0;
    bt.kn_tangent[0] = bt.kn[0] = 1e5;
    dct.compute(bt.b);
    const double mu = by_pair ? 0.25 : 0.1;
    EXPECT_NEAR(bt.tqx[0], -mu * 1e-3 * 2.0, 1e-15) << "dct, by_pair " << by_pair;
    bt.clear_outputs();
    sd.compute(bt.b);
    const double a = 1e-3 * (by_pair ? 0.25 : std::tan(30.0 * kDeg));
    EXPECT_NEAR(bt.rolling_stiffness[0], 0.25 * 1e5 * a * a, 1e-12 * 0.25 * 1e5 * a * a) << "sd, by_pair " << by_pair;
  }
}

// Guards the SDK's split of a batch of several material pairs (abi.h: pair
// NULL, pair_of per contact) into runs of one pair: through the generated C
// callback, every contact gets its own pair's mu_r, bit for bit as in
// uniform batches of each pair.
TEST(RollingKernel, MixedPairBatchIsSplitIntoRunsOfOnePair) {
  using Export = domel::sdk::detail::Export<Dct>;
  void* inst = nullptr;
  char err[256] = {0};
  ASSERT_EQ(Export::create(R"({"rolling_friction": 0.1})", nullptr, &inst, err, sizeof err), DOMEL_OK) << err;
  const uint32_t n = 7;
  Batch mixed(n, 0);
  domel_pair_v2 a = mixed.pair, b = mixed.pair;
  a.has_rolling_friction = 1; a.rolling_friction = 0.2;
  b.has_rolling_friction = 1; b.rolling_friction = 0.4;
  const std::vector<const domel_pair_v2*> pair_of = {&a, &a, &a, &b, &b, &a, &b};
  mixed.b.pair = nullptr;
  mixed.b.pair_of = pair_of.data();
  for (uint32_t c = 0; c < n; ++c) {
    mixed.set_normal(c, unit({0.1 * c, 1.0, 0.3}));
    mixed.set_omega(c, {1.0 + c, -2.0, 0.5});
    mixed.r_eff[c] = 1e-3 * (1 + c);
    mixed.fn_elastic[c] = 0.5 + c;
  }
  ASSERT_EQ(Export::contact(inst, &mixed.b, err, sizeof err), DOMEL_OK) << err;
  for (uint32_t c = 0; c < n; ++c) {
    Batch one(1, 0);
    one.pair = *pair_of[c];
    one.set_normal(0, {mixed.nx[c], mixed.ny[c], mixed.nz[c]});
    one.set_omega(0, {mixed.wx[c], mixed.wy[c], mixed.wz[c]});
    one.r_eff[0] = mixed.r_eff[c];
    one.fn_elastic[0] = mixed.fn_elastic[c];
    ASSERT_EQ(Export::contact(inst, &one.b, err, sizeof err), DOMEL_OK) << err;
    EXPECT_EQ(one.tqx[0], mixed.tqx[c]) << c;
    EXPECT_EQ(one.tqy[0], mixed.tqy[c]) << c;
    EXPECT_EQ(one.tqz[0], mixed.tqz[c]) << c;
  }
  Export::destroy(inst);
}

// The example's two stiffness options and its dashpot switch (LIGGGHTS epsd:
// ai + dashpot, epsd2: iwashita_oda without), driven at a constant rolling
// angular velocity until the cap: the elastic law M = -(k_r theta_r +
// C_r omega_r), then |M| = mu_r R* F_n opposing omega_r, with the ABI outputs
// rolling_stiffness = k_r and rolling_damping = C_r.
TEST(EpsdExample, StiffnessOptionsAndDashpotSwitchFollowTheFormulas) {
  const double mu_r = 0.1, eta_r = 0.3, dt = 1e-5;
  const double g_eff = 5e6 / (4.0 * (2.0 - 0.3) * (1.0 + 0.3));  // G* of two E = 5 MPa, nu = 0.3 spheres (physics.md §1.1)
  for (const char* stiffness : {"ai", "iwashita_oda"})
    for (const bool dashpot : {true, false}) {
      json params = {{"rolling_friction", mu_r}, {"stiffness", stiffness}, {"dashpot", dashpot}};
      if (dashpot) params["viscous_damping"] = eta_r;
      const Epsd model{Params(params)};
      const auto cases = sweep(0.0);
      const uint32_t nc = static_cast<uint32_t>(cases.size());
      Batch bt(nc);
      bt.pair.shear_eff = g_eff;
      std::vector<Case> scaled = cases;
      std::vector<double> k_r(nc), c_r(nc), m_max(nc);
      for (uint32_t c = 0; c < nc; ++c) {
        Case& k = scaled[c];
        const double delta = 1e-3 * k.r_eff;
        k_r[c] = std::string(stiffness) == "ai" ? 2.25 * k.kn_secant * mu_r * mu_r * k.r_eff * k.r_eff
                                                : 8.0 * g_eff * std::sqrt(k.r_eff * delta) * k.r_eff * k.r_eff;
        // two spheres of radius 2 R*, masses 3e-5 and 1e-5 kg: I_r = 1.4 I_i I_j / (I_i + I_j), I = m R^2
        const double ii = 3e-5 * 4.0 * k.r_eff * k.r_eff, ij = 1e-5 * 4.0 * k.r_eff * k.r_eff;
        c_r[c] = dashpot ? eta_r * 2.0 * std::sqrt(1.4 * ii * ij / (ii + ij) * k_r[c]) : 0.0;
        m_max[c] = mu_r * k.r_eff * k.fn_el;
        // yield near step 1500: M_max = k_r |omega_r| dt steps
        const double steps = m_max[c] / (k_r[c] * norm(in_plane(k.omega, k.n)) * dt);
        for (auto& w : k.omega) w *= steps / 1500.0;
      }
      for (uint32_t c = 0; c < nc; ++c) {
        const Case& k = scaled[c];
        load(bt, c, k, dt);
        bt.fn[c] = k.fn_el;  // the total normal force, the cap's F_n
        bt.overlap[c] = 1e-3 * k.r_eff;
        bt.contact_radius[c] = std::sqrt(k.r_eff * bt.overlap[c]);  // Hertz
        bt.radius_i[c] = bt.radius_j[c] = 2.0 * k.r_eff;
        bt.mass_i[c] = 3e-5;
        bt.mass_j[c] = 1e-5;
      }
      std::vector<int> yielded_at(nc, -1);
      for (int step = 1; step <= 3000; ++step) {
        bt.clear_outputs();
        model.compute(bt.b);
        for (uint32_t c = 0; c < nc; ++c) {
          const Case& k = scaled[c];
          ASSERT_NEAR(bt.rolling_stiffness[c], k_r[c], 1e-14 * k_r[c]) << stiffness << " contact " << c;
          ASSERT_NEAR(bt.rolling_damping[c], c_r[c], 1e-14 * c_r[c]) << stiffness << " contact " << c;
          const V3 wr = in_plane(k.omega, k.n);
          const V3 tq = bt.torque(c);
          const double spring = k_r[c] * step * dt * norm(wr);
          if (spring <= m_max[c] * (1 - 1e-9)) {
            ASSERT_LT(yielded_at[c], 0) << "elastic again after yielding";
            const double f = k_r[c] * step * dt + c_r[c];
            for (int q = 0; q < 3; ++q)
              ASSERT_NEAR(tq[q], -f * wr[q], 1e-11 * f * norm(wr)) << stiffness << " contact " << c << " step " << step;
          } else if (spring > m_max[c] * (1 + 1e-9)) {
            if (yielded_at[c] < 0) yielded_at[c] = step;
            ASSERT_NEAR(norm(tq), m_max[c], 1e-12 * m_max[c]) << stiffness << " contact " << c << " step " << step;
            ASSERT_NEAR(dot(tq, unit(wr)), -m_max[c], 1e-12 * m_max[c]) << "must oppose omega_r";
          }
        }
      }
      for (uint32_t c = 0; c < nc; ++c) EXPECT_GT(yielded_at[c], 1000) << stiffness << " contact " << c;
    }
}

// epsd2's spring is much stiffer than epsd's at the same mu_r (§2.3 against
// §2.2): k_t R*^2 / (2.25 k_n mu_r^2 R*^2) = 8 G* a / (2.25 (4/3) E* a mu_r^2)
// for Hertz, 2.67 G*/(E* mu_r^2) = 55 at nu = 0.3 and mu_r = 0.1.
TEST(EpsdExample, IwashitaOdaOverAiIsTheHertzMindlinStiffnessRatio) {
  const double e_eff = 5e6 / (2.0 * (1.0 - 0.09)), g_eff = 5e6 / (4.0 * 1.7 * 1.3), mu_r = 0.1;
  const double r = 1.4e-3, delta = 1e-5, a = std::sqrt(r * delta);
  double k[2] = {0.0, 0.0};
  for (int opt = 0; opt < 2; ++opt) {
    const Epsd model{Params(json{{"rolling_friction", mu_r}, {"stiffness", opt ? "iwashita_oda" : "ai"}})};
    Batch bt(1);
    bt.pair.shear_eff = g_eff;
    bt.set_normal(0, {0, 0, 1});
    bt.r_eff[0] = bt.radius_i[0] = bt.radius_j[0] = r;
    bt.overlap[0] = delta;
    bt.contact_radius[0] = a;
    bt.kn[0] = 4.0 / 3.0 * e_eff * a;  // Hertz secant stiffness
    bt.fn[0] = bt.kn[0] * delta;
    model.compute(bt.b);
    k[opt] = bt.rolling_stiffness[0];
  }
  const double expected = 8.0 * g_eff / (2.25 * 4.0 / 3.0 * e_eff * mu_r * mu_r);
  EXPECT_NEAR(k[1] / k[0], expected, 1e-12 * expected);
  EXPECT_NEAR(expected, 55.0, 0.5);
}

TEST(EpsdExample, RefusesAnUnknownStiffnessAndADashpotContradiction) {
  EXPECT_THROW(Epsd(Params(json{{"rolling_friction", 0.1}, {"stiffness", "iwashita"}})), ParameterError);
  try {
    Epsd(Params(json{{"rolling_friction", 0.1}, {"dashpot", false}, {"viscous_damping", 0.3}}));
    ADD_FAILURE() << "dashpot false with viscous_damping 0.3 was accepted";
  } catch (const ParameterError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'viscous_damping'"), std::string::npos) << what;
    EXPECT_NE(what.find("'dashpot' is false"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(Epsd(Params(json{{"rolling_friction", 0.1}, {"dashpot", false}, {"viscous_damping", 0.0}})));
}
