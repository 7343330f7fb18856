// SPDX-License-Identifier: MIT
// Guards the fluid-coupler host (fluid/fluid_coupling.hpp; the scenario's
// `fluid` block; abi.h ABI 2.2) with the test couplers of family_plugins.cpp
// in whole runs: exchanges fall on macro-step boundaries shared by levels of
// different time steps; the linearised drag is refreshed every step (a
// particle reaches the exact steady velocity u + g tau of the discrete
// scheme); the held force is held; the interval-mean velocity the host hands
// over is the exact time average of the step velocities; a coupler built for
// ABI 2.1 (held force only, one level per call) works unchanged; a stable interval shorter than the
// coupling interval, and a drag relaxation time not longer than the step,
// stop the run naming the limit; fields are written as fluid.pvd; bad
// blocks are refused with their JSON pointers.
#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"
#include "scheduler/simulation.hpp"

#include "log_capture.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

namespace dp = domel::platform;
using nlohmann::json;

namespace {

dp::PluginRegistry& registry() {
  static dp::PluginRegistry r;
  static bool loaded = false;
  if (!loaded) {
    r.load_directory(DOMEL_BINARY_DIR "/plugins");
    for (const char* lib : {"family_plugins", "abi21_fluid"})
      r.load(std::filesystem::path(DOMEL_ABI_GOOD_DIR) /
             (std::string(DOMEL_ABI_MODULE_PREFIX) + lib + DOMEL_ABI_MODULE_SUFFIX));
    loaded = true;
  }
  return r;
}

/// Two subdomains far apart (time steps 1e-4 and 5e-5 s: macro step 1e-4
/// s), three spheres each, no walls, gravity -9.81 along z; the fluid
/// coupler `fluid` on both.
json scenario(const json& fluid, double duration = 0.3) {
  json doc = {
      {"name", "fluid_host"},
      {"gravity", {0, 0, -9.81}},
      {"materials", {{"m", {{"density", 2500}, {"youngs_modulus", 1e6}, {"poisson_ratio", 0.3}}}}},
      {"interactions", {{{"materials", {"m", "m"}}, {"restitution", 0.5}, {"friction", 0.5}}}},
      {"subdomains", json::array()},
      {"fluid", fluid},
      {"run", {{"duration", duration}}},
      {"output", {{"vtk_interval", 0}, {"probe_interval", 0}}}};
  const double dts[2] = {1e-4, 5e-5};
  const char* names[2] = {"slow", "fast"};
  for (int s = 0; s < 2; ++s)
    doc["subdomains"].push_back(
        {{"name", names[s]},
         {"material", "m"},
         {"time_step", dts[s]},
         {"insert",
          {{{"model", "lattice"},
            {"diameter", 0.002},
            {"spacing", 5.0},
            {"region", {{"box", {{"min", {0.0, s * 1.0, 0.0}}, {"max", {0.03, s * 1.0 + 0.01, 0.01}}}}}}}}}});
  return doc;
}

std::filesystem::path out_dir(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("domel_fluid_host_" + name + "_" + std::to_string(getpid()));
}

dp::RunResult run(dp::Simulation& sim, const std::string& name) {
  dp::RunOptions o;
  o.output_directory = out_dir(name);
  o.progress = false;
  std::filesystem::remove_all(o.output_directory);
  return sim.run(o, registry());
}

using domel::test::LogCapture;

std::string config_error(const json& doc) {
  try {
    dp::load_scenario(doc, "fluid.json", registry());
  } catch (const dp::ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The drag beta (u - v) refreshed every step with the step's velocity is an
// explicit relaxation v <- v + dt (g + (u - v)/tau) whose fixed point is
// exactly u + g tau; after 30 tau the start (rest) is forgotten to e^-30,
// 1e-13 of |u + g tau|, so the tolerance is round-off. Both levels, with
// their own time steps, reach it; the held force m a shifts it by a tau.
TEST(FluidHost, RefreshedDragReachesTheExactSteadyVelocityOnEveryLevel) {
  const double tau = 0.01;
  auto sim = dp::load_scenario(scenario({{"model", "abi_test_linear_drag"},
                                         {"interval", 1e-3},
                                         {"relaxation_time", tau},
                                         {"flow", {0.1, 0.0, 0.2}},
                                         {"held", {0.0, 0.5, 0.0}},
                                         {"write_interval", 0.1}}),
                               "fluid.json", registry());
  ASSERT_TRUE(sim->fluid);
  EXPECT_EQ(sim->fluid->spec().interval_macro, 10u);
  const dp::RunResult r = run(*sim, "steady");
  for (const auto& sd : sim->subdomains) {
    const dp::ParticleStore& s = sd->store();
    ASSERT_EQ(s.size(), 3u) << sd->name();
    for (std::size_t k = 0; k < s.size(); ++k) {
      EXPECT_NEAR(s.vx[k], 0.1, 1e-12) << sd->name();
      EXPECT_NEAR(s.vy[k], 0.5 * tau, 1e-12) << sd->name();
      EXPECT_NEAR(s.vz[k], 0.2 - 9.81 * tau, 1e-12) << sd->name();
    }
  }
  const json& f = r.summary["fluid"];
  EXPECT_EQ(f["exchanges"].get<int>(), 300);
  EXPECT_EQ(f["model"]["library"], "abi_families");
  EXPECT_EQ(f["limits"]["limit"], "test limit");
  // at rest in the steady state, the fluid carries the weight minus the held force
  const double m = 2500 * M_PI / 6 * 0.008e-6;
  EXPECT_NEAR(f["levels"][0]["net_fluid_force_N"][2].get<double>(), 3 * m * 9.81, 1e-9 * m);
  EXPECT_NEAR(f["levels"][0]["net_fluid_force_N"][1].get<double>(), 0.0, 1e-9 * m);
  // fields: one frame per output time plus the final one
  EXPECT_EQ(r.summary["outputs"]["fluid"], "fluid.pvd");
  EXPECT_TRUE(std::filesystem::exists(out_dir("steady") / "fluid.pvd"));
  EXPECT_TRUE(std::filesystem::exists(out_dir("steady") / "fluid_000000.vti"));
  std::filesystem::remove_all(out_dir("steady"));
}

// The mean velocity over an interval: in free fall (drag 1e-9 of gravity)
// the step velocities are v(t_n + dt/2), whose time average over [t - T, t]
// is exactly -g (t - T/2); at the first exchange it is the velocity then (0).
TEST(FluidHost, MeanVelocityIsTheTimeAverageOverTheInterval) {
  LogCapture log;
  auto sim = dp::load_scenario(
      scenario({{"model", "abi_test_linear_drag"}, {"interval", 1e-3}, {"relaxation_time", 1e9}}, 0.01), "fluid.json",
      registry());
  run(*sim, "mean");
  const std::string text = log.text.str();
  const std::regex line("exchange (\\d+) t ([-0-9.e]+) level (\\w+) v_mean_z ([-0-9.e]+) v_z ([-0-9.e]+)");
  int seen = 0;
  for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) {
    const double t = std::stod((*it)[2]), mean = std::stod((*it)[4]), now = std::stod((*it)[5]);
    const double expected = t == 0 ? 0.0 : -9.81 * (t - 0.5e-3);
    EXPECT_NEAR(mean, expected, 1e-10) << (*it)[0];
    EXPECT_NEAR(now, -9.81 * t, 1e-10) << (*it)[0];
    ++seen;
  }
  EXPECT_EQ(seen, 2 * 10) << text;  // two levels, exchanges at t = 0, 1, ..., 9 ms
  std::filesystem::remove_all(out_dir("mean"));
}

// A coupler built for ABI 2.1 (abi21_fluid.c: its table ends after
// `exchange`, it reads one level per call and gives a held force only) is
// called once per level, and its held force F_x = 0.5 m acts from the
// exchange's instant: after one interval T from rest, v_x = 0.5 T exactly
// on both levels (velocity Verlet with a constant force).
TEST(FluidHost, CouplerBuiltForAbi21IsCalledPerLevelAndItsForceIsHeld) {
  json doc = scenario({{"model", "abi21_push"}, {"interval", 1e-3}}, 1e-3);
  doc["gravity"] = {0, 0, 0};
  auto sim = dp::load_scenario(doc, "fluid.json", registry());
  ASSERT_TRUE(sim->fluid->spec().one_level_per_call);
  run(*sim, "held");
  for (const auto& sd : sim->subdomains)
    for (double v : sd->store().vx) EXPECT_NEAR(v, 0.5 * 1e-3, 1e-15) << sd->name();
  std::filesystem::remove_all(out_dir("held"));
}

// The coupler's limit of its initial state refuses the scenario before
// anything runs; a limit that drops during the run stops it, naming the limit.
TEST(FluidHost, IntervalLongerThanTheCouplersLimitIsRefusedOrStopsTheRun) {
  std::string m = config_error(scenario(
      {{"model", "abi_test_linear_drag"}, {"interval", 1e-3}, {"relaxation_time", 0.01}, {"max_interval", 4e-4}}));
  EXPECT_NE(m.find("at /fluid/interval: expected a coupling interval of at most 0.0004 s (test limit), found 0.001 s"),
            std::string::npos)
      << m;
  auto sim = dp::load_scenario(scenario({{"model", "abi_test_linear_drag"},
                                         {"interval", 1e-3},
                                         {"relaxation_time", 0.01},
                                         {"max_interval_later", 4e-4}}),
                               "fluid.json", registry());
  try {
    run(*sim, "limit");
    ADD_FAILURE() << "an interval above the coupler's limit ran";
  } catch (const dp::RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("/fluid/interval: the coupling interval 0.001 s is longer than the fluid's "
                                         "stable interval 0.0004 s at t = 0 s (test limit)"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(out_dir("limit"));
}

TEST(FluidHost, DragRelaxationTimeShorterThanTheStepStopsTheRun) {
  auto sim = dp::load_scenario(
      scenario({{"model", "abi_test_linear_drag"}, {"interval", 1e-3}, {"relaxation_time", 8e-5}}), "fluid.json",
      registry());
  try {
    run(*sim, "stiff");
    ADD_FAILURE() << "a drag stiffer than the time step ran";
  } catch (const dp::RuntimeError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("/fluid: the drag relaxation time m/beta = 8e-05 s of particle"), std::string::npos) << m;
    EXPECT_NE(m.find("in subdomain 'slow' is not longer than the subdomain's time step 0.0001 s"), std::string::npos)
        << m;
  }
  std::filesystem::remove_all(out_dir("stiff"));
}

TEST(FluidHost, BadFluidBlocksAreRefusedWithTheirPointers) {
  json doc = scenario({{"model", "abi_test_linear_drag"}, {"interval", 1e-3}, {"relaxation_tme", 0.01}});
  std::string m = config_error(doc);
  EXPECT_NE(m.find("at /fluid/relaxation_tme: unknown property 'relaxation_tme' (did you mean 'relaxation_time'?)"),
            std::string::npos)
      << m;

  doc = scenario({{"model", "abi_test_linear_drag"}, {"relaxation_time", 0.01}});
  m = config_error(doc);
  EXPECT_NE(m.find("at /fluid: missing required property 'interval'"), std::string::npos) << m;

  doc = scenario({{"model", "abi_test_lineardrag"}, {"interval", 1e-3}, {"relaxation_time", 0.01}});
  m = config_error(doc);
  EXPECT_NE(m.find("at /fluid/model: unknown fluid_coupler model 'abi_test_lineardrag' (did you mean "
                   "'abi_test_linear_drag'?)"),
            std::string::npos)
      << m;

  doc = scenario({{"model", "abi_test_linear_drag"},
                  {"interval", 1e-3},
                  {"relaxation_time", 0.01},
                  {"subdomains", {"slow", "fats"}}});
  m = config_error(doc);
  EXPECT_NE(m.find("at /fluid/subdomains/1: unknown subdomain 'fats' (did you mean 'fast'?)"), std::string::npos)
      << m;
}

// A coupler built before ABI 2.3 cannot save its state: checkpoints of a run
// that uses it are refused before anything runs, naming the model and the
// key, and a restart too (a controller without save_state is refused the
// same way, Simulation::why_no_checkpoint).
TEST(FluidHost, ACouplerThatCannotSaveItsStateRefusesCheckpointsNamingIt) {
  json doc = scenario({{"model", "abi21_push"}, {"interval", 1e-3}}, 1e-3);
  doc["run"]["checkpoint_interval"] = 5e-4;
  const std::string msg = config_error(doc);
  EXPECT_NE(msg.find("/run/checkpoint_interval"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'abi21_push'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("save_state"), std::string::npos) << msg;
  doc["run"].erase("checkpoint_interval");
  auto sim = dp::load_scenario(doc, "fluid.json", registry());
  dp::RunOptions o;
  o.output_directory = out_dir("nostate");
  o.progress = false;
  o.restart = out_dir("nostate") / "checkpoint.ckpt";
  try {
    sim->run(o, registry());
    ADD_FAILURE() << "a restart of a run whose coupler cannot load its state ran";
  } catch (const dp::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot restart"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'abi21_push'"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(out_dir("nostate"));
}
