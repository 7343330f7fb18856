// Guards the named step phases (subdomain/step_phases.hpp) and the body-force
// list (subdomain/integrator.hpp): hooks run in phase order and see the step
// they belong to; a subdomain with hooks (the step completed in phase order)
// gives bit for bit the results of the fused, deferred fast path; post-force
// hooks see complete forces; the external force array and a post-force hook
// accelerate a particle as Newton's second law says (velocity Verlet is exact
// for a constant force, so the tolerance is round-off); failures name their
// place.
#include "support/fixture.hpp"

#include "core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace dt = domel::test;
using domel::platform::Phase;
using domel::platform::StepContext;
using domel::platform::StepHook;
using domel::platform::Subdomain;
using nlohmann::json;

namespace {

constexpr double kD = 0.0028;

/// A 10 x 10 x 20 lattice column settling in an open box (pairs and walls in contact).
json column() { return dt::lattice_column(kD); }

/// One free particle, no walls.
json single(double gz) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, gz};
  json insert = {{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.0}, {"jitter", 0.0}};
  insert["region"] = {{"box", {{"min", {0, 0, 0}}, {"max", {kD, kD, kD}}}}};
  doc["subdomains"][0]["insert"] = json::array({insert});
  return doc;
}

std::unique_ptr<domel::platform::Simulation> prepared(const json& doc, int threads) {
  auto sim = dt::build(doc);
  Subdomain& sd = *sim->subdomains[0];
  sd.set_threads(threads);
  sd.set_skin(0.5 * kD);
  sd.setup();
  return sim;
}

}  // namespace

TEST(StepPhases, EmptyHooksGiveTheFastPathsResultsBitForBit) {
  // 1500 steps: several list builds, far-tier screening, wall contacts.
  for (int threads : {1, 2, 3}) {
    auto fast = prepared(column(), threads);
    auto hooked = prepared(column(), threads);
    Subdomain& a = *fast->subdomains[0];
    Subdomain& b = *hooked->subdomains[0];
    b.add_hook(Phase::end_of_step, {"nothing", [](StepContext&) {}});
    for (int k = 0; k < 1500; ++k) {
      a.step_deferred();
      b.step_deferred();
    }
    const auto& p = a.store();
    const auto& q = b.store();
    ASSERT_EQ(p.size(), q.size());
    EXPECT_GT(a.neighbor_builds(), 1u);
    EXPECT_GT(a.stats().wall_contacts, 0u);
    for (std::size_t k = 0; k < p.size(); ++k) {
      ASSERT_EQ(p.x[k], q.x[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.y[k], q.y[k]);
      ASSERT_EQ(p.z[k], q.z[k]);
      ASSERT_EQ(p.vz[k], q.vz[k]);
      ASSERT_EQ(p.wx[k], q.wx[k]);
      ASSERT_EQ(p.fz[k], q.fz[k]);
    }
    EXPECT_EQ(a.stats().contacts, b.stats().contacts);
    EXPECT_EQ(a.stats().wall_contacts, b.stats().wall_contacts);
  }
}

TEST(StepPhases, TheFastPathFollowsAStoreReorderedAtAListBuild) {
  // The fused step copies the drifted positions for the pair screen
  // (PackedPositions) in its first sweep; a list build that re-orders the
  // store in between must not leave the screen the old order. 16 x 16 x 20
  // particles (re-ordering needs 5000 or more), re-ordered at every build;
  // the hooked path copies the positions right before the forces.
  json doc = column();
  const double a = 1.02 * kD;
  doc["walls"][0]["max"] = {16 * a, 16 * a, 40 * a};
  doc["subdomains"][0]["insert"][0]["region"]["box"]["max"] = {16 * a, 16 * a, 20 * a};
  for (int threads : {1, 2}) {
    auto fast = prepared(doc, threads);
    auto hooked = prepared(doc, threads);
    Subdomain& f = *fast->subdomains[0];
    Subdomain& h = *hooked->subdomains[0];
    f.set_reorder_every(1);
    h.set_reorder_every(1);
    h.add_hook(Phase::end_of_step, {"nothing", [](StepContext&) {}});
    for (int k = 0; k < 2500; ++k) {
      f.step_deferred();
      h.step_deferred();
    }
    const auto& p = f.store();
    const auto& q = h.store();
    ASSERT_EQ(p.size(), 5120u);
    std::printf("%d thread(s): %zu list builds, %zu contacts\n", threads, f.neighbor_builds(), f.stats().contacts);
    EXPECT_GT(f.neighbor_builds(), 2u);  // re-ordered after the first build too
    EXPECT_GT(f.stats().contacts, 1000u);
    for (std::size_t k = 0; k < p.size(); ++k) {
      ASSERT_EQ(p.id[k], q.id[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.x[k], q.x[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.z[k], q.z[k]);
      ASSERT_EQ(p.vz[k], q.vz[k]);
    }
    EXPECT_EQ(f.stats().contacts, h.stats().contacts);
  }
}

TEST(StepPhases, HooksRunInPhaseOrderAndSeeTheirStep) {
  auto sim = prepared(column(), 2);
  Subdomain& sd = *sim->subdomains[0];
  struct Call {
    Phase phase;
    std::uint64_t step;
    double time;
  };
  std::vector<Call> calls;
  for (std::size_t p = 0; p < domel::platform::kPhaseCount; ++p)
    sd.add_hook(static_cast<Phase>(p), {domel::platform::kPhaseNames[p], [&calls](StepContext& c) {
                                          calls.push_back({c.phase, c.step, c.time});
                                        }});
  sd.step();  // no rebuild: the lists are fresh from setup()
  // a new particle makes the layout stale: the next step exchanges and rebuilds
  auto& st = sd.store();
  st.add(999999, 5 * kD, 5 * kD, 60 * kD, 0.5 * kD, 2500.0);
  sd.apply_body_forces(st.size() - 1, st.size());
  sd.step();
  const std::vector<Phase> without_rebuild = {Phase::initial_integrate, Phase::ghost_update,     Phase::body_force,
                                              Phase::contact_force,     Phase::reverse_exchange, Phase::post_force,
                                              Phase::final_integrate,   Phase::end_of_step};
  std::vector<Phase> with_rebuild = without_rebuild;
  with_rebuild.insert(with_rebuild.begin() + 1, {Phase::exchange, Phase::neighbor});
  ASSERT_EQ(calls.size(), without_rebuild.size() + with_rebuild.size());
  for (std::size_t k = 0; k < without_rebuild.size(); ++k) {
    EXPECT_EQ(calls[k].phase, without_rebuild[k]) << k;
    EXPECT_EQ(calls[k].step, 0u);
    EXPECT_EQ(calls[k].time, 1e-5);  // the step's end, the time of its force evaluation
  }
  for (std::size_t k = 0; k < with_rebuild.size(); ++k) {
    const Call& c = calls[without_rebuild.size() + k];
    EXPECT_EQ(c.phase, with_rebuild[k]) << k;
    EXPECT_EQ(c.step, 1u);
    EXPECT_EQ(c.time, 1e-5 + 1e-5);
  }
  EXPECT_EQ(sd.steps(), 2u);
}

TEST(StepPhases, PostForceHooksSeeCompleteForces) {
  // The forces a post-force hook sees are those a complete step leaves in
  // the store (pairs summed over threads, walls added): compared bit for bit.
  for (int threads : {1, 2}) {
    auto plain = prepared(column(), threads);
    auto hooked = prepared(column(), threads);
    Subdomain& a = *plain->subdomains[0];
    Subdomain& b = *hooked->subdomains[0];
    std::vector<double> seen_fz, seen_tx;
    b.add_hook(Phase::post_force, {"copy forces", [&](StepContext& c) {
                                     const auto& s = c.store;
                                     seen_fz = s.fz;
                                     seen_tx = s.tx;
                                   }});
    for (int k = 0; k < 300; ++k) {
      a.step();
      b.step();
      const auto& s = a.store();
      ASSERT_EQ(s.fz.size(), seen_fz.size());
      for (std::size_t i = 0; i < s.size(); ++i) {
        ASSERT_EQ(s.fz[i], seen_fz[i]) << threads << " threads, step " << k << ", particle " << i;
        ASSERT_EQ(s.tx[i], seen_tx[i]);
      }
    }
  }
}

TEST(BodyForces, ExternalForceAndPostForceHookAccelerateAFreeParticle) {
  // One particle, gravity g and a constant extra force F: v(t) = (g + F/m) t
  // and z(t) = z0 + (g + F/m) t^2 / 2, exactly for velocity Verlet; 1e-12
  // relative covers the round-off of 1000 additions.
  const double g = -9.81, steps = 1000, dt = 1e-5, t = steps * dt;
  for (int way = 0; way < 3; ++way) {  // 0: gravity only, 1: external force array, 2: post-force hook
    auto sim = prepared(single(g), 1);
    Subdomain& sd = *sim->subdomains[0];
    auto& s = sd.store();
    ASSERT_EQ(s.size(), 1u);
    const double m = s.mass[0], f = 2.0 * m * 9.81, z0 = s.z[0];
    if (way == 1) {
      s.enable_external_force();
      s.ext_fz[0] = f;
      sd.apply_body_forces(0, 1);  // the forces of the current state include it
    }
    if (way == 2) {
      sd.add_hook(Phase::post_force, {"push", [f](StepContext& c) { c.store.fz[0] += f; }});
      // the forces of the current state include it, as after a complete step
      s.fz[0] += f;
    }
    for (int k = 0; k < steps; ++k) sd.step_deferred();
    const double a = g + (way == 0 ? 0.0 : f / m);
    const auto& e = sd.store();
    EXPECT_NEAR(e.vz[0], a * t, 1e-12 * std::fabs(a * t)) << way;
    EXPECT_NEAR(e.z[0] - z0, 0.5 * a * t * t, 1e-12 * std::fabs(0.5 * a * t * t) + 1e-18) << way;
    EXPECT_EQ(e.vx[0], 0.0);
  }
}

TEST(BodyForces, ExternalForceFollowsItsParticleThroughReordering) {
  // The external force array moves with the particles (permute, removal).
  domel::platform::ParticleStore s;
  for (int k = 0; k < 4; ++k) s.add(10 + k, k, 0, 0, 0.1, 1000.0);
  s.enable_external_force();
  for (int k = 0; k < 4; ++k) s.ext_fx[k] = 100.0 + k;
  s.permute({3, 2, 1, 0});
  EXPECT_EQ(s.id[0], 13u);
  EXPECT_EQ(s.ext_fx[0], 103.0);
  s.remove_marked({1, 0, 0, 0});
  EXPECT_EQ(s.id[0], 12u);
  EXPECT_EQ(s.ext_fx[0], 102.0);
  s.add(20, 0, 0, 0, 0.1, 1000.0);
  EXPECT_EQ(s.ext_fx.size(), s.size());
  EXPECT_EQ(s.ext_fx.back(), 0.0);
}

TEST(BodyForces, AuxArraysFollowTheirParticleThroughReorderingAndSwapRemove) {
  // A module's per-particle arrays (ParticleStore::add_aux; the fluid
  // coupling's drag) move with the particles; new particles get 0.
  domel::platform::ParticleStore s;
  for (int k = 0; k < 4; ++k) s.add(10 + k, k, 0, 0, 0.1, 1000.0);
  const std::size_t a = s.add_aux(2);
  EXPECT_EQ(a, 0u);
  EXPECT_EQ(s.add_aux(1), 2u);
  for (int k = 0; k < 4; ++k) s.aux[a + 1][k] = 200.0 + k;
  s.permute({3, 2, 1, 0});
  EXPECT_EQ(s.aux[a + 1][0], 203.0);
  s.swap_remove(0);  // the last (id 10) moves into slot 0
  EXPECT_EQ(s.id[0], 10u);
  EXPECT_EQ(s.aux[a + 1][0], 200.0);
  s.add(20, 0, 0, 0, 0.1, 1000.0);
  for (const auto& v : s.aux) ASSERT_EQ(v.size(), s.size());
  EXPECT_EQ(s.aux[a + 1].back(), 0.0);
}

TEST(StepPhases, AFailingHookNamesItselfAndItsPlace) {
  auto sim = prepared(column(), 1);
  Subdomain& sd = *sim->subdomains[0];
  sd.add_hook(Phase::post_force, {"bad controller", [](StepContext& c) {
                                    if (c.step == 2) throw std::runtime_error("no setpoint");
                                  }});
  sd.step();
  sd.step();
  try {
    sd.step();
    FAIL() << "the hook's failure was swallowed";
  } catch (const domel::platform::RuntimeError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("subdomain 'sd'"), std::string::npos) << m;
    EXPECT_NE(m.find("step 2"), std::string::npos) << m;
    EXPECT_NE(m.find("post_force hook 'bad controller' failed: no setpoint"), std::string::npos) << m;
  }
}

TEST(StepPhases, ANonFiniteParticleIsNamedWithItsState) {
  auto sim = prepared(single(-9.81), 1);
  Subdomain& sd = *sim->subdomains[0];
  const std::uint64_t id = sd.store().id[0];
  sd.store().vz[0] = std::nan("");
  try {
    sd.step();
    sd.step();
    FAIL() << "a NaN velocity went unnoticed";
  } catch (const domel::platform::RuntimeError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("subdomain 'sd'"), std::string::npos) << m;
    EXPECT_NE(m.find("particle id " + std::to_string(id)), std::string::npos) << m;
    EXPECT_NE(m.find("v = (0, 0, nan)"), std::string::npos) << m;
  }
}

TEST(StepPhases, CoincidingInitialParticlesAreNamedAtSetUp) {
  auto sim = dt::build(single(-9.81));
  Subdomain& sd = *sim->subdomains[0];
  auto& s = sd.store();
  s.add(777, s.x[0], s.y[0], s.z[0], s.radius[0], 2500.0);
  sd.set_initial_source("the state file 'bed.csv'");
  sd.set_skin(0.5 * kD);
  try {
    sd.setup();
    FAIL() << "coinciding particles went unnoticed";
  } catch (const domel::platform::RuntimeError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("is not finite"), std::string::npos) << m;
    EXPECT_NE(m.find("coincides with particle id"), std::string::npos) << m;
    EXPECT_NE(m.find("the state file 'bed.csv'"), std::string::npos) << m;
  }
}
