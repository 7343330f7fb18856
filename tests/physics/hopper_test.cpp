// Guards the cone (hopper) container and its outlet plug: a sphere dropped
// into a hopper whose bottom is plugged rests on the plug; once the plug is
// removed (outlet_open_at) a sphere smaller than the outlet falls out, and
// a larger one is caught by the outlet's rim edge and rests there at the
// height where it touches the rim circle. Also the cylinder with an outlet
// in its flat bottom.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace dt = domel::test;
using nlohmann::json;

namespace {

constexpr double kRho = 2500, kG = 9.81;
constexpr double kOutlet = 0.004, kOpen = 0.3;

struct Drop {
  double z_plugged;  ///< centre height just before the plug goes
  double z_end, speed_end;
};

Drop drop(const json& wall, double r) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, 0.5);
  doc["gravity"] = {0, 0, -kG};
  doc["walls"].push_back(wall);
  auto sim = dt::build(doc);
  auto& sd = *sim->subdomains[0];
  auto& s = sd.store();
  s.add(1, 1e-4, 0, 0.012, r, kRho);  // slightly off the axis
  const auto rep = sd.estimate_time_step(0.5);
  sd.set_time_step(std::min(rep.contact_time / 50.0, 2e-5));
  sd.set_skin(0.4 * r);
  sd.setup();
  Drop d{};
  while (sd.time() < kOpen - 1e-3) sd.step();
  d.z_plugged = s.z[0];
  while (sd.time() < 0.6) sd.step();
  d.z_end = s.z[0];
  d.speed_end = std::sqrt(s.vx[0] * s.vx[0] + s.vy[0] * s.vy[0] + s.vz[0] * s.vz[0]);
  return d;
}

json hopper() {
  // a shallow hopper: radius 4 mm at z = 0 widening at 1.5 m per m, so a
  // large sphere meets the lower rim before the mantle
  return {{"name", "hopper"}, {"type", "cone"}, {"material", "m"}, {"axis", "z"}, {"center", {0, 0, 0}},
          {"bottom", 0.0}, {"top", 0.03}, {"radius_bottom", kOutlet}, {"radius_top", kOutlet + 1.5 * 0.03},
          {"closed_bottom", true}, {"outlet_open_at", kOpen}};
}

}  // namespace

TEST(Hopper, SmallSphereRestsOnThePlugThenFallsOut) {
  // Tolerance: the resting height is r minus the Hertz overlap under the
  // sphere's weight (~1e-5 m here), so 2 % of r holds it.
  const double r = 0.0014;
  const Drop d = drop(hopper(), r);
  EXPECT_NEAR(d.z_plugged, r, 0.02 * r);
  EXPECT_LT(d.z_end, -0.1);  // free fall for ~0.3 s after the plug went
}

TEST(Hopper, LargeSphereIsCaughtByTheRimEdge) {
  // At rest on the rim circle of radius a the centre lies at sqrt(r^2 - a^2)
  // above the outlet plane; tolerance 2 %: the rim overlap under the weight
  // (~2e-5 m) and the residual sideways rocking on a single closest rim point.
  const double r = 0.006;
  const Drop d = drop(hopper(), r);
  EXPECT_NEAR(d.z_plugged, r, 0.02 * r);
  const double expected = std::sqrt(r * r - kOutlet * kOutlet);
  EXPECT_NEAR(d.z_end, expected, 0.02 * expected);
  EXPECT_LT(d.speed_end, 1e-3);
}

TEST(Hopper, CylinderOutletOpensAtItsTime) {
  json silo = {{"name", "silo"}, {"type", "cylinder"}, {"material", "m"}, {"axis", "z"}, {"center", {0, 0, 0}},
               {"radius", 0.02}, {"bottom", 0.0}, {"top", 0.05}, {"outlet_radius", kOutlet},
               {"outlet_open_at", kOpen}};
  const Drop small = drop(silo, 0.0014);
  EXPECT_NEAR(small.z_plugged, 0.0014, 0.02 * 0.0014);
  EXPECT_LT(small.z_end, -0.1);
  const double r = 0.006;
  const Drop large = drop(silo, r);  // held by the annulus' inner rim
  const double expected = std::sqrt(r * r - kOutlet * kOutlet);
  EXPECT_NEAR(large.z_end, expected, 0.02 * expected);
  EXPECT_LT(large.speed_end, 1e-3);
}
