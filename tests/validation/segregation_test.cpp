// SPDX-License-Identifier: MIT
// Guards mixtures in motion (issue 18 item 6): the vibrated binary mixture
// of scenarios/examples/shaker.json (3 mm and 6 mm beads, 50/50 by volume,
// in a box vibrating at 25 Hz with Gamma = 3) segregates by size, the large
// beads rising (the Brazil-nut effect, Rosato et al., Phys. Rev. Lett. 58
// (1987) 1038; here driven by the wall-induced convection of Knight, Jaeger
// & Nagel, Phys. Rev. Lett. 70 (1993) 3728). The index
// S = (z_large - z_small) / h0 (h0: the bed's mean height at rest; 0 mixed,
// 1 fully segregated) from probes.csv's centres of mass must grow from
// its value at rest by at least 0.2 within 3 s of shaking; the control, the
// same bed with both components of 3 mm, must keep |S| below 0.1 (no
// size difference, no segregation: the index is not an artefact of the
// shaking). Measured values in docs/validation/segregation.md. Label "slow":
// about 1 min on two threads.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>
#include <vector>

namespace dt = domel::test;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Series {
  double rest = 0;   ///< S before the shaking (mean of the rows in (0.3, 0.5] s: settled)
  double early = 0;  ///< S over (0.5, 1.0] s
  double late = 0;   ///< S over the last 0.5 s
};

Series run(bool equal_sizes) {
  std::ifstream in(DOMEL_SOURCE_DIR "/scenarios/examples/shaker.json");
  json doc = json::parse(in);
  doc["run"]["duration"] = 3.5;
  doc["output"]["vtk_interval"] = 0;
  if (equal_sizes) {
    auto& large = doc["subdomains"][0]["insert"][0];
    large["diameter"] = 3e-3;
    large["count"] = large["count"].get<int>() * 8;  // the same volume
  }
  const fs::path out = dt::run_into_temp(doc, DOMEL_SOURCE_DIR "/scenarios/examples/shaker.json",
                                         equal_sizes ? "shaker_equal" : "shaker", 2);
  const dt::Csv csv = dt::read_csv(out / "probes.csv");
  const std::vector<std::vector<double>>& rows = csv.rows;
  fs::remove_all(out);
  const std::size_t t = csv.column.at("time"), zl = csv.column.at("large.com_z"), zs = csv.column.at("small.com_z"),
                    ml = csv.column.at("large.mass_kg"), ms = csv.column.at("small.mass_kg");
  double h0 = 0, n0 = 0;
  for (const auto& r : rows)
    if (r[t] > 0.3 && r[t] <= 0.5) {
      h0 += (r[zl] * r[ml] + r[zs] * r[ms]) / (r[ml] + r[ms]);
      n0 += 1;
    }
  h0 /= n0;
  auto mean_s = [&](double from, double to) {
    double s = 0, n = 0;
    for (const auto& r : rows)
      if (r[t] > from && r[t] <= to + 1e-9) {
        s += (r[zl] - r[zs]) / h0;
        n += 1;
      }
    return s / n;
  };
  const double end = rows.back()[t];
  return {mean_s(0.3, 0.5), mean_s(0.5, 1.0), mean_s(end - 0.5, end)};
}

}  // namespace

TEST(Segregation, AVibratedBinaryMixtureSegregatesBySizeAndAnEqualSizedOneDoesNot) {
  const Series mix = run(false);
  const Series control = run(true);
  std::printf("segregation index S: 3/6 mm mixture %+.3f at rest, %+.3f over 0.5-1.0 s, %+.3f over the last 0.5 s; "
              "3/3 mm control %+.3f, %+.3f, %+.3f\n",
              mix.rest, mix.early, mix.late, control.rest, control.early, control.late);
  EXPECT_GT(mix.late - mix.rest, 0.2);
  EXPECT_GT(mix.late, mix.early);
  EXPECT_LT(std::fabs(control.late), 0.1);
  EXPECT_LT(std::fabs(control.late - control.rest), 0.1);
}
