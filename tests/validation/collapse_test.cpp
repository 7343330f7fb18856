// SPDX-License-Identifier: MIT
// Guards the S–D vs DCT difference at rest (issue 3, acceptance 6(d);
// the mission's S–D vs DCT comparison, docs/validation/collapse_sd_vs_dct/report.md):
// scenarios/ab/collapse_sd_vs_dct.json,
// a column of ~1900 spheres released on a rough floor at t = 0.2 s, comes to
// rest by t ~ 0.8 s. Median |omega| (robust against the few free spinners
// about the contact normal, docs/validation/repose.md):
//  - S–D (sd_critical_angle): keeps decaying once positions are static: at
//    least tenfold over the last 0.5 s (measured ~200x at dt = 1e-5 s).
//  - DCT (mu_r = tan theta_c): stalls, at both time steps: the median falls
//    by well under tenfold over the last 0.5 s (measured last/first ~0.6).
//    What it stalls at is not a floor set by the per-step kick M_r dt / I:
//    run to 4 s at dt = 1e-5, 5e-6 and 2.5e-6 s (scenarios/ab/dct_floor.py,
//    docs/validation/collapse_sd_vs_dct/report.md) the median keeps falling
//    slowly, with bursts, to ~1e-4 rad/s, and the three steps give the same
//    level within their run-to-run scatter. So nothing here asserts a
//    dependence on dt; the dt/2 runs check that the S–D/DCT difference
//    holds at both steps.
//  - the S–D result does not depend on dt: it keeps decaying at either step.
// CI (label long) runs the scenario's step, 1e-5 s: two runs of 1.5 s, about
// 2 minutes on one core; scripts/validate the half step too (label validate).
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace dt = domel::test;
using nlohmann::json;

namespace {

struct Series {
  std::vector<double> t, median;
  double mean_median(double from, double to) const {
    double s = 0;
    int n = 0;
    for (std::size_t k = 0; k < t.size(); ++k)
      if (t[k] >= from - 1e-9 && t[k] <= to + 1e-9) { s += median[k]; ++n; }
    return n ? s / n : 0;
  }
};

Series run(const std::string& model, double step) {
  std::ifstream in(DOMEL_SOURCE_DIR "/scenarios/ab/collapse_sd_vs_dct.json");
  json doc = json::parse(in);
  const double theta = doc["subdomains"][0]["contact"]["rolling"]["critical_angle"].get<double>();
  doc["subdomains"][0]["contact"]["rolling"] = {{"model", model}, {"critical_angle", theta}};
  doc["subdomains"][0]["time_step"] = step;
  auto sim = domel::platform::load_scenario(doc, DOMEL_SOURCE_DIR "/scenarios/ab/collapse_sd_vs_dct.json",
                                            dt::builtin_registry());
  auto& sd = *sim->subdomains[0];
  sd.setup();
  Series out;
  const auto steps = static_cast<long>(std::llround(sim->duration / step));
  const long every = static_cast<long>(std::llround(0.01 / step));
  for (long k = 1; k <= steps; ++k) {
    sd.step();
    if (k % every == 0) {
      out.t.push_back(sd.time());
      out.median.push_back(sd.stats().median_angular_speed);
    }
  }
  return out;
}

/// The claims of the file comment at one time step (both print their medians).
void expect_sd_decays_and_dct_stalls(double step) {
  const Series sd = run("sd_critical_angle", step), dct = run("dct", step);
  const double sd_early = sd.mean_median(0.95, 1.05), sd_late = sd.mean_median(1.45, 1.5);
  const double dct_early = dct.mean_median(0.95, 1.05), dct_late = dct.mean_median(1.45, 1.5);
  const double dct_floor = dct.mean_median(1.0, 1.5);
  std::printf("dt = %g s: S-D  median |omega| %.3g (t~1.0) -> %.3g (t~1.5)\n", step, sd_early, sd_late);
  std::printf("dt = %g s: DCT  median |omega| %.3g (t~1.0) -> %.3g (t~1.5); window mean %.3g\n", step, dct_early,
              dct_late, dct_floor);
  EXPECT_LT(sd_late, 0.1 * sd_early) << "S-D must keep decaying, at least tenfold over the last 0.5 s";
  EXPECT_GT(dct_late, 0.3 * dct_early) << "DCT should stall";
  EXPECT_LT(sd_late, 0.01 * dct_floor) << "S-D ends far below the level DCT stalls at";
}

}  // namespace

// CI size (label long): the scenario's time step, 1e-5 s.
TEST(CollapseSdVsDct, SpringDashpotComesToRestConstantTorqueKeepsChattering) {
  expect_sd_decays_and_dct_stalls(1e-5);
}

// Full size (label validate, scripts/validate): the same at half the time
// step, so the difference is not a time-step artefact (two runs of 1.5 s at
// 5e-6 s: about 4 minutes on one core).
TEST(CollapseSdVsDctFullSize, TheDifferenceHoldsAtHalfTheTimeStep) { expect_sd_decays_and_dct_stalls(5e-6); }

// Guards issue 3, acceptance 6(e): the angle-of-repose probe (free-surface fit
// of the heap, platform/subdomain/repose_probe.cpp) shows that the S–D model
// builds a steeper heap than no rolling resistance. theta_c = 20 deg makes
// the effect large compared with the seed-to-seed scatter (about +-1 deg on
// the peers' deck, docs/validation/repose.md); the bound is 2 deg.
TEST(CollapseSdVsDct, SpringDashpotHeapIsSteeperThanWithoutRollingResistance) {
  auto angle = [](const json& rolling) {
    std::ifstream in(DOMEL_SOURCE_DIR "/scenarios/ab/collapse_sd_vs_dct.json");
    json doc = json::parse(in);
    doc["subdomains"][0]["contact"]["rolling"] = rolling;
    auto sim = domel::platform::load_scenario(doc, DOMEL_SOURCE_DIR "/scenarios/ab/collapse_sd_vs_dct.json",
                                              dt::builtin_registry());
    auto& sd = *sim->subdomains[0];
    sd.setup();
    const auto steps = static_cast<long>(std::llround(1.2 / sd.time_step()));  // at rest by t ~ 0.8 s
    for (long k = 0; k < steps; ++k) sd.step();
    return domel::platform::repose_angle(sd.store(), *sim->repose_probe).value_or(0.0);
  };
  const double with_sd = angle({{"model", "sd_critical_angle"}, {"critical_angle", 20.0}});
  const double without = angle({{"model", "none"}});
  std::printf("angle of repose: sd_critical_angle(20 deg) %.2f deg, none %.2f deg\n", with_sd, without);
  EXPECT_GT(with_sd, without + 2.0);
}
