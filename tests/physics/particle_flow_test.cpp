// SPDX-License-Identifier: MIT
// Guards pours, deletion regions, mass-flow planes and the exact mass balance
// (issue 4, acceptance 3 and 5): a pour into an open-bottomed box at a mass
// rate, a floor removed at a set time, a deletion region below it and a
// mass-flow plane between them.
//
// Expected values and why:
//  - pouring: each event inserts until the cumulative mass reaches
//    mass_rate x (t - start + interval), so after every event the inserted
//    mass exceeds that target by less than one particle (the largest one,
//    d = 5 mm: 3.3e-4 kg) -- unless total_mass caps it, then the same bound
//    holds against total_mass. Exactly one event per interval.
//  - overlap-free insertion: no two new particles overlap, and none overlaps
//    a particle present (the pour region is refilled while earlier particles
//    are still falling through it).
//  - mass balance: inserted - present - removed is zero in the integer units
//    the platform keeps (1e-18 kg), at every stage, not merely to round-off.
//  - counting: every particle removed by the deletion region first crossed
//    the plane above it, so the plane's net mass equals the removed mass to
//    round-off of the summation order (1e-12 relative), and their counts agree exactly.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using domel::platform::mass_kg;
using nlohmann::json;

json pour_box(double total_mass, double end = 0.0) {
  json doc = domel::test::scenario(domel::test::hertz_mindlin(), 1e-5, 0.5, 0.5, 1e7);
  doc["gravity"] = {0, 0, -9.81};
  doc["walls"].push_back({{"name", "bin"}, {"type", "box"}, {"material", "m"}, {"min", {0, 0, 0}},
                          {"max", {0.04, 0.04, 0.2}}, {"open", {"zmin", "zmax"}}});
  doc["walls"].push_back({{"name", "floor"}, {"type", "plane"}, {"material", "m"}, {"point", {0, 0, 0}},
                          {"normal", {0, 0, 1}}, {"remove_at", 0.3}});
  doc["deletion_regions"] = {{{"name", "out"}, {"region", {{"box", {{"min", {-1, -1, -1}}, {"max", {1, 1, -0.01}}}}}}}};
  doc["output"]["mass_flow"] = {{{"name", "plane"}, {"point", {0, 0, -0.005}}, {"normal", {0, 0, -1}}}};
  doc["subdomains"][0].erase("time_step");
  doc["subdomains"][0]["impact_velocity"] = 2.0;
  json insert = {{"model", "random"}, {"diameter", 0.004}, {"diameter_max", 0.005}, {"volume_fraction", 0.2},
                 {"velocity", {0, 0, -1}}};
  insert["region"]["box"] = {{"min", {0.001, 0.001, 0.1}}, {"max", {0.039, 0.039, 0.15}}};
  json pour = {{"mass_rate", 0.5}, {"interval", 0.05}, {"total_mass", total_mass}};
  if (end > 0) pour["end"] = end;
  pour["insert"] = insert;
  doc["subdomains"][0]["pour"] = json::array({pour});
  doc["run"] = {{"duration", 0.5}};
  return doc;
}

/// Macro step `index` of a run whose one subdomain is `sd` (its step is the
/// macro step), as the run loop hands it to the flow.
domel::platform::MacroStep macro_step_at(const domel::platform::Subdomain& sd, std::uint64_t index) {
  domel::platform::MacroStep m;
  m.index = index;
  m.macro = sd.time_step();
  m.t = static_cast<double>(index) * m.macro;
  return m;
}

TEST(ParticleFlow, PourFollowsTheMassRateWithoutOverlapAndTheBalanceIsExact) {
  auto sim = domel::test::build(pour_box(1.0));  // no cap within the run
  auto& flow = sim->flow;
  auto& sd = *sim->subdomains[0];
  const double m_max = 2500.0 * M_PI / 6.0 * std::pow(0.005, 3);
  flow.start(sim->subdomains);
  sd.setup();
  for (int event = 0; event < 4; ++event) {
    const double t = sd.time();
    const std::size_t before = sd.store().size();
    flow.update(macro_step_at(sd, sd.steps()), sim->subdomains);
    ASSERT_EQ(flow.pours[0].events, static_cast<std::uint64_t>(event + 1));
    const double target = 0.5 * (t + 0.05);
    EXPECT_GE(flow.pours[0].inserted_mass, target);
    EXPECT_LT(flow.pours[0].inserted_mass, target + m_max);
    // the newly inserted particles overlap nobody
    const auto& s = sd.store();
    for (std::size_t i = before; i < s.size(); ++i)
      for (std::size_t j = 0; j < s.size(); ++j) {
        if (j == i) continue;
        const double dx = s.x[i] - s.x[j], dy = s.y[i] - s.y[j], dz = s.z[i] - s.z[j];
        ASSERT_GE(std::sqrt(dx * dx + dy * dy + dz * dz), s.radius[i] + s.radius[j] - 1e-12) << i << " " << j;
      }
    EXPECT_EQ(flow.residual(0, s), 0);
    // step to the next event
    while (sd.time() < t + 0.05 - 1e-9) sd.step();
    const std::size_t n = s.size();
    const auto early = static_cast<std::uint64_t>(1e-3 / sd.time_step());  // 1 ms before the event: not due
    flow.update(macro_step_at(sd, sd.steps() - early), sim->subdomains);   // nothing happens
    EXPECT_EQ(s.size(), n);
  }
}

TEST(ParticleFlow, PourStopsAtItsEndTime) {
  // end = 0.12 s with events at 0, 0.05, 0.1 s: the last event's target is
  // mass_rate x (end - start) = 0.06 kg, not mass_rate x (0.1 + interval).
  auto sim = domel::test::build(pour_box(1.0, 0.12));
  auto& sd = *sim->subdomains[0];
  sim->flow.start(sim->subdomains);
  sd.setup();
  while (sd.time() < 0.2) {
    sim->flow.update(macro_step_at(sd, sd.steps()), sim->subdomains);
    sd.step();
  }
  const double m_max = 2500.0 * M_PI / 6.0 * std::pow(0.005, 3);
  EXPECT_EQ(sim->flow.pours[0].events, 3u);
  EXPECT_GE(sim->flow.pours[0].inserted_mass, 0.06);
  EXPECT_LT(sim->flow.pours[0].inserted_mass, 0.06 + m_max);
}

TEST(ParticleFlow, MassUnitsAreExactAndDoNotOverflowForHeavyParcels) {
  using domel::platform::mass_units;
  EXPECT_TRUE(mass_units(20.0) == static_cast<domel::platform::MassUnits>(20) * 1000000000000000000LL);
  EXPECT_NEAR(mass_kg(mass_units(123.456789)), 123.456789, 1e-12);
  EXPECT_TRUE(mass_units(3e-5) == static_cast<domel::platform::MassUnits>(30000000000000LL));
}

TEST(ParticleFlow, DeletionRegionAndPlaneCountTheSameMassAndTheBalanceStaysExact) {
  auto sim = domel::test::build(pour_box(0.08));
  domel::platform::RunOptions opt;
  opt.progress = false;
  opt.output_directory = ::testing::TempDir() + "/particle_flow_test";
  const auto result = sim->run(opt, domel::test::builtin_registry());
  const json& s = result.summary;
  const json& bal = s["mass_balance"]["sd"];
  EXPECT_TRUE(bal["exact"].get<bool>());
  EXPECT_EQ(bal["residual_units_1e-18kg"].get<long long>(), 0);
  // total_mass caps the pour: within one particle above 0.08 kg
  EXPECT_GE(bal["inserted_kg"].get<double>(), 0.08);
  EXPECT_LT(bal["inserted_kg"].get<double>(), 0.08 + 2500.0 * M_PI / 6.0 * std::pow(0.005, 3));
  // the floor opened at 0.3 s; by 0.5 s everything has fallen 0.2 m+ and was removed
  EXPECT_EQ(bal["present"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(bal["removed"].get<std::uint64_t>(), bal["inserted"].get<std::uint64_t>());
  const double removed = s["deletion_regions"]["out"]["removed_kg"].get<double>();
  EXPECT_NEAR(removed, bal["inserted_kg"].get<double>(), 1e-12 * removed);
  EXPECT_EQ(s["mass_flow"]["plane"]["net_count"].get<long long>(),
            static_cast<long long>(s["deletion_regions"]["out"]["removed"].get<std::uint64_t>()));
  EXPECT_NEAR(s["mass_flow"]["plane"]["net_kg"].get<double>(), removed, 1e-12 * removed);
  EXPECT_NEAR(mass_kg(sim->flow.accounts()[0].removed), removed, 1e-12 * removed);
}

TEST(ParticleFlow, RegionMassCountsTheParticlesInsideItsRegion) {
  // output.region_mass: a region holding the whole bin counts every particle
  // present (the balance's inserted - removed, to summation round-off); the
  // bin's left half counts part of it; a speed limit counts no more.
  json doc = pour_box(0.08);
  doc["run"]["duration"] = 0.25;  // the floor is still there: everything poured is in the bin
  json bin = {{"box", {{"min", {0, 0, 0}}, {"max", {0.04, 0.04, 0.2}}}}};
  json left = {{"box", {{"min", {0, 0, 0}}, {"max", {0.02, 0.04, 0.2}}}}};
  doc["output"]["region_mass"] = {{{"name", "bin"}, {"region", bin}},
                                  {{"name", "left"}, {"region", left}},
                                  {{"name", "bin_at_rest"}, {"region", bin}, {"max_speed", 0.05}}};
  auto sim = domel::test::build(doc);
  domel::platform::RunOptions opt;
  opt.progress = false;
  opt.output_directory = ::testing::TempDir() + "/region_mass_test";
  const json s = sim->run(opt, domel::test::builtin_registry()).summary;
  const json& bal = s["mass_balance"]["sd"];
  const double present = bal["inserted_kg"].get<double>() - bal["removed_kg"].get<double>();
  ASSERT_GT(present, 0.07);
  const json& rm = s["region_mass"];
  EXPECT_NEAR(rm["bin"]["mass_kg"].get<double>(), present, 1e-12 * present);
  EXPECT_EQ(rm["bin"]["particles"].get<std::uint64_t>(), bal["present"].get<std::uint64_t>());
  const double half = rm["left"]["mass_kg"].get<double>();
  EXPECT_GT(half, 0.2 * present);
  EXPECT_LT(half, 0.8 * present);
  EXPECT_LE(rm["bin_at_rest"]["mass_kg"].get<double>(), rm["bin"]["mass_kg"].get<double>());
  EXPECT_GT(rm["bin_at_rest"]["particles"].get<std::uint64_t>(), 0u);
}

}  // namespace
