// Guards "subdomains from day one" (issue 2): two independent subdomains in
// one scenario — different materials, contact laws and time steps, the
// finer one sub-cycling twice per macro step — evolve exactly as each does
// when run alone (bit-identical, since they share nothing but walls and
// gravity). Also checks each keeps its own coarse-grain ratio and time step.
#include "support/fixture.hpp"

#include <gtest/gtest.h>
#include <unistd.h>  // getpid: the 1- and 2-thread variants of a test may run at once

#include <filesystem>

namespace dt = domel::test;
using nlohmann::json;

namespace {

json column(const std::string& name, const std::string& material, const json& contact, double dt, double x0,
            double alpha) {
  const double d = 0.0028, a = 1.02 * d;
  json box = {{"min", {x0, 0.0, 0.0}}, {"max", {x0 + 6 * a, 6 * a, 10 * a}}};
  json insert = {{"model", "lattice"}, {"diameter", d}, {"spacing", 1.02}, {"jitter", 0.005}};
  insert["region"] = {{"box", box}};
  json sd = {{"name", name}, {"material", material}, {"coarse_grain", alpha}, {"contact", contact}, {"time_step", dt}};
  sd["insert"] = json::array({insert});
  return sd;
}

json two_level(bool a, bool b) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  doc["materials"]["soft"] = {{"density", 1500}, {"youngs_modulus", 1e6}, {"poisson_ratio", 0.25}};
  doc["interactions"].push_back({{"materials", {"soft", "soft"}}, {"restitution", 0.7}, {"friction", 0.3}});
  doc["interactions"].push_back({{"materials", {"soft", "m"}}, {"restitution", 0.6}, {"friction", 0.4}});
  doc["walls"] = {{{"name", "floor"}, {"type", "plane"}, {"material", "m"}, {"point", {0, 0, 0}}, {"normal", {0, 0, 1}}}};
  doc["subdomains"] = json::array();
  if (a) doc["subdomains"].push_back(column("hertz_level", "m", dt::hertz_mindlin(), 1e-5, 0.0, 1.0));
  if (b) doc["subdomains"].push_back(column("linear_level", "soft", dt::linear_spring(300.0), 5e-6, 0.05, 2.0));
  return doc;
}

void run(domel::platform::Simulation& sim, std::uint64_t macro_steps) {
  domel::platform::RunOptions opt;
  opt.output_directory = std::filesystem::temp_directory_path() / ("domel_subdomains_test_" + std::to_string(::getpid()));
  opt.progress = false;
  opt.max_steps = macro_steps;
  sim.run(opt, dt::builtin_registry());
  std::filesystem::remove_all(opt.output_directory);
}

void expect_same(const domel::platform::ParticleStore& p, const domel::platform::ParticleStore& q) {
  ASSERT_EQ(p.size(), q.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_EQ(p.x[k], q.x[k]);
    EXPECT_EQ(p.z[k], q.z[k]);
    EXPECT_EQ(p.vz[k], q.vz[k]);
    EXPECT_EQ(p.wy[k], q.wy[k]);
  }
}

}  // namespace

TEST(Subdomains, TwoIndependentLevelsMatchTheirSoloRuns) {
  auto both = dt::build(two_level(true, true));
  auto only_a = dt::build(two_level(true, false));
  auto only_b = dt::build(two_level(false, true));
  ASSERT_EQ(both->subdomains.size(), 2u);
  EXPECT_EQ(both->subdomains[0]->coarse_grain(), 1.0);
  EXPECT_EQ(both->subdomains[1]->coarse_grain(), 2.0);
  run(*both, 300);                // 300 macro steps of 1e-5 s
  run(*only_a, 300);              // same
  run(*only_b, 600);              // 600 steps of 5e-6 s
  EXPECT_EQ(both->subdomains[0]->steps(), 300u);
  EXPECT_EQ(both->subdomains[1]->steps(), 600u);
  EXPECT_EQ(both->subdomains[1]->time_step(), 5e-6);
  expect_same(both->subdomains[0]->store(), only_a->subdomains[0]->store());
  expect_same(both->subdomains[1]->store(), only_b->subdomains[0]->store());
  // and they did move: the columns fell under gravity
  EXPECT_LT(both->subdomains[0]->store().vz[0], 0.0);
}
