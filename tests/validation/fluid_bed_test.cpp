// SPDX-License-Identifier: MIT
// Guards case (c) of docs/validation/fluid.md at CI size (label "slow",
// about a minute and a half): 2187 glass beads of 1 mm in a 10 x 10 mm
// column with frictionless walls, air from a velocity inlet below, the
// built-in "vans" coupler with the Gidaspow law.
//  - At U = 0.3 m/s (about half of minimum fluidisation) the bed stays
//    packed and the pressure gradient inside it is Ergun's (1952) at
//    the void fraction the coupler deposited there, within 10 % (a random
//    packing's local eps varies over the 5 mm layers, and Ergun's gradient
//    moves 5 % per 1 % of eps).
//  - At U = 1.0 m/s (about 1.7 U_mf) the bed is fluidised and carries its
//    buoyant weight: the pressure drop sampled every 5 ms over 0.3-1.0 s
//    averages to the buoyant weight per area within 10 % (the column is 10
//    beads wide and slugs: single samples scatter by about 25 %, and 140
//    correlated samples leave a few per cent of sampling error).
#include "plugins/fluid/drag_laws.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

namespace dt = domel::test;
namespace dp = domel::platform;
namespace fl = domel::plugins::fluid;
using nlohmann::json;

namespace {

constexpr double kD = 1e-3, kRhoP = 2500, kRhoF = 1.2, kMu = 1.8e-5, kG = 9.81, kSide = 0.01;

json bed(double u, double duration) {
  json doc = dt::scenario(dt::hertz_mindlin(), 5e-6, 0.9, 0.3, 1e7, 0.3, kRhoP);
  doc["gravity"] = {0, 0, -kG};
  doc["materials"]["wall"] = {{"youngs_modulus", 1e7}, {"poisson_ratio", 0.3}};
  doc["interactions"].push_back({{"materials", {"m", "wall"}}, {"restitution", 0.9}, {"friction", 0.0}});
  doc["walls"] = {{{"name", "column"}, {"type", "box"}, {"material", "wall"}, {"min", {0, 0, 0}},
                   {"max", {kSide, kSide, 0.1}}, {"open", json::array()}}};
  json box = {{"min", {0, 0, 0}}, {"max", {kSide, kSide, 0.03}}};
  doc["subdomains"][0]["insert"] = json::array({json{{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.1},
                                                     {"jitter", 0.04}, {"seed", 3}, {"region", {{"box", box}}}}});
  json slip = {{"type", "slip_wall"}};
  doc["fluid"] = {{"model", "vans"},
                  {"interval", 1e-4},
                  {"grid", {{"min", {0, 0, 0}}, {"max", {kSide, kSide, 0.1}}, {"cells", {2, 2, 20}}}},
                  {"density", kRhoF},
                  {"viscosity", kMu},
                  {"drag", {{"law", "gidaspow"}}},
                  {"boundaries",
                   {{"x_min", slip}, {"x_max", slip}, {"y_min", slip}, {"y_max", slip},
                    {"z_min", {{"type", "velocity_inlet"}, {"velocity", {0, 0, u}}}},
                    {"z_max", {{"type", "pressure_outlet"}}}}},
                  {"initial_velocity", {0, 0, u}},
                  {"write_interval", 0}};
  doc["run"] = {{"duration", duration}};
  return doc;
}

struct Sample {
  double dp;        ///< inlet face to above the bed, less the gas's hydrostatic part [Pa]
  double eps;       ///< mean void fraction of the layers below the bed's top layer
  double gradient;  ///< -dp/dz between the centres of layers 1 and 2, less rho_f g [Pa/m]
  double eps_low;   ///< mean void fraction of layers 1 and 2
};

Sample sample(const dp::Simulation& sim) {
  domel_fluid_fields_v1 f{};
  sim.fluid->spec().model->fluid_fields(f);
  const double *p = nullptr, *e = nullptr;
  for (uint32_t k = 0; k < f.field_count; ++k) {
    if (std::strcmp(f.names[k], "pressure") == 0) p = f.data[k];
    if (std::strcmp(f.names[k], "void_fraction") == 0) e = f.data[k];
  }
  const uint32_t per = f.nx * f.ny;
  std::vector<double> pl(f.nz, 0.0), el(f.nz, 0.0);
  for (uint32_t k = 0; k < f.nz; ++k)
    for (uint32_t c = 0; c < per; ++c) pl[k] += p[k * per + c] / per, el[k] += e[k * per + c] / per;
  uint32_t top = 1;
  while (top + 1 < f.nz && el[top] <= 0.999) ++top;
  double eps = 0;
  for (uint32_t k = 0; k < top; ++k) eps += el[k] / top;
  const double z_top = (top + 0.5) * f.spacing[2];
  const double p_inlet = pl[0] + 0.5 * (pl[0] - pl[1]);  // extrapolated to the inlet face
  const double gradient = (pl[1] - pl[2]) / f.spacing[2] - kRhoF * kG;
  return {p_inlet - pl[top] - kRhoF * kG * z_top, eps, gradient, 0.5 * (el[1] + el[2])};
}

/// Runs the bed at superficial velocity u and averages samples taken every
/// 5 ms from t_from on.
Sample run_bed(double u, double duration, double t_from, std::size_t* particles, std::vector<double>* dps) {
  auto sim = dt::build(bed(u, duration));
  *particles = sim->subdomains[0]->store().size();
  const auto every = static_cast<std::uint64_t>(std::llround(5e-3 / sim->macro_step()));
  Sample mean{0, 0, 0, 0};
  int n = 0;
  dp::Simulation* raw = sim.get();
  sim->hooks.after.push_back([&](const dp::MacroStep& step) {
    if ((step.index + 1) % every != 0 || step.t < t_from) return;
    const Sample s = sample(*raw);
    mean.dp += s.dp, mean.eps += s.eps, mean.gradient += s.gradient, mean.eps_low += s.eps_low;
    dps->push_back(s.dp);
    ++n;
  });
  dp::RunOptions o;
  o.output_directory = std::filesystem::temp_directory_path() / ("domel_fbed_" + std::to_string(getpid()));
  o.progress = false;
  sim->run(o, dt::builtin_registry());
  std::filesystem::remove_all(o.output_directory);
  return {mean.dp / n, mean.eps / n, mean.gradient / n, mean.eps_low / n};
}

}  // namespace

TEST(FluidisedBed, PackedBelowAndCarriedAboveMinimumFluidisation) {
  std::size_t n = 0;
  std::vector<double> packed_dps, fluid_dps;
  const Sample packed = run_bed(0.3, 0.3, 0.2, &n, &packed_dps);
  const double weight = n * kRhoP * M_PI * kD * kD * kD / 6 * kG * (1 - kRhoF / kRhoP) / (kSide * kSide);
  // Ergun inside the packed bed: the gradient across the face between
  // layers 1 and 2 against Ergun's at those layers' mean void fraction. The
  // bed is four layers of 5 mm, the top one partly filled; the face above
  // the floor layer is not used: the drag of the particles next to the inlet
  // (whose face velocity is fixed) is deposited on it, so it carries more
  // than its share while the bed's total is kept.
  const double ergun = fl::ergun_pressure_gradient(0.3, packed.eps_low, kD, kRhoF, kMu);
  std::printf("[fluidised bed] %zu beads, buoyant weight / area %.1f Pa\n", n, weight);
  std::printf("[fluidised bed] U = 0.3 m/s: dp %.1f Pa; inside the bed eps %.3f, -dp/dz %.0f Pa/m, Ergun %.0f Pa/m "
              "(%+.1f %%)\n",
              packed.dp, packed.eps_low, packed.gradient, ergun, 100 * (packed.gradient / ergun - 1));
  EXPECT_NEAR(packed.gradient, ergun, 0.10 * ergun);
  EXPECT_LT(packed.dp, 0.6 * weight);  // not fluidised

  const Sample fluid = run_bed(1.0, 1.0, 0.3, &n, &fluid_dps);
  double lo = fluid_dps.front(), hi = lo;
  for (double v : fluid_dps) lo = std::min(lo, v), hi = std::max(hi, v);
  std::printf("[fluidised bed] U = 1.0 m/s: dp %.1f Pa (%zu samples, %.1f-%.1f), %.3f of the weight, eps %.3f\n",
              fluid.dp, fluid_dps.size(), lo, hi, fluid.dp / weight, fluid.eps);
  EXPECT_NEAR(fluid.dp, weight, 0.10 * weight);
  EXPECT_GT(fluid.eps, packed.eps + 0.03);  // the bed has expanded
}
