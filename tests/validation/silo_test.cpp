// SPDX-License-Identifier: MIT
// Guards the silo discharge end to end (issue 4, acceptance 6-8): the
// CI-sized silo of scenarios/silo/silo_ci.json (D = 70 mm, flat bottom, 20 mm
// outlet = 7.1 d, 15,000 spheres of 2.8 mm poured at 2.5 kg/s, settled,
// outlet opened at 0.5 s) discharges at the Beverloo rate, counts every
// particle, and the mass-flow plane agrees with the deletion region.
//
// Expected values:
//  - Beverloo (shared physics.md §6.1): W = C rho_b sqrt(g) (D_o - k d)^(5/2),
//    C = 0.58, k = 1.5, rho_b = phi rho_p with phi the volume fraction of the
//    settled bed measured by the run's own cell grid (layers between 20 % and
//    80 % of the bed height, just before the outlet opens). Tolerance 15 %:
//    the issue's, and physics.md §9 target 13 ("typical for DEM vs
//    Beverloo"); measured -11.5 %.
//  - mass balance: exact in the integer units the platform keeps.
//  - the plane 1 cm below the outlet and the deletion region below it see the
//    same flow: their least-squares rates over the window agree within 3 %
//    (the plane leads the region by the free-fall time of 4-6 cm, ~0.05 s, and
//    the rows are 0.01 s apart; measured 0.5 %).
// Label "slow": about 70-100 s on this machine.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace dt = domel::test;

namespace {

/// Accessible-volume-weighted volume fraction of the bed's middle layers in
/// the last profile written at or before t_open.
double bed_volume_fraction(const std::string& csv, double t_open) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header: time,layer,centre,accessible_volume,count,volume_fraction,...
  struct Row { double t, z, vol, phi; };
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string f;
    std::vector<double> v;
    while (std::getline(ss, f, ',')) v.push_back(std::stod(f));
    rows.push_back({v[0], v[2], v[3], v[5]});
  }
  double t_best = -1;
  for (const auto& r : rows)
    if (r.t <= t_open + 1e-9) t_best = std::max(t_best, r.t);
  double top = 0;
  for (const auto& r : rows)
    if (r.t == t_best && r.phi > 0.3) top = std::max(top, r.z);
  double sum = 0, vol = 0;
  for (const auto& r : rows)
    if (r.t == t_best && r.phi > 0.3 && r.z >= 0.2 * top && r.z <= 0.8 * top) {
      sum += r.phi * r.vol;
      vol += r.vol;
    }
  return vol > 0 ? sum / vol : std::nan("");
}

}  // namespace

TEST(SiloCi, DischargesAtTheBeverlooRateWithAnExactMassBalance) {
  const std::string file = DOMEL_SOURCE_DIR "/scenarios/silo/silo_ci.json";
  auto sim = domel::platform::load_scenario(file, dt::builtin_registry());
  domel::platform::RunOptions opt;
  opt.progress = false;
  opt.output_directory = ::testing::TempDir() + "/silo_ci";
  const auto result = sim->run(opt, dt::builtin_registry());
  const auto& s = result.summary;

  const auto& bal = s["mass_balance"]["grains"];
  EXPECT_TRUE(bal["exact"].get<bool>());
  EXPECT_EQ(bal["residual_units_1e-18kg"].get<long long>(), 0);
  EXPECT_GE(bal["inserted"].get<std::uint64_t>(), 15000u);
  EXPECT_LE(bal["inserted"].get<std::uint64_t>(), 15001u);
  EXPECT_GT(bal["removed"].get<std::uint64_t>(), 1000u);

  const double phi = bed_volume_fraction(opt.output_directory.string() + "/bed_profile.csv", 0.5);
  ASSERT_TRUE(std::isfinite(phi));
  EXPECT_GT(phi, 0.55);  // a random packing of poured monodisperse spheres (0.55-0.64)
  EXPECT_LT(phi, 0.65);
  const double d = 0.0028, d_o = 0.020, rho_b = phi * 2500.0;
  const double beverloo = 0.58 * rho_b * std::sqrt(9.81) * std::pow(d_o - 1.5 * d, 2.5);
  const double rate = s["deletion_regions"]["outlet"]["steady"]["rate_kg_s"].get<double>();
  const double plane = s["mass_flow"]["orifice"]["steady"]["rate_kg_s"].get<double>();
  std::printf("[silo_ci] phi %.3f, discharge %.4f kg/s (plane %.4f), Beverloo %.4f kg/s: %+.1f %%\n", phi, rate,
              plane, beverloo, 100.0 * (rate / beverloo - 1.0));
  EXPECT_NEAR(rate, beverloo, 0.15 * beverloo);
  EXPECT_NEAR(plane, rate, 0.03 * rate);
}
