// Guards moving walls (WallPrimitive motion, the surface velocity in the
// wall contact): a sphere at rest on a belt (a plane moving in its own
// plane at U) is dragged until it rolls without slip on the belt, at the
// analytic 2/7 U; a cylinder container rotating about its axis spins up a
// sphere resting on its bottom at the mantle to 2/7 of the bottom's speed.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace dt = domel::test;
using nlohmann::json;

namespace {
constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kG = 9.81, kMu = 0.5;
}

TEST(MovingWall, BeltDragsARestingSphereToTwoSeventhsOfItsSpeed) {
  // Coulomb sliding with F = mu m g: v = mu g t, omega_y = -(5/2) mu g t / r,
  // contact-point speed v - r omega_y = (7/2) mu g t reaches U at
  // t* = 2U / (7 mu g), so v = 2U/7 and the sphere rolls on from then on
  // (no rolling resistance). Tolerance 1 %: the tangential spring makes the
  // end of slip slightly soft, as in incline_rolling_test (2 % there, on an
  // acceleration; here on a velocity plateau).
  const double U = 0.2;
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, kMu);
  doc["gravity"] = {0, 0, -kG};
  doc["walls"].push_back({{"name", "belt"}, {"type", "plane"}, {"material", "m"}, {"point", {0, 0, 0}},
                          {"normal", {0, 0, 1}}, {"motion", {{"velocity", {U, 0, 0}}, {"start", 0.02}}}});
  auto sim = dt::build(doc);
  auto& sd = dt::one_sphere(*sim, {0, 0, kR}, kR, kRho);
  auto& s = sd.store();
  while (sd.time() < 0.02) sd.step();  // settle on the still belt
  EXPECT_LT(std::fabs(s.vx[0]), 1e-4);
  const double t_star = 2 * U / (7 * kMu * kG);
  while (sd.time() < 0.02 + 0.5 * t_star) sd.step();
  EXPECT_NEAR(s.vx[0], kMu * kG * 0.5 * t_star, 0.05 * kMu * kG * 0.5 * t_star);  // still sliding: a = mu g
  while (sd.time() < 0.02 + 3 * t_star) sd.step();
  EXPECT_NEAR(s.vx[0], 2.0 / 7.0 * U, 0.01 * 2.0 / 7.0 * U);
  EXPECT_NEAR(s.vx[0] - kR * s.wy[0], U, 0.01 * U);  // the contact point moves with the belt
  EXPECT_GT(sd.neighbor_builds(), 0u);
}

TEST(MovingWall, RotatingCylinderSpinsUpASphereAtItsWall) {
  // A sphere resting on the turning bottom against the mantle: the bottom
  // is a belt moving at Omega rho under it, so (as for the belt above) it
  // ends up rolling on the bottom at 2/7 Omega rho in the turning direction;
  // the mantle only supplies the centripetal force m v^2 / rho, and its
  // friction (at most mu m v^2 / rho, 1e-3 of the weight here) shifts that
  // by well under 1 %. Tolerance 2 %: that shift plus the tangential
  // spring's softness (as for the belt).
  const double R = 0.01, omega = 10.0;
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, kMu);
  doc["gravity"] = {0, 0, -kG};
  doc["walls"].push_back({{"name", "drum"}, {"type", "cylinder"}, {"material", "m"}, {"axis", "z"},
                          {"center", {0, 0, 0}}, {"radius", R}, {"bottom", 0.0}, {"top", 0.02},
                          {"motion", {{"angular_velocity", {0, 0, omega}}}}});
  auto sim = dt::build(doc);
  auto& sd = dt::one_sphere(*sim, {R - kR, 0, kR}, kR, kRho);
  auto& s = sd.store();
  while (sd.time() < 0.3) sd.step();
  const double rho = std::hypot(s.x[0], s.y[0]);
  const double v_tangential = (s.x[0] * s.vy[0] - s.y[0] * s.vx[0]) / rho;  // positive: counter-clockwise, as omega
  EXPECT_NEAR(v_tangential, 2.0 / 7.0 * omega * rho, 0.02 * 2.0 / 7.0 * omega * rho);
  EXPECT_LT(rho + kR, R * 1.001);
}

TEST(MovingWall, AnalyticWallsRefuseRotationAboutAnotherAxis) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, kMu);
  doc["walls"].push_back({{"name", "drum"}, {"type", "cylinder"}, {"material", "m"}, {"axis", "z"},
                          {"center", {0, 0, 0}}, {"radius", 0.01}, {"bottom", 0.0}, {"top", 0.02},
                          {"motion", {{"angular_velocity", {1, 0, 0}}}}});
  try {
    dt::build(doc);
    FAIL() << "a cylinder rotating about x was accepted";
  } catch (const domel::platform::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("rotates only about an axis parallel to its own axis"), std::string::npos) << e.what();
  }
}
