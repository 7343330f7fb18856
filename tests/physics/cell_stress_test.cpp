// SPDX-License-Identifier: MIT
// Guards the cell averages wired into a run (output.grids; issue 4,
// acceptance 4): the stress the grid measures in a settled column balances
// the column's weight, and its volume fraction is the column's.
//
// The check is exact statics, not an empirical fit. For particles at rest,
// sum over particles of x_i (x) (contact forces + external force) = 0. A pair
// contributes (x_i - x_j) (x) F_ij, a wall contact (x_i - p) (x) F + p (x) F.
// With gravity -g z, a floor at z = 0 (p_z = 0) and frictionless side walls
// (F_z = 0 there), the zz component gives
//     sum_cells sigma_zz V_c w_c = (contact virial)_zz = g sum_i m_i z_i
// (physics.md §8 sign: compression positive). The residual motion of a
// settled column leaves the kinetic part and the unbalanced forces at well
// under 1 % (measured max overlap velocity ~1e-4 m/s); 2 % is the tolerance.
// The volume fraction: the grid's sum of phi V_c w_c is the particles'
// volume exactly (every centre lies in the grid; binning by centre moves
// volume between cells, never out of the grid).
#include "outputs/grid_files.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using nlohmann::json;

TEST(CellStress, SettledColumnStressBalancesItsWeight) {
  json doc = domel::test::scenario(domel::test::hertz_mindlin(), 2e-5, 0.5, 0.5, 1e7);
  doc["gravity"] = {0, 0, -9.81};
  doc["materials"]["wall"] = {{"youngs_modulus", 1e7}, {"poisson_ratio", 0.3}};
  doc["interactions"].push_back({{"materials", {"m", "wall"}}, {"restitution", 0.5}, {"friction", 0.0}});
  doc["walls"].push_back({{"name", "bin"}, {"type", "box"}, {"material", "wall"}, {"min", {0, 0, 0}},
                          {"max", {0.03, 0.03, 0.2}}, {"open", {"zmax"}}});
  json ins = {{"model", "random"}, {"diameter", 0.003}, {"diameter_max", 0.0035}, {"count", 1500}};
  ins["region"]["box"] = {{"min", {0, 0, 0}}, {"max", {0.03, 0.03, 0.2}}};
  doc["subdomains"][0]["insert"] = json::array({ins});
  doc["subdomains"][0].erase("time_step");
  doc["subdomains"][0]["impact_velocity"] = 2.0;
  doc["run"] = {{"duration", 0.8}};
  doc["output"]["grids"] = {{{"name", "column"}, {"min", {0, 0, 0}}, {"max", {0.03, 0.03, 0.09}}, {"cells", {2, 2, 6}},
                             {"every", 15}, {"write_interval", 0}}};
  auto sim = domel::test::build(doc);
  domel::platform::RunOptions opt;
  opt.progress = false;
  opt.output_directory = ::testing::TempDir() + "/cell_stress_test";
  sim->run(opt, domel::test::builtin_registry());

  const auto& s = sim->subdomains[0]->store();
  double weight_moment = 0, volume = 0, top = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    weight_moment += 9.81 * s.mass[k] * s.z[k];
    volume += 4.0 / 3.0 * M_PI * std::pow(s.radius[k], 3);
    top = std::max(top, s.z[k]);
  }
  ASSERT_LT(top, 0.09) << "the column must fit the grid for the exact balance";
  const auto& grid = *sim->find<domel::platform::GridFiles>()->grids()[0];
  const auto& f = grid.latest();
  double virial_zz = 0, phi_volume = 0;
  for (std::size_t c = 0; c < grid.cell_count(); ++c) {
    const double vw = grid.cell_volume() * grid.accessible()[c];
    virial_zz += f.stress[9 * c + 8] * vw;
    phi_volume += f.volume_fraction[c] * vw;
  }
  EXPECT_NEAR(virial_zz, weight_moment, 0.02 * weight_moment);
  EXPECT_NEAR(phi_volume, volume, 1e-9 * volume);
  // the walls bound the grid: every cell is fully accessible
  for (double w : grid.accessible()) EXPECT_NEAR(w, 1.0, 1e-12);
  // the bottom layer is compressed, and more than the top one
  const auto prof = grid.profile(f, 2);
  EXPECT_GT(prof.pressure.front(), 0.0);
  EXPECT_GT(prof.pressure.front(), prof.pressure[prof.pressure.size() - 2]);
}

}  // namespace
