// Guards the cylinder container (platform/geometry/wall.hpp): a sphere
// thrown radially at the mantle rebounds with the pair's restitution (1 %,
// as for a plane: the contact uses R* = R_i, the mantle's curvature is not
// in the contact law — documented in docs/physics.md), and a randomly filled
// cylinder keeps every particle inside its radius and above its bottom while
// the fill settles under gravity.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace dt = domel::test;
using nlohmann::json;

TEST(CylinderContainer, RadialImpactOnMantleRecoversRestitution) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-7, 0.5, 0.5);
  doc["walls"] = {{{"name", "tube"}, {"type", "cylinder"}, {"material", "m"}, {"axis", "z"}, {"center", {0, 0, 0}},
                   {"radius", 0.02}, {"bottom", -0.1}, {"top", 0.1}, {"closed_bottom", false}}};
  auto sim = dt::build(doc);
  auto& sd = *sim->subdomains[0];
  const double r = 0.0014;
  sd.store().add(1, 0.02 - r * 1.001, 0, 0, r, 2500);
  sd.store().vx[0] = 0.8;
  const auto rep = sd.estimate_time_step(0.8);
  sd.set_time_step(rep.contact_time / 200);
  sd.set_skin(0.0005);
  sd.setup();
  bool started = false;
  for (int k = 0; k < 100000; ++k) {
    sd.step();
    const bool touching = sd.stats().wall_contacts > 0;
    started |= touching;
    if (started && !touching) break;
  }
  ASSERT_TRUE(started);
  EXPECT_NEAR(-sd.store().vx[0] / 0.8, 0.5, 0.005);
}

TEST(CylinderContainer, RandomFillStaysInsideWhileSettling) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  doc["walls"] = {{{"name", "tube"}, {"type", "cylinder"}, {"material", "m"}, {"axis", "z"}, {"center", {0, 0, 0}},
                   {"radius", 0.015}, {"bottom", 0.0}, {"top", 0.2}}};
  json insert = {{"model", "random"}, {"diameter", 0.0028}, {"count", 300}};
  insert["region"] = {{"cylinder", {{"axis", "z"}, {"center", {0, 0, 0}}, {"radius", 0.015}, {"bottom", 0.0}, {"top", 0.08}}}};
  doc["subdomains"][0]["insert"] = json::array({insert});
  auto sim = dt::build(doc);
  auto& sd = *sim->subdomains[0];
  ASSERT_EQ(sd.store().size(), 300u);
  sd.set_skin(0.0014);
  sd.setup();
  for (int k = 0; k < 15000; ++k) sd.step();  // 0.15 s: the fill has fallen and packed
  const auto& s = sd.store();
  double lowest = 1;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double rho = std::hypot(s.x[k], s.y[k]);
    EXPECT_LT(rho + s.radius[k], 0.015 + 0.01 * 0.0028) << "particle " << s.id[k] << " outside the mantle";
    EXPECT_GT(s.z[k] - s.radius[k], -0.01 * 0.0028) << "particle " << s.id[k] << " below the bottom";
    lowest = std::min(lowest, s.z[k]);
  }
  EXPECT_LT(lowest, 0.0015);  // the fill reached the bottom
  EXPECT_GT(sd.stats().wall_contacts, 30u);
}
