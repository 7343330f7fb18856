// SPDX-License-Identifier: MIT
// Guards the coupling between levels (issue 14; coupling/coupling.hpp,
// docs/multilevel.md): coarse parcels crossing an inflow face are counted
// once by that face, with their mass, and become (alpha_c/alpha_f)^3 fine particles each,
// placed without overlap in the shell behind the face with the face's
// mass-weighted velocity; what cannot be placed waits as backlog; fine
// particles leaving the region are removed and booked to the face they
// crossed; the mass books close exactly; and in a run every exchange happens
// when all levels stand at the same time, on a step of each.
#include "coupling/coupling.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>  // getpid: the 1- and 2-thread variants of a test may run at once

namespace dt = domel::test;
namespace dp = domel::platform;
using nlohmann::json;

namespace {

constexpr double kD = 0.0028;  // fine diameter; coarse parcels are 2 kD
constexpr double kPi = 3.14159265358979323846;

/// A coarse level (alpha 2) on a lattice over [0, 0.06]^2 x [0.06, 0.12]
/// and an empty fine level (alpha 1) coupled on the box [0, 0.06]^2 x
/// [0, 0.03] with +z as inflow face, controllers off (they are tested on
/// their own), a transfer at every control interval. The lattice is built
/// above the fine region (a scenario may not start with parcels inside it);
/// make() lowers it by kLift to fill [0, 0.06]^3, the region full of parcels
/// as during a run.
constexpr double kLift = 0.06;
json two_level(double gravity = 0.0) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1.8e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, gravity};
  json coarse = {{"name", "coarse"}, {"material", "m"}, {"coarse_grain", 2}, {"contact", dt::hertz_mindlin()},
                 {"time_step", 3.6e-5}};
  coarse["insert"] = {{{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.05},
                       {"region", {{"box", {{"min", {0, 0, kLift}}, {"max", {0.06, 0.06, 0.06 + kLift}}}}}}}};
  json fine = {{"name", "fine"}, {"material", "m"}, {"coarse_grain", 1}, {"contact", dt::hertz_mindlin()},
               {"time_step", 1.8e-5}};
  doc["subdomains"] = {coarse, fine};
  doc["couplings"] = {{{"name", "zone"},
                       {"coarse", "coarse"},
                       {"fine", "fine"},
                       {"region", {{"min", {0, 0, 0}}, {"max", {0.06, 0.06, 0.03}}, {"cells", {2, 2, 1}}}},
                       {"inflow_faces", {"+z"}},
                       {"transfer_max_steps", 1},
                       {"stress_control", {{"enabled", false}}},
                       {"velocity_control", {{"enabled", false}}}}};
  return doc;
}

struct Levels {
  std::unique_ptr<dp::Simulation> sim;
  dp::Coupling* c = nullptr;
  dp::ParticleStore& coarse() { return sim->subdomains[0]->store(); }
  dp::ParticleStore& fine() { return sim->subdomains[1]->store(); }
  void exchange(double t) { c->exchange(t, sim->subdomains, sim->walls, sim->flow); }
};

Levels make(const json& doc) {
  Levels s;
  s.sim = dt::build(doc);
  for (double& z : s.sim->subdomains[0]->store().z) z -= kLift;
  s.sim->flow.start(s.sim->subdomains);
  s.c = s.sim->couplings.at(0).get();
  s.c->start(s.sim->subdomains, s.sim->walls, {});
  return s;
}

/// Indices of `n` coarse parcels whose centre lies above the region.
std::vector<std::size_t> above(const dp::ParticleStore& s, std::size_t n) {
  std::vector<std::size_t> out;
  for (std::size_t q = 0; q < s.size() && out.size() < n; ++q)
    if (s.z[q] > 0.04) out.push_back(q);
  return out;
}

dp::MassUnits fine_mass_units(const dp::ParticleStore& s) {
  dp::MassUnits u = 0;
  for (double m : s.mass) u += dp::mass_units(m);
  return u;
}

}  // namespace

TEST(Coupling, CountsEachParcelOnceAndInsertsItsFineParticlesInTheShell) {
  Levels s = make(two_level());
  const auto& spec = s.c->spec();
  EXPECT_DOUBLE_EQ(spec.shell_depth, 2 * 2 * kD);  // default: 2 coarse diameters
  auto& c = s.coarse();
  const auto moved = above(c, 5);
  ASSERT_EQ(moved.size(), 5u);
  // five parcels cross +z; distinct velocities, so the mass-weighted mean is checkable
  double mass = 0, mom[3] = {0, 0, 0};
  dp::MassUnits units = 0;
  for (std::size_t k = 0; k < moved.size(); ++k) {
    const std::size_t q = moved[k];
    c.z[q] = 0.025;
    c.vx[q] = 0.1 * k;
    c.vy[q] = -0.05;
    c.vz[q] = -0.5 - 0.1 * k;
    mass += c.mass[q];
    units += dp::mass_units(c.mass[q]);
    mom[0] += c.mass[q] * c.vx[q];
    mom[1] += c.mass[q] * c.vy[q];
    mom[2] += c.mass[q] * c.vz[q];
  }
  // one parcel enters through -x, which is not an inflow face: first outside, then in
  const std::size_t side = above(c, 6).back();
  c.x[side] = -0.01;
  c.z[side] = 0.01;
  s.exchange(1e-3);
  c.x[side] = 0.01;
  s.exchange(2e-3);

  const dp::FaceBalance& top = s.c->faces()[5];
  EXPECT_EQ(top.parcels, 5u);
  EXPECT_EQ(top.counted, units);
  // alpha_c/alpha_f = 2: 8 fine particles of diameter kD per parcel, all placed in a shell this empty
  auto& f = s.fine();
  EXPECT_EQ(top.n_inserted, 40u);
  EXPECT_EQ(f.size(), 40u);
  EXPECT_EQ(top.queue.size(), 0u);
  EXPECT_EQ(top.inserted, fine_mass_units(f));
  // the parcel's mass, split in 8: what is left pending is round-off of the radius scaling only
  EXPECT_LT(std::fabs(dp::mass_kg(top.pending())), 1e-12 * mass);
  for (std::size_t q = 0; q < f.size(); ++q) {
    EXPECT_NEAR(f.radius[q], kD / 2, 1e-15);
    // entirely inside the shell [0.03 - L, 0.03] and the region's lateral extent
    EXPECT_GE(f.z[q] - f.radius[q], 0.03 - spec.shell_depth - 1e-12);
    EXPECT_LE(f.z[q] + f.radius[q], 0.03 + 1e-12);
    EXPECT_GE(f.x[q] - f.radius[q], -1e-12);
    EXPECT_LE(f.x[q] + f.radius[q], 0.06 + 1e-12);
    EXPECT_NEAR(f.vx[q], mom[0] / mass, 1e-12);
    EXPECT_NEAR(f.vy[q], mom[1] / mass, 1e-12);
    EXPECT_NEAR(f.vz[q], mom[2] / mass, 1e-12);
    for (std::size_t p = 0; p < q; ++p) {
      const double d = std::hypot(f.x[q] - f.x[p], f.y[q] - f.y[p], f.z[q] - f.z[p]);
      EXPECT_GE(d, f.radius[q] + f.radius[p]) << "fine particles " << p << " and " << q << " overlap";
    }
  }
  // leave and come back: counted once
  c.z[moved[0]] = 0.05;
  s.exchange(3e-3);
  c.z[moved[0]] = 0.02;
  s.exchange(4e-3);
  EXPECT_EQ(top.parcels, 5u);
  EXPECT_EQ(s.sim->flow.residual(1, f), 0);
}

// Each inflow face is a counting surface of its own, as each of LIGGGHTS-PFM's
// massflow/mesh/face fixes counts once on its own (docs/multilevel.md): a
// parcel that came in through the top and bounces back up through the bottom
// (off a bed below the region) is counted by the bottom face too, once.
// The inflow places no fine particle overlapping a wall, a mesh included (it
// asks the same WallClearance as insertions and pours, issue 41): a flat STL
// surface of two triangles, tilted by 0.2 across the inflow shell
// [0.0188, 0.03] m, cuts it in two. The fine particles of five parcels go
// where they clear it; the distance to the surface is the plane's, written
// out here (the triangles cover the region's whole extent). Cost: 0.1 s.
TEST(Coupling, TheInflowPlacesNothingOverlappingAMeshWall) {
  json doc = two_level();
  const std::string stl = (std::filesystem::temp_directory_path() /
                           ("domel_inflow_mesh_" + std::to_string(getpid()) + ".stl")).string();
  auto z_of = [](double x) { return 0.024 + 0.2 * (x - 0.03); };  // the surface z(x), flat along y
  {
    std::ofstream out(stl);
    const double x0 = -0.1, x1 = 0.16, y0 = -0.02, y1 = 0.08;  // z from -0.002 to 0.05: it spans the region
    auto vertex = [&](double x, double y) { out << "      vertex " << x << " " << y << " " << z_of(x) << "\n"; };
    out << "solid tilted\n";
    for (int t = 0; t < 2; ++t) {
      out << "  facet normal 0 0 1\n    outer loop\n";
      if (t == 0) { vertex(x0, y0); vertex(x1, y0); vertex(x1, y1); }
      else { vertex(x0, y0); vertex(x1, y1); vertex(x0, y1); }
      out << "    endloop\n  endfacet\n";
    }
    out << "endsolid tilted\n";
  }
  doc["walls"] = {{{"name", "tilted"}, {"type", "mesh"}, {"material", "m"}, {"file", stl}}};
  Levels s = make(doc);
  std::filesystem::remove(stl);
  auto& c = s.coarse();
  const auto moved = above(c, 5);
  ASSERT_EQ(moved.size(), 5u);
  for (std::size_t q : moved) {
    c.z[q] = 0.025;
    c.vz[q] = -0.5;
  }
  s.exchange(1e-3);
  const dp::FaceBalance& top = s.c->faces()[5];
  auto& f = s.fine();
  const double n = std::hypot(0.2, 1.0);  // the surface's normal (-0.2, 0, 1) / n
  double closest = INFINITY;
  std::size_t below = 0;
  for (std::size_t q = 0; q < f.size(); ++q) {
    const double d = std::fabs(f.z[q] - z_of(f.x[q])) / n;
    closest = std::min(closest, (d - f.radius[q]) / f.radius[q]);
    below += f.z[q] < z_of(f.x[q]) ? 1 : 0;
  }
  std::printf("[inflow beside a mesh] %zu fine particles placed (%zu under the surface), least clearance %.3g "
              "radii, %zu waiting\n", f.size(), below, closest, top.queue.size());
  EXPECT_EQ(top.parcels, 5u);
  EXPECT_GT(f.size(), 10u);  // the shell has room on both sides of the surface
  EXPECT_GE(closest, -1e-9);
  // nothing lost: what is not placed waits in the backlog
  EXPECT_EQ(top.n_inserted + top.queue.size(), 40u);
  EXPECT_EQ(top.inserted, fine_mass_units(f));
}

// A region far longer than the level it couples (1e6 m along x, found by the
// run-time fuzzer, docs/reliability.md): the inflow's hash of the fine
// particles sized its 4 mm cells by the region's extent and asked for 2.5e8 x
// 17 x 5 of them (an allocation of 870 GB under the sanitizers). Its cells now
// grow until there are at most 4e6; the five parcels' fine particles are
// placed as in a region of the level's own size. Cost: 0.1 s.
TEST(Coupling, TheInflowOfARegionFarLongerThanItsLevelPlacesItsParticles) {
  json doc = two_level();
  doc["couplings"][0]["region"]["max"] = {1e6, 0.06, 0.03};
  Levels s = make(doc);
  auto& c = s.coarse();
  const auto moved = above(c, 5);
  ASSERT_EQ(moved.size(), 5u);
  for (std::size_t q : moved) {
    c.z[q] = 0.025;
    c.vz[q] = -0.5;
  }
  s.exchange(1e-3);
  const dp::FaceBalance& top = s.c->faces()[5];
  auto& f = s.fine();
  std::printf("[inflow, region 1e6 m long] %zu fine particles placed, %zu waiting\n", f.size(), top.queue.size());
  EXPECT_EQ(top.parcels, 5u);
  EXPECT_GT(f.size(), 10u);
  EXPECT_EQ(top.n_inserted + top.queue.size(), 40u);
  EXPECT_EQ(top.inserted, fine_mass_units(f));
}

TEST(Coupling, EachInflowFaceCountsAParcelOnce) {
  json doc = two_level();
  doc["couplings"][0]["inflow_faces"] = {"+z", "-z"};
  Levels s = make(doc);
  auto& c = s.coarse();
  const std::size_t q = above(c, 1).back();
  const dp::FaceBalance& top = s.c->faces()[5];
  const dp::FaceBalance& bottom = s.c->faces()[4];
  double t = 0;
  auto move_to = [&](double z) {
    c.z[q] = z;
    s.exchange(t += 1e-3);
  };
  move_to(0.025);  // in through the top
  EXPECT_EQ(top.parcels, 1u);
  EXPECT_EQ(bottom.parcels, 0u);
  move_to(-0.005);  // out through the bottom...
  move_to(0.005);   // ...and back in through it
  EXPECT_EQ(bottom.parcels, 1u);
  EXPECT_EQ(bottom.counted, dp::mass_units(c.mass[q]));
  for (int k = 0; k < 2; ++k) {  // again through each face: neither counts it twice
    move_to(-0.005);
    move_to(0.005);
    move_to(0.035);
    move_to(0.025);
  }
  EXPECT_EQ(top.parcels, 1u);
  EXPECT_EQ(bottom.parcels, 1u);
  EXPECT_EQ(s.sim->flow.residual(1, s.fine()), 0);
}

TEST(Coupling, RemovesFineParticlesThatLeaveAndBooksTheFaceTheyCrossed) {
  Levels s = make(two_level());
  auto& c = s.coarse();
  for (std::size_t q : above(c, 2)) c.z[q] = 0.02;
  s.exchange(1e-3);
  auto& f = s.fine();
  ASSERT_EQ(f.size(), 16u);
  const double m_out_x = f.mass[0], m_out_z = f.mass[1];
  f.x[0] = 0.0601;   // beyond +x
  f.z[1] = -0.0005;  // beyond -z
  f.x[2] = 0.03;     // still inside
  s.exchange(2e-3);
  const auto& faces = s.c->faces();
  EXPECT_EQ(faces[1].n_removed, 1u);
  EXPECT_EQ(faces[1].removed, dp::mass_units(m_out_x));
  EXPECT_EQ(faces[4].n_removed, 1u);
  EXPECT_EQ(faces[4].removed, dp::mass_units(m_out_z));
  EXPECT_EQ(f.size(), 14u);
  EXPECT_EQ(s.sim->flow.residual(1, f), 0);
}

TEST(Coupling, WhatCannotBePlacedWaitsAsBacklog) {
  json doc = two_level();
  // a fine bed packed on a cubic lattice right up to the face: no room in the shell
  doc["subdomains"][1]["insert"] = {{{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.0},
                                     {"region", {{"box", {{"min", {0, 0, 0.0}}, {"max", {0.06, 0.06, 0.03}}}}}}}};
  Levels s = make(doc);
  const std::size_t before = s.fine().size();
  for (std::size_t q : above(s.coarse(), 3)) s.coarse().z[q] = 0.02;
  s.exchange(1e-3);
  const dp::FaceBalance& top = s.c->faces()[5];
  EXPECT_EQ(top.n_inserted, 0u);
  EXPECT_EQ(top.backlog, 24u);
  EXPECT_EQ(top.queue.size(), 24u);
  EXPECT_EQ(top.pending(), top.counted);
  EXPECT_EQ(s.fine().size(), before);
  // the backlog waits: the next transfer tries again, and places nothing either
  s.exchange(2e-3);
  EXPECT_EQ(top.backlog, 24u);
  EXPECT_EQ(top.n_inserted, 0u);
}

TEST(Coupling, MatchOutflowRemovesTheLowestCoarseParcelsWhileTheFineLevelDischargedMore) {
  json doc = two_level(-9.81);
  doc["couplings"][0]["match_outflow"] = true;
  Levels s = make(doc);
  auto& c = s.coarse();
  for (std::size_t q : above(c, 2)) c.z[q] = 0.02;
  s.exchange(1e-3);
  auto& f = s.fine();
  ASSERT_EQ(f.size(), 16u);
  const double mf = f.mass[0], mc = 8 * mf;  // alpha 2 over alpha 1: a parcel is 8 fine particles
  // the lowest parcel in the region, and one below the region (outside it: never a candidate)
  std::size_t lowest = 0, below = 1;
  for (std::size_t q = 0; q < c.size(); ++q)
    if (c.z[q] < 0.01) { lowest = q; break; }
  for (std::size_t q = lowest + 1; q < c.size(); ++q)
    if (c.z[q] < 0.01) { below = q; break; }
  c.z[lowest] = 0.0005;
  c.z[below] = -0.004;  // left the region by itself through -z: the coarse level discharged one parcel
  // one bounces out through the inflow face +z: the transfer's business (it comes back), not a discharge
  std::size_t bounced = 0;
  for (std::size_t q = 0; q < c.size(); ++q)
    if (q != lowest && q != below && c.z[q] > 0.015 && c.z[q] < 0.03) { bounced = q; break; }
  c.z[bounced] = 0.035;
  const std::uint64_t lowest_id = c.id[lowest];
  s.exchange(2e-3);
  const auto& out = s.c->outflow();
  EXPECT_EQ(out.coarse, dp::mass_units(mc));
  EXPECT_EQ(out.n_sink, 0u);
  EXPECT_NEAR(out.deficit(), -mc, 1e-12 * mc);
  // the fine level discharges 11 particles through -z: 11/8 parcels, 3/8 beyond the coarse discharge, under
  // half a parcel; one more leaves through the inflow face +z and is not a discharge
  for (std::size_t q = 0; q < 11; ++q) f.z[q] = -0.0005;
  f.z[11] = 0.0305;
  s.exchange(3e-3);
  EXPECT_EQ(s.c->faces()[5].n_removed, 1u);
  EXPECT_EQ(out.fine, 11 * dp::mass_units(mf));
  EXPECT_EQ(out.n_sink, 0u);
  EXPECT_NEAR(out.deficit(), 3 * mf, 1e-9 * mf);
  // two more: 5/8 of a parcel owed, so the lowest parcel in the region goes and 3/8 is owed back
  const std::size_t n_coarse = c.size();
  f.z[0] = -0.0005;
  f.z[1] = -0.0005;
  s.exchange(4e-3);
  EXPECT_EQ(out.n_sink, 1u);
  EXPECT_EQ(out.sink, dp::mass_units(mc));
  EXPECT_NEAR(out.deficit(), -3 * mf, 1e-9 * mf);
  ASSERT_EQ(c.size(), n_coarse - 1);
  for (std::size_t q = 0; q < c.size(); ++q) EXPECT_NE(c.id[q], lowest_id) << "the lowest parcel is still there";
  // the removed parcel is booked once, as the sink's: no second loss when it is missed at the next count
  s.exchange(5e-3);
  EXPECT_EQ(out.coarse, dp::mass_units(mc));
  EXPECT_EQ(out.sink, dp::mass_units(mc));
  // the books of both levels close exactly
  EXPECT_EQ(out.fine, 13 * dp::mass_units(mf));
  EXPECT_EQ(out.coarse, dp::mass_units(mc));
  EXPECT_EQ(s.sim->flow.residual(0, c), 0);
  EXPECT_EQ(s.sim->flow.residual(1, f), 0);
}

TEST(Coupling, ExchangesHappenWhenAllLevelsStandAtTheSameTime) {
  json doc = two_level(-9.81);
  doc["couplings"][0]["control_steps"] = 15;  // 16 fine steps = 8 macro steps of 3.6e-5 s
  doc["couplings"][0].erase("stress_control");
  doc["couplings"][0].erase("velocity_control");
  auto sim = dt::build(doc);
  ASSERT_EQ(sim->control_macro, 8u);
  const auto& spec = sim->couplings[0]->spec();
  EXPECT_EQ(spec.fine_steps, 16);
  EXPECT_EQ(spec.coarse_steps, 8);
  // the controllers are created with their blocks' parameters only (their schemas' defaults filled in):
  // the gains 1/N and the time steps come from their setup (tests/unit/plugins/controller_test.cpp)
  for (const char* invented : {"kp", "ki", "cells", "directions", "limit_horizon"})
    EXPECT_FALSE(spec.stress.params.contains(invented)) << invented;
  for (const char* invented : {"kp", "cells", "time_step"})
    EXPECT_FALSE(spec.velocity.params.contains(invented)) << invented;
  EXPECT_EQ(spec.velocity.params["ki"], 0);  // velocity_p's own default
  EXPECT_EQ(spec.stress.params["layer_diameters"], 1.4);
  EXPECT_EQ(spec.velocity.params["mass_flow_correction"], true);
  // What each level's clock says at every exchange (a component registered
  // last acts just after the couplings, before the levels step).
  std::vector<std::array<double, 4>> seen;  // t, t_fine, t_coarse, fine steps
  std::uint64_t calls_seen = 0;
  sim->add(std::make_unique<dp::HookComponent>(
      [&](const dp::MacroStep& m) {
        if (sim->couplings[0]->control_calls() == calls_seen) return;  // no exchange at this macro step
        calls_seen = sim->couplings[0]->control_calls();
        auto& sds = *m.subdomains;
        seen.push_back({m.t, sds[1]->time(), sds[0]->time(), static_cast<double>(sds[1]->steps())});
      },
      nullptr));
  dp::RunOptions opt;
  opt.output_directory = std::filesystem::temp_directory_path() / ("domel_coupling_test_" + std::to_string(::getpid()));
  opt.progress = false;
  opt.max_steps = 41;
  sim->run(opt, dt::builtin_registry());
  std::filesystem::remove_all(opt.output_directory);
  ASSERT_EQ(seen.size(), 5u);  // m = 8, 16, 24, 32, 40
  EXPECT_EQ(sim->couplings[0]->control_calls(), 5u);
  for (std::size_t k = 0; k < seen.size(); ++k) {
    EXPECT_NEAR(seen[k][1], seen[k][0], 1e-12) << "fine level not at the exchange time";
    EXPECT_NEAR(seen[k][2], seen[k][0], 1e-12) << "coarse level not at the exchange time";
    EXPECT_EQ(seen[k][3], 16.0 * (k + 1));
    EXPECT_NEAR(seen[k][0], 8.0 * (k + 1) * 3.6e-5, 1e-12) << "an exchange off the control clock";
  }
  EXPECT_NEAR(sim->couplings[0]->last_exchange_time(), 40 * 3.6e-5, 1e-12);
  // and the cell averages the controllers read were sampled at that time (Coupling::control checks it)
}

TEST(Coupling, NestsThreeLevels) {
  // alpha 4 everywhere (a falling lattice block), alpha 2 in the lower half,
  // alpha 1 in the lower quarter: material must pass 4 -> 2 -> 1.
  json doc = dt::scenario(dt::hertz_mindlin(), 1.8e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  auto level = [&](const char* name, double alpha) {
    return json{{"name", name}, {"material", "m"}, {"coarse_grain", alpha}, {"contact", dt::hertz_mindlin()},
                {"time_step", 1.8e-5 * alpha}};
  };
  json top = level("a4", 4);
  top["insert"] = {{{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.05}, {"velocity", {0, 0, -3}},
                    {"region", {{"box", {{"min", {0, 0, 0.062}}, {"max", {0.12, 0.12, 0.12}}}}}}}};
  doc["subdomains"] = {top, level("a2", 2), level("a1", 1)};
  auto coupling = [](const char* name, const char* coarse, const char* fine, double z_top) {
    return json{{"name", name},
                {"coarse", coarse},
                {"fine", fine},
                {"region", {{"min", {0, 0, 0}}, {"max", {0.12, 0.12, z_top}}, {"cells", {2, 2, 1}}}},
                {"inflow_faces", {"+z"}},
                {"transfer_max_steps", 16}};
  };
  doc["couplings"] = {coupling("upper", "a4", "a2", 0.06), coupling("lower", "a2", "a1", 0.03)};
  auto sim = dt::build(doc);
  EXPECT_EQ(sim->control_macro, 4u);  // 15 fine steps asked, 4 per macro step of 7.2e-5 s
  dp::RunOptions opt;
  opt.output_directory = std::filesystem::temp_directory_path() / ("domel_coupling_nest_test_" + std::to_string(::getpid()));
  opt.progress = false;
  opt.max_steps = 240;  // 17 ms: the block reaches the lower region
  sim->run(opt, dt::builtin_registry());
  std::filesystem::remove_all(opt.output_directory);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(sim->flow.residual(k, sim->subdomains[k]->store()), 0) << k;
  const auto& upper = sim->couplings[0]->faces()[5];
  const auto& lower = sim->couplings[1]->faces()[5];
  EXPECT_GT(upper.parcels, 0u);
  EXPECT_GT(upper.n_inserted, 0u);
  EXPECT_GT(lower.parcels, 0u);  // alpha-2 particles, themselves inserted by "upper", crossed into "lower"
  EXPECT_GT(lower.n_inserted, 0u);
  EXPECT_EQ(lower.n_inserted + lower.queue.size(), 8 * lower.parcels);
  // each finer level lives only in its region (checked at the last control interval, before the last steps)
  const auto& a1 = sim->subdomains[2]->store();
  for (std::size_t q = 0; q < a1.size(); ++q) EXPECT_LT(a1.z[q], 0.03 + 0.01);
}
