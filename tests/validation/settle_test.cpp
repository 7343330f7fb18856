// SPDX-License-Identifier: MIT
// Guards the whole engine on a many-body problem (issue 2 acceptance): the
// 10k column of scenarios/validation/settle_10k.json settles in its box
// with no particle lost (all still inside the box, all finite), no overlap
// above 1 % of the diameter once at rest (the largest static Hertz overlap
// for this material is ~0.5 % d: 2.3 % measured at E = 5 MPa, scaled by
// (10)^(-2/3)), and kinetic energy decayed to below 1e-4 of its peak
// (measured: ~1e-7 at E = 5 MPa after 0.6 s). Label "slow": ~2 min.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace dt = domel::test;

TEST(Settle10k, ComesToRestWithoutLossOrExcessOverlap) {
  const std::string file = DOMEL_SOURCE_DIR "/scenarios/validation/settle_10k.json";
  auto sim = domel::platform::load_scenario(file, dt::builtin_registry());
  auto& sd = *sim->subdomains[0];
  const std::size_t n0 = sd.store().size();
  ASSERT_EQ(n0, 10115u);
  sd.setup();
  double ke_peak = 0;
  const auto steps = static_cast<std::uint64_t>(std::llround(sim->duration / sd.time_step()));
  for (std::uint64_t k = 0; k < steps; ++k) {
    sd.step();
    if (k % 100 == 0) ke_peak = std::max(ke_peak, sd.stats().kinetic_translational + sd.stats().kinetic_rotational);
  }
  const auto st = sd.stats();
  const auto& s = sd.store();
  ASSERT_EQ(s.size(), n0);
  // the box: min [0,0,0], max [17 a, 17 a, 37 a], a = 1.02 d, open top
  const double a = 1.02 * 0.0028, lx = 17 * a;
  for (std::size_t k = 0; k < s.size(); ++k) {
    ASSERT_TRUE(std::isfinite(s.x[k]) && std::isfinite(s.y[k]) && std::isfinite(s.z[k]));
    EXPECT_GT(s.x[k], 0.0); EXPECT_LT(s.x[k], lx);
    EXPECT_GT(s.y[k], 0.0); EXPECT_LT(s.y[k], lx);
    EXPECT_GT(s.z[k], 0.0);
  }
  EXPECT_LT(st.max_overlap_ratio, 0.01);
  EXPECT_GT(ke_peak, 0.0);
  EXPECT_LT(st.kinetic_translational + st.kinetic_rotational, 1e-4 * ke_peak);
  std::printf("settle_10k: %zu particles, %zu contacts, max overlap %.4f d, KE end/peak %.3g\n", s.size(),
              st.contacts, st.max_overlap_ratio, (st.kinetic_translational + st.kinetic_rotational) / ke_peak);
}
