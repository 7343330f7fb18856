// SPDX-License-Identifier: MIT
// Guards the controller host (issue 40, item 3; coupling blocks
// `stress_control` and `velocity_control`, abi.h ABI 2.5): a controller
// block passes to the model's own schema as contact and fluid blocks do, so a
// third-party controller with parameters of its own names (abi_test_band's
// `gain` and `band`, family_plugins.cpp) is wired by a scenario and works;
// the coupling's derived values (the levels' time steps and steps per
// control interval, the interval, the grid, the inflow cells) reach the
// model through its setup, not as parameters; a bad parameter is refused at
// its JSON pointer, a setup the model refuses at the block's. Cost: three
// runs of 40 macro steps of 500 particles, well under a second.
#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"
#include "scheduler/simulation.hpp"

#include "log_capture.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace dp = domel::platform;
using domel::test::LogCapture;
using nlohmann::json;

namespace {

dp::PluginRegistry& registry() {
  static dp::PluginRegistry r;
  static bool loaded = false;
  if (!loaded) {
    r.load_directory(DOMEL_BINARY_DIR "/plugins");
    r.load(std::filesystem::path(DOMEL_ABI_GOOD_DIR) /
           (std::string(DOMEL_ABI_MODULE_PREFIX) + "family_plugins" + DOMEL_ABI_MODULE_SUFFIX));
    loaded = true;
  }
  return r;
}

constexpr double kD = 0.0028;        // particle diameter; the coarse parcels are 2 kD
constexpr double kDtFine = 1.8e-5;   // [s]
constexpr double kDtCoarse = 3.6e-5; // [s], the macro step
constexpr double kU = -0.1;          // [m/s] the fine level's velocity

/// No gravity, no walls: a coarse level (alpha 2) on a lattice filling
/// [0, 0.06]^3 at rest, and a fine level (alpha 1) on a lattice filling the
/// coupled region [0, 0.06]^2 x [0, 0.03] (2 x 2 x 1 cells, inflow face +z)
/// moving at kU along z. Lattice spacing 1.05 diameters: no contact within
/// a level, so each particle moves only by the controller's force. Control
/// every 15 fine steps, rounded up to 16 (8 macro steps); stress control off.
json scenario(const json& velocity_control) {
  json lattice = {{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.05}};
  json coarse_insert = lattice, fine_insert = lattice;
  coarse_insert["region"] = {{"box", {{"min", {0, 0, 0}}, {"max", {0.06, 0.06, 0.06}}}}};
  fine_insert["region"] = {{"box", {{"min", {0, 0, 0}}, {"max", {0.06, 0.06, 0.03}}}}};
  fine_insert["velocity"] = {0, 0, kU};
  return {{"name", "controller_host"},
          {"gravity", {0, 0, 0}},
          {"materials", {{"m", {{"density", 2500}, {"youngs_modulus", 5e6}, {"poisson_ratio", 0.3}}}}},
          {"interactions", {{{"materials", {"m", "m"}}, {"restitution", 0.5}, {"friction", 0.5}}}},
          {"subdomains",
           {{{"name", "coarse"}, {"material", "m"}, {"coarse_grain", 2}, {"time_step", kDtCoarse},
             {"insert", {coarse_insert}}},
            {{"name", "fine"}, {"material", "m"}, {"coarse_grain", 1}, {"time_step", kDtFine},
             {"insert", {fine_insert}}}}},
          {"couplings",
           {{{"name", "zone"},
             {"coarse", "coarse"},
             {"fine", "fine"},
             {"region", {{"min", {0, 0, 0}}, {"max", {0.06, 0.06, 0.03}}, {"cells", {2, 2, 1}}}},
             {"inflow_faces", {"+z"}},
             {"control_steps", 15},
             {"stress_control", {{"enabled", false}}},
             {"velocity_control", velocity_control}}}},
          {"run", {{"duration", 1.0}}},
          {"output", {{"vtk_interval", 0}, {"probe_interval", 0}}}};
}

std::string config_error(const json& doc) {
  try {
    dp::load_scenario(doc, "controller.json", registry());
  } catch (const dp::ConfigError& e) {
    return e.what();
  }
  return "";
}

/// Runs 40 macro steps: control calls at macro steps 8, 16, 24 and 32, each
/// force then held for 8 macro steps.
void run40(dp::Simulation& sim, const std::string& name) {
  dp::RunOptions o;
  o.output_directory = std::filesystem::temp_directory_path() /
                       ("domel_controller_host_" + name + "_" + std::to_string(::getpid()));
  o.progress = false;
  o.max_steps = 40;
  sim.run(o, registry());
  std::filesystem::remove_all(o.output_directory);
}

}  // namespace

// gain g pulls each coarse parcel in an occupied cell towards the fine
// cell's mean velocity u: call k (before macro step 8k) reads v and sets
// the force g m (u - v), which the host holds until the next call. Velocity
// Verlet applies a step's force in two half kicks, the second in that step
// and the first in the next, so each force acts from the second half of
// step 8k to the first half of step 8k + 8. The expected velocity is that
// recursion evaluated in the same order: round-off apart (1e-12 relative),
// the run must land on it.
namespace {
double expected_velocity(double gain, double u, double dt, int calls_every, int steps) {
  double v = 0.0, f = 0.0, f_prev = 0.0;
  for (int n = 0; n < steps; ++n) {
    if (n > 0 && n % calls_every == 0) f = gain * (u - v);
    v += 0.5 * dt * f_prev;
    v += 0.5 * dt * f;
    f_prev = f;
  }
  return v;
}
}  // namespace

TEST(ControllerHost, APluginControllerWithItsOwnParametersIsSetUpByTheHostAndWorks) {
  LogCapture log;
  const double gain = 100.0;
  auto sim = dp::load_scenario(scenario({{"model", "abi_test_band"}, {"gain", gain}, {"band", 0.0}}),
                               "controller.json", registry());
  ASSERT_EQ(sim->couplings.size(), 1u);
  const std::string text = log.text.str();
  // the derived values, through the setup: 16 fine steps of 1.8e-5 s and 8 coarse steps of 3.6e-5 s per
  // interval of 8 macro steps; the 2 x 2 x 1 grid, every cell touching the +z inflow face, pushed along -z
  auto g17 = [](double x) {  // as the plugin prints it
    char b[64];
    std::snprintf(b, sizeof b, "%.17g", x);
    return std::string(b);
  };
  EXPECT_NE(text.find("setup: gain 100 band 0 interval " + g17(8 * kDtCoarse) + " grid 2 2 1 (4 cells) inflow cells 4"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("setup: level 0 'fine' alpha 1 dt " + g17(kDtFine) + " steps 16"), std::string::npos) << text;
  EXPECT_NE(text.find("setup: level 1 'coarse' alpha 2 dt " + g17(kDtCoarse) + " steps 8"), std::string::npos)
      << text;
  for (int c = 0; c < 4; ++c)
    EXPECT_NE(text.find("setup: inflow cell " + std::to_string(c) + " direction 0 0 -1"), std::string::npos) << c;

  run40(*sim, "pull");
  const double want = expected_velocity(gain, kU, kDtCoarse, 8, 40);
  // about u (1 - (1 - g T)^4) of four whole intervals T: the last force has acted for 7.5 of its 8 steps
  EXPECT_NEAR(want, kU * (1 - std::pow(1 - gain * 8 * kDtCoarse, 4)), 0.02 * std::fabs(want));
  const dp::ParticleStore& s = sim->subdomains[0]->store();
  std::size_t inside = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_EQ(s.vx[k], 0.0);  // u_x = v_x = 0: within the band of 0, no force
    EXPECT_EQ(s.vy[k], 0.0);
    if (s.z[k] < 0.03) {
      ++inside;
      EXPECT_NEAR(s.vz[k], want, 1e-12 * std::fabs(want)) << k;
    } else {
      EXPECT_EQ(s.vz[k], 0.0) << k;  // outside the grid: never pushed
    }
  }
  EXPECT_GT(inside, 0u);
  EXPECT_NE(log.text.str().find("band call 4: pushed " + std::to_string(inside)), std::string::npos);
  EXPECT_EQ(log.text.str().find("band call 5"), std::string::npos);
}

// A band wider than every velocity difference (0.1 m/s) switches the law off.
TEST(ControllerHost, ABandWiderThanTheDifferencePushesNothing) {
  LogCapture log;
  auto sim = dp::load_scenario(scenario({{"model", "abi_test_band"}, {"gain", 100.0}, {"band", 0.2}}),
                               "controller.json", registry());
  run40(*sim, "band");
  for (double v : sim->subdomains[0]->store().vz) EXPECT_EQ(v, 0.0);
  EXPECT_NE(log.text.str().find("band call 4: pushed 0"), std::string::npos);
}

TEST(ControllerHost, BadControllerParametersAndRefusedSetupsNameTheirPointers) {
  std::string m = config_error(scenario({{"model", "abi_test_band"}, {"gian", 1.0}}));
  EXPECT_NE(m.find("at /couplings/0/velocity_control/gian: unknown property 'gian' (did you mean 'gain'?)"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("at /couplings/0/velocity_control: missing required property 'gain'"), std::string::npos) << m;

  m = config_error(scenario({{"model", "abi_test_band"}, {"gain", 1.0}, {"band", -0.1}}));
  EXPECT_NE(m.find("at /couplings/0/velocity_control/band:"), std::string::npos) << m;

  m = config_error(scenario({{"model", "velocity_pp"}}));
  EXPECT_NE(m.find("at /couplings/0/velocity_control/model: unknown controller model 'velocity_pp' (did you mean "
                   "'velocity_p'?)"),
            std::string::npos)
      << m;

  // the built-in models refuse, in their setup, cells beyond the coupling's grid
  json doc = scenario({{"model", "velocity_p"}, {"cells", {0, 7}}});
  m = config_error(doc);
  EXPECT_NE(m.find("/couplings/0/velocity_control"), std::string::npos) << m;
  EXPECT_NE(m.find("cells[1] = 7 lies outside the coupling's grid (2 x 2 x 1 = 4 cells"), std::string::npos) << m;

  doc = scenario({{"enabled", false}});
  doc["couplings"][0]["stress_control"] = {{"cells", {1}}};
  m = config_error(doc);
  EXPECT_NE(m.find("/couplings/0/stress_control"), std::string::npos) << m;
  EXPECT_NE(m.find("give 'cells' and 'directions' together"), std::string::npos) << m;

  // the keys the scenario used to invent for the built-in models are theirs no longer
  doc = scenario({{"model", "velocity_p"}, {"time_step", 1e-5}});
  m = config_error(doc);
  EXPECT_NE(m.find("at /couplings/0/velocity_control/time_step: unknown property 'time_step'"), std::string::npos)
      << m;
}
