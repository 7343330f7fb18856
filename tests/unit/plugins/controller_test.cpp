// SPDX-License-Identifier: MIT
// Unit tests of the built-in controller library (plugins/controllers): the
// stress_pi and velocity_p models used directly through their C++ classes on
// hand-built two-level views (levels[0] fine, levels[1] coarse, a 2 x 1 x 2
// grid of 1 cm cells), once through the C callbacks the SDK generates, and
// once loaded from the built library through the host's plugin registry.
// Every expected number is computed by hand in the comment beside it from
// the formulas of docs/physics.md §5.3 (stress_pi) and §5.4 (velocity_p).
#include "plugins/controllers/stress_pi.hpp"
#include "plugins/controllers/velocity_p.hpp"

#include "loader/plugin_registry.hpp"
#include "scenario/json_schema.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

namespace {

using domel::plugins::controller::StressPi;
using domel::plugins::controller::StressPiOutcome;
using domel::plugins::controller::VelocityP;
using domel::sdk::ParameterError;
using domel::sdk::Params;
using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kOut = UINT32_MAX;

// Relative closeness for numbers computed by the same few operations in a
// different order (a handful of roundings of 1e-16 each).
::testing::AssertionResult close(double got, double want, double rel = 1e-12) {
  if (std::fabs(got - want) <= rel * std::max(std::fabs(want), 1e-300) || got == want)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << got << ", want " << want;
}

// One level's grid: 2 x 1 x 2 cells of 1 cm from the origin, cell index
// ix + 2 iz; every field zero until a test sets it.
struct Grid {
  static constexpr std::size_t kCells = 4;
  double origin[3] = {0.0, 0.0, 0.0};
  double spacing[3] = {0.01, 0.01, 0.01};
  uint32_t nx = 2, ny = 1, nz = 2;
  std::vector<uint32_t> count = std::vector<uint32_t>(kCells, 0);
  std::vector<double> phi = std::vector<double>(kCells, 0.0), mass = std::vector<double>(kCells, 0.0);
  std::vector<double> u[3], u_min[3], u_max[3];
  std::vector<double> stress = std::vector<double>(6 * kCells, 0.0);  // xx yy zz xy xz yz, compression < 0
  domel_cell_grid_v1 view{};
  Grid() {
    for (int k = 0; k < 3; ++k) {
      u[k].assign(kCells, 0.0);
      u_min[k].assign(kCells, 0.0);
      u_max[k].assign(kCells, 0.0);
    }
  }
  void bind() {
    view = domel_cell_grid_v1{};
    view.struct_size = sizeof view;
    view.nx = nx; view.ny = ny; view.nz = nz;
    for (int k = 0; k < 3; ++k) { view.origin[k] = origin[k]; view.spacing[k] = spacing[k]; }
    view.n_cells = kCells;
    view.count = count.data();
    view.volume_fraction = phi.data();
    view.mass = mass.data();
    view.ux = u[0].data(); view.uy = u[1].data(); view.uz = u[2].data();
    view.u_min_x = u_min[0].data(); view.u_min_y = u_min[1].data(); view.u_min_z = u_min[2].data();
    view.u_max_x = u_max[0].data(); view.u_max_y = u_max[1].data(); view.u_max_z = u_max[2].data();
    view.stress = stress.data();
  }
};

struct Particles {
  std::vector<uint64_t> id;
  std::vector<double> x, y, z, vx, vy, vz, m, r, fx, fy, fz;
  std::vector<uint32_t> cell;
  domel_particles_v1 view{};
  std::size_t add(double px, double py, double pz, double radius, double mass, uint32_t c, double vzz = 0.0) {
    id.push_back(id.size());
    x.push_back(px); y.push_back(py); z.push_back(pz);
    vx.push_back(0.0); vy.push_back(0.0); vz.push_back(vzz);
    m.push_back(mass); r.push_back(radius); cell.push_back(c);
    fx.push_back(0.0); fy.push_back(0.0); fz.push_back(0.0);
    return id.size() - 1;
  }
  void bind() {
    // the host zeroes the outputs before each call (abi.h)
    std::fill(fx.begin(), fx.end(), 0.0);
    std::fill(fy.begin(), fy.end(), 0.0);
    std::fill(fz.begin(), fz.end(), 0.0);
    view = domel_particles_v1{};
    view.struct_size = sizeof view;
    view.n = id.size();
    view.id = id.data();
    view.x = x.data(); view.y = y.data(); view.z = z.data();
    view.vx = vx.data(); view.vy = vy.data(); view.vz = vz.data();
    view.mass = m.data(); view.radius = r.data(); view.cell = cell.data();
    view.fx = fx.data(); view.fy = fy.data(); view.fz = fz.data();
  }
};

struct Level {
  std::string name;
  double cg;
  Grid grid;
  Particles p;
  domel_level_v1 view{};
  void bind() {
    grid.bind();
    p.bind();
    view = domel_level_v1{};
    view.struct_size = sizeof view;
    view.name = name.c_str();
    view.coarse_grain = cg;
    view.cells = &grid.view;
    view.particles = &p.view;
  }
};

struct TwoLevels {
  Level fine{"fine", 1.0, {}, {}, {}};
  Level coarse{"coarse", 2.0, {}, {}, {}};
  domel_level_v1* levels[2] = {nullptr, nullptr};
  domel_control_step_v1 s{};
  // The step of one control interval T, views rebuilt and outputs zeroed.
  domel_control_step_v1& step(double interval) {
    fine.bind();
    coarse.bind();
    levels[0] = &fine.view;
    levels[1] = &coarse.view;
    s = domel_control_step_v1{};
    s.struct_size = sizeof s;
    s.level_count = 2;
    s.time = 1.0;
    s.interval = interval;
    s.levels = levels;
    return s;
  }
};

std::size_t cell(uint32_t ix, uint32_t iz) { return ix + 2u * iz; }

// What the host sets a controller up with (ABI 2.5) for the 2 x 1 x 2 grid
// of 1 cm cells: the fine level's step and steps per interval, the coarse
// level's, and the inflow cells with their inward normals.
struct HostSetup {
  domel_control_level_setup_v1 levels[2]{};
  std::vector<uint32_t> inflow_cell;
  std::vector<int32_t> inflow_direction;
  domel_control_setup_v1 view{};
  HostSetup(const HostSetup&) = delete;
  HostSetup& operator=(const HostSetup&) = delete;
  HostSetup(double dt_fine, uint64_t n_fine, double dt_coarse, uint64_t n_coarse, std::vector<uint32_t> cells = {},
        std::vector<int32_t> directions = {})
      : inflow_cell(std::move(cells)), inflow_direction(std::move(directions)) {
    static_assert(!std::is_copy_constructible_v<HostSetup>, "view points into the object");
    levels[0] = {sizeof(domel_control_level_setup_v1), 0, "fine", 1.0, dt_fine, n_fine};
    levels[1] = {sizeof(domel_control_level_setup_v1), 0, "coarse", 2.0, dt_coarse, n_coarse};
    view.struct_size = sizeof view;
    view.level_count = 2;
    view.interval = dt_fine * static_cast<double>(n_fine);
    view.levels = levels;
    view.nx = 2, view.ny = 1, view.nz = 2, view.n_cells = 4;
    for (int a = 0; a < 3; ++a) view.spacing[a] = 0.01;
    view.n_inflow_cells = inflow_cell.size();
    view.inflow_cell = inflow_cell.data();
    view.inflow_direction = inflow_direction.data();
  }
};

// ----------------------------------------------------------------- stress_pi
//
// The base case: cell 2 (x in [0, 1] cm, z in [1, 2] cm) under a top inflow
// face, direction [0, 0, -1]. Fine particles of cell 2 (radii 0.4, 0.5, 0.6,
// 0.5 mm: mean rbar = 0.5 mm) at depths below the top face z = 2 cm of
// 0.5 mm (P0), 1.575 mm (P1), 5 mm (P2), 9.9 mm (P3). The largest fine
// diameter is d_max = 1.2 mm (P2), so the layer is used = 1.4 d_max =
// 1.68 mm, full strength down to 0.875 used = 1.47 mm, sin^2 ramp to 1.68 mm:
// P1 sits in the middle of the ramp, (used - depth)/(0.125 used) = 0.5,
// weight sin^2(pi/4) = 1/2. P4 (cell 0, just under cell 2), P5 (cell 3, P0's
// height) and P6 (outside the grid) are never pushed.
// Averages: fine N_a = 4, phi_a = 0.3, S_zz = -1000 Pa; coarse (cg 2)
// N_t = 1, phi_t = 0.25, S_zz = -4000 Pa. V_c = 1e-6 m^3. Then
//   pre_t = V_c/(2 rbar) = 1e-6/(1e-3) = 1e-3 m^2,  c = 0.3/0.25 = 1.2,  pre_a = 1.2e-3 m^2
//   PV = pre_a 1000/4 = 0.3 N;  rho3 = (1/2)^3 = 1/8,  SP = pre_t 4000/(1/(1/8)) = 4/8 = 0.5 N
//   e = 0.2 N. With N = 15 fine steps of 1e-6 s: T = 1.5e-5 s, kp = 1/15, ki = 1/(15e-6) 1/s:
//   I = e T = 3e-6 N s,  u = e/15 + I/1.5e-5 = 0.2/15 + 0.2 = 0.21333... N.
struct StressCase {
  TwoLevels L;
  std::size_t p0, p1, p2, p3, p4, p5, p6, coarse0;
  static constexpr double kT = 1.5e-5;
  static constexpr double kE = 0.2, kPV = 0.3, kSP = 0.5;
  static constexpr double kUsed = 1.4 * 1.2e-3;
  StressCase() {
    Particles& f = L.fine.p;
    p0 = f.add(0.005, 0.005, 0.0195, 0.0004, 1e-3, 2);
    p1 = f.add(0.005, 0.005, 0.02 - 0.001575, 0.0005, 1e-3, 2);
    p2 = f.add(0.005, 0.005, 0.015, 0.0006, 1e-3, 2);
    p3 = f.add(0.005, 0.005, 0.0101, 0.0005, 1e-3, 2);
    p4 = f.add(0.005, 0.005, 0.0099, 0.0005, 1e-3, 0);
    p5 = f.add(0.015, 0.005, 0.0195, 0.0005, 1e-3, 3);
    p6 = f.add(0.005, 0.005, 0.025, 0.0005, 1e-3, kOut);
    Grid& ga = L.fine.grid;
    ga.count = {1, 0, 4, 1};
    ga.phi = {0.1, 0.0, 0.3, 0.1};
    ga.stress[6 * 2 + 2] = -1000.0;
    ga.stress[6 * 0 + 2] = -1000.0;
    ga.stress[6 * 3 + 2] = -1000.0;
    Grid& gt = L.coarse.grid;
    gt.count = {1, 0, 1, 1};
    gt.phi = {0.25, 0.0, 0.25, 0.25};
    gt.stress[6 * 2 + 2] = -4000.0;
    coarse0 = L.coarse.p.add(0.005, 0.005, 0.015, 0.001, 8e-3, 2);
  }
  static json params() {
    return {{"cells", {2}}, {"directions", {{0, 0, -1}}}, {"kp", 1.0 / 15}, {"ki", 1.0 / 1.5e-5},
            {"velocity_limit", 0}};
  }
  static double u1() { return kE / 15 + kE * kT / kT; }  // first call: kp e + ki e T
  // sin^2 fade weight of a particle at depth below the pushing face (§5.3)
  static double fade(double depth) {
    const double s = std::sin(0.5 * kPi * (kUsed - depth) / (0.125 * kUsed));
    return s * s;
  }
};

}  // namespace

// Guards SP, PV, e, I and u of one call against the hand computation above (physics.md §5.3).
TEST(StressPi, HandComputedSetpointProcessValueAndCommand) {
  StressCase c;
  StressPi model{Params(StressCase::params())};
  model.control(c.L.step(StressCase::kT));
  const auto& s = model.state().at(0);
  EXPECT_EQ(s.outcome, StressPiOutcome::kControlled);
  EXPECT_TRUE(close(s.process[2], 0.3));
  EXPECT_TRUE(close(s.setpoint[2], 0.5));
  EXPECT_TRUE(close(s.error[2], 0.2));
  EXPECT_TRUE(close(s.integral[2], 3e-6));
  EXPECT_TRUE(close(s.command[2], 0.2 / 15 + 0.2));
  EXPECT_FALSE(s.unwound[2]);
  // x and y have direction 0: not controlled, nothing computed
  EXPECT_EQ(s.command[0], 0.0);
  EXPECT_EQ(s.integral[1], 0.0);
  // P0 full, P1 half (the fade), P2 and P3 below the layer: 2 pushed, mean 0.75 u
  EXPECT_EQ(s.pushed[2], 2u);
  EXPECT_TRUE(close(s.applied_mean[2], 0.75 * s.command[2], 1e-9));
}

// Guards where the force acts: full in the outer layer, sin^2 mid-fade, zero below the layer and elsewhere.
TEST(StressPi, ForcesOnlyInTheForcingLayerWithSinSquaredFade) {
  StressCase c;
  StressPi model{Params(StressCase::params())};
  model.control(c.L.step(StressCase::kT));
  const Particles& f = c.L.fine.p;
  const double u = StressCase::u1();
  EXPECT_TRUE(close(f.fz[c.p0], -u));  // dir -1, full strength (depth 0.5 mm < 1.47 mm)
  // depth 1.575 mm: sin^2((pi/2)(1.68 - 1.575)/0.21) = sin^2(pi/4) = 1/2
  const double depth1 = 0.02 - f.z[c.p1];
  EXPECT_NEAR(StressCase::fade(depth1), 0.5, 1e-9);
  EXPECT_TRUE(close(f.fz[c.p1], -u * StressCase::fade(depth1), 1e-12));
  EXPECT_TRUE(close(StressPi::layer_weight(depth1, StressCase::kUsed, 0.125), StressCase::fade(depth1)));
  for (std::size_t i : {c.p2, c.p3, c.p4, c.p5, c.p6}) EXPECT_EQ(f.fz[i], 0.0) << "particle " << i;
  for (std::size_t i = 0; i < f.id.size(); ++i) {
    EXPECT_EQ(f.fx[i], 0.0);
    EXPECT_EQ(f.fy[i], 0.0);
  }
  EXPECT_EQ(c.L.coarse.p.fz[c.coarse0], 0.0);  // the coarse level is only read
  // the weight's shape: 1 at the face and at 0.875 used, 0 at and beyond used, no ramp when fade is 0
  EXPECT_EQ(StressPi::layer_weight(0.0, 1.0, 0.125), 1.0);
  EXPECT_EQ(StressPi::layer_weight(0.875, 1.0, 0.125), 1.0);
  EXPECT_EQ(StressPi::layer_weight(1.0, 1.0, 0.125), 0.0);
  EXPECT_EQ(StressPi::layer_weight(1.2, 1.0, 0.125), 0.0);
  EXPECT_EQ(StressPi::layer_weight(0.999, 1.0, 0.0), 1.0);
  EXPECT_TRUE(close(StressPi::layer_weight(0.9, 1.0, 0.5), std::pow(std::sin(0.5 * kPi * 0.1 / 0.5), 2)));
}

// Guards the direction signs: dir +1 pushes from the lower face (layer [lo, lo + used]) along +k, on x and z.
TEST(StressPi, DirectionSignsPickTheFace) {
  StressCase c;
  // the same target on xx as on zz, so u_x = u_z = the base case's u
  c.L.fine.grid.stress[6 * 2 + 0] = -1000.0;
  c.L.coarse.grid.stress[6 * 2 + 0] = -4000.0;
  Particles& f = c.L.fine.p;
  const std::size_t near_x0 = f.add(0.0003, 0.005, 0.015, 0.0005, 1e-3, 2);  // depth 0.3 mm from x = 0
  // a fifth particle in cell 2: N_a and rbar as before (count 4 stays the grid's, rbar (2.0+0.5)/5 mm = 0.5 mm)
  json params = StressCase::params();
  params["directions"] = {{1, 0, 1}};
  StressPi model{Params(params)};
  model.control(c.L.step(StressCase::kT));
  const double u = StressCase::u1();
  // z: pushed up from z = 1 cm, so P3 (depth 0.1 mm) gets +u; P0 and P1 at the top get nothing
  EXPECT_TRUE(close(f.fz[c.p3], u));
  EXPECT_EQ(f.fz[c.p0], 0.0);
  EXPECT_EQ(f.fz[c.p1], 0.0);
  EXPECT_EQ(f.fz[near_x0], 0.0);  // depth 5 mm from z = 1 cm
  EXPECT_EQ(f.fz[c.p4], 0.0);     // cell 0, though 0.1 mm under the face
  // x: pushed along +x from x = 0; only near_x0 (the others sit at x = 5 mm)
  EXPECT_TRUE(close(f.fx[near_x0], u));
  for (std::size_t i : {c.p0, c.p1, c.p2, c.p3}) EXPECT_EQ(f.fx[i], 0.0) << i;
  EXPECT_TRUE(close(model.state()[0].command[0], u));
  EXPECT_TRUE(close(model.state()[0].command[2], u));
}

// Guards the PI law over two calls: I += e T each call, u = kp e + ki I; and kd acts on PV's change.
TEST(StressPi, IntegralAccumulatesOverCalls) {
  StressCase c;
  StressPi model{Params(StressCase::params())};
  model.control(c.L.step(StressCase::kT));
  model.control(c.L.step(StressCase::kT));
  const auto& s = model.state()[0];
  EXPECT_TRUE(close(s.integral[2], 6e-6));               // 2 e T
  EXPECT_TRUE(close(s.command[2], 0.2 / 15 + 0.4));      // e/15 + 6e-6/1.5e-5
  EXPECT_TRUE(close(c.L.fine.p.fz[c.p0], -(0.2 / 15 + 0.4)));

  // kd only, kd = T: no previous PV on the first call (u = 0, no force);
  // then PV falls from 0.3 to 0.2 N (S_zz -1000 -> -2000/3): u = -kd (0.2 - 0.3)/T = 0.1 N
  StressCase d;
  json p = StressCase::params();
  p["kp"] = 0; p["ki"] = 0; p["kd"] = StressCase::kT;
  StressPi pd{Params(p)};
  pd.control(d.L.step(StressCase::kT));
  EXPECT_EQ(pd.state()[0].command[2], 0.0);
  EXPECT_EQ(d.L.fine.p.fz[d.p0], 0.0);
  d.L.fine.grid.stress[6 * 2 + 2] = -2000.0 / 3.0;
  pd.control(d.L.step(StressCase::kT));
  EXPECT_TRUE(close(pd.state()[0].process[2], 0.2));
  EXPECT_TRUE(close(pd.state()[0].command[2], 0.1, 1e-9));
  EXPECT_TRUE(close(d.L.fine.p.fz[d.p0], -0.1, 1e-9));
}

// Guards the a-priori anti-windup: u < 0 applies nothing and undoes this call's integration.
TEST(StressPi, NegativeCommandPushesNothingAndUndoesIntegration) {
  StressCase c;
  c.L.coarse.grid.stress[6 * 2 + 2] = -1000.0;  // SP = 1e-3 1000/8 = 0.125 N < PV = 0.3 N
  StressPi model{Params(StressCase::params())};
  model.control(c.L.step(StressCase::kT));
  const auto& s = model.state()[0];
  EXPECT_TRUE(close(s.error[2], -0.175));
  EXPECT_TRUE(close(s.command[2], -0.175 / 15 - 0.175));  // kp e + ki e T before the undo
  EXPECT_EQ(s.integral[2], 0.0);
  EXPECT_TRUE(s.unwound[2]);
  for (double f : c.L.fine.p.fz) EXPECT_EQ(f, 0.0);

  // a tensile (or zero) target clips SP to 0 and resets the integral built before
  StressCase t;
  StressPi mt{Params(StressCase::params())};
  mt.control(t.L.step(StressCase::kT));
  ASSERT_TRUE(close(mt.state()[0].integral[2], 3e-6));
  t.L.coarse.grid.stress[6 * 2 + 2] = 100.0;
  mt.control(t.L.step(StressCase::kT));
  EXPECT_EQ(mt.state()[0].setpoint[2], 0.0);
  EXPECT_EQ(mt.state()[0].integral[2], 0.0);  // reset, then e = -0.3 integrated and undone
  for (double f : t.L.fine.p.fz) EXPECT_EQ(f, 0.0);
}

// Guards the empty-cell rule: no particle on either level (or none of the cell's fine particles in the
// view) resets I and the previous PV, and pushes nothing.
TEST(StressPi, EmptyCellResetsState) {
  for (int which = 0; which < 3; ++which) {
    StressCase c;
    StressPi model{Params(StressCase::params())};
    model.control(c.L.step(StressCase::kT));
    ASSERT_TRUE(close(model.state()[0].integral[2], 3e-6));
    if (which < 2) {
      (which == 0 ? c.L.coarse.grid : c.L.fine.grid).count[2] = 0;
    } else {  // the averages still count 4, but the view holds none of them in cell 2
      for (std::size_t i : {c.p0, c.p1, c.p2, c.p3}) c.L.fine.p.cell[i] = kOut;
    }
    model.control(c.L.step(StressCase::kT));
    const auto& s = model.state()[0];
    EXPECT_EQ(s.outcome, StressPiOutcome::kEmpty);
    EXPECT_EQ(s.integral[2], 0.0);
    EXPECT_EQ(s.pv_old[2], 0.0);
    EXPECT_FALSE(s.has_pv_old[2]);
    for (double f : c.L.fine.p.fz) EXPECT_EQ(f, 0.0);
  }
}

// Guards the skip rule: phi_target <= 0.5 phi_actual pushes nothing and keeps the state.
TEST(StressPi, SkipsWhenTargetVolumeFractionBelowHalf) {
  StressCase c;
  StressPi model{Params(StressCase::params())};
  model.control(c.L.step(StressCase::kT));
  c.L.coarse.grid.phi[2] = 0.15;  // = 0.5 phi_a: skipped
  model.control(c.L.step(StressCase::kT));
  EXPECT_EQ(model.state()[0].outcome, StressPiOutcome::kSkipped);
  EXPECT_TRUE(close(model.state()[0].integral[2], 3e-6));  // kept
  EXPECT_TRUE(model.state()[0].has_pv_old[2]);
  for (double f : c.L.fine.p.fz) EXPECT_EQ(f, 0.0);
  c.L.coarse.grid.phi[2] = 0.16;  // above half: controlled again
  model.control(c.L.step(StressCase::kT));
  EXPECT_EQ(model.state()[0].outcome, StressPiOutcome::kControlled);
  EXPECT_LT(c.L.fine.p.fz[c.p0], 0.0);
}

// Guards the velocity limit: with the force held over T, v + (T/m) F lands exactly on the limit.
TEST(StressPi, VelocityLimitLandsExactlyOnTheBound) {
  StressCase c;
  // coarse cell 2: u_min_z = -0.5, u_max_z = 0.1, r = 0.2 -> [-0.5 * 1.2, 0.1 * 1.2] = [-0.6, 0.12] m/s
  c.L.coarse.grid.u_min[2][2] = -0.5;
  c.L.coarse.grid.u_max[2][2] = 0.1;
  Particles& f = c.L.fine.p;
  // P0: m = 1e-5 kg, vz = -0.59: unlimited dv = -T u/m = -1.5e-5 0.21333/1e-5 = -0.32 m/s
  // would reach -0.91; lambda = (-0.6 + 0.59)/(-0.32) = 0.03125
  f.m[c.p0] = 1e-5;
  f.vz[c.p0] = -0.59;
  // P1 already moves faster than the limit, in the direction of the force: lambda = 0
  f.vz[c.p1] = -0.7;
  json p = StressCase::params();
  p["velocity_limit"] = 0.2;
  StressPi model{Params(p)};
  model.control(c.L.step(StressCase::kT));
  const double u = StressCase::u1();
  EXPECT_TRUE(close(f.fz[c.p0], -u * 0.03125, 1e-9));
  EXPECT_NEAR(f.vz[c.p0] + StressCase::kT * f.fz[c.p0] / f.m[c.p0], -0.6, 1e-14);
  EXPECT_EQ(f.fz[c.p1], 0.0);
  // A particle moving the other way (up, vz = +0.1) is slowed freely: the force points away from hi.
  StressCase d;
  d.L.coarse.grid.u_min[2][2] = -0.5;
  d.L.coarse.grid.u_max[2][2] = 0.1;
  d.L.fine.p.vz[d.p0] = 0.1;
  StressPi md{Params(p)};
  md.control(d.L.step(StressCase::kT));
  EXPECT_TRUE(close(d.L.fine.p.fz[d.p0], -u));  // dv = -3.2e-3: v* = 0.0968 > -0.6
}

// Guards limit_horizon: the limiter predicts v + h F/m over the given horizon
// instead of the whole interval (domel's couplings pass the fine time step).
TEST(StressPi, VelocityLimitPredictsOverTheHorizon) {
  StressCase c;
  c.L.coarse.grid.u_min[2][2] = -0.5;
  c.L.coarse.grid.u_max[2][2] = 0.1;
  Particles& f = c.L.fine.p;
  // P0: m = 1e-5 kg, vz = -0.59, horizon T/10: unlimited dv = -0.032 m/s would reach -0.622;
  // lambda = (-0.6 + 0.59)/(-0.032) = 0.3125 (ten times the whole-interval lambda 0.03125 above)
  f.m[c.p0] = 1e-5;
  f.vz[c.p0] = -0.59;
  json p = StressCase::params();
  p["velocity_limit"] = 0.2;
  p["limit_horizon"] = StressCase::kT / 10;
  StressPi model{Params(p)};
  model.control(c.L.step(StressCase::kT));
  EXPECT_TRUE(close(f.fz[c.p0], -StressCase::u1() * 0.3125, 1e-9));
  EXPECT_NEAR(f.vz[c.p0] + StressCase::kT / 10 * f.fz[c.p0] / f.m[c.p0], -0.6, 1e-14);
  json bad = StressCase::params();
  bad["limit_horizon"] = 0.0;
  EXPECT_THROW(StressPi{Params(bad)}, domel::sdk::ParameterError);
}

// Guards the a-posteriori anti-windup: mean applied force per pushed particle < u/2 undoes the integration.
TEST(StressPi, APosterioriAntiWindup) {
  json p = StressCase::params();
  p["velocity_limit"] = 0.2;
  // P0 limited by lambda, P1 free (weight 1/2): mean = (lambda + 1/2) u / 2.
  // lambda = (-0.6 - v)/(-0.32) with m = 1e-5: v = -0.408 -> 0.6 (mean 0.55 u, kept);
  // v = -0.52 -> 0.25 (mean 0.375 u, undone).
  for (const auto& [v0, lambda, kept] : {std::tuple{-0.408, 0.6, true}, std::tuple{-0.52, 0.25, false}}) {
    StressCase c;
    c.L.coarse.grid.u_min[2][2] = -0.5;
    c.L.coarse.grid.u_max[2][2] = 0.1;
    c.L.fine.p.m[c.p0] = 1e-5;
    c.L.fine.p.vz[c.p0] = v0;
    c.L.fine.p.m[c.p1] = 1.0;  // dv = -1.6e-6 m/s: free
    StressPi model{Params(p)};
    model.control(c.L.step(StressCase::kT));
    const auto& s = model.state()[0];
    const double u = StressCase::u1();
    EXPECT_TRUE(close(c.L.fine.p.fz[c.p0], -lambda * u, 1e-9)) << v0;
    EXPECT_TRUE(close(s.applied_mean[2], 0.5 * (lambda + 0.5) * u, 1e-9)) << v0;
    EXPECT_TRUE(close(s.command[2], u)) << v0;  // the command itself is not changed
    if (kept) {
      EXPECT_TRUE(close(s.integral[2], 3e-6)) << v0;
      EXPECT_FALSE(s.unwound[2]);
    } else {
      EXPECT_EQ(s.integral[2], 0.0) << v0;
      EXPECT_TRUE(s.unwound[2]);
    }
  }
  // No particle in the layer: nothing applied, the integration is undone.
  StressCase c;
  c.L.fine.p.z[c.p0] = 0.014;
  c.L.fine.p.z[c.p1] = 0.013;
  StressPi model{Params(StressCase::params())};
  model.control(c.L.step(StressCase::kT));
  EXPECT_EQ(model.state()[0].pushed[2], 0u);
  EXPECT_EQ(model.state()[0].integral[2], 0.0);
  for (double f : c.L.fine.p.fz) EXPECT_EQ(f, 0.0);
}

// Guards the refusals at control time: level count, grid geometry, cells outside the grid, the interval.
TEST(StressPi, RefusesStepsItCannotControl) {
  auto message = [](StressCase& c, const json& params, auto&& tweak) {
    StressPi model{Params(params)};
    domel_control_step_v1& s = c.L.step(StressCase::kT);
    tweak(s);
    try {
      model.control(s);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const json p = StressCase::params();
  {
    StressCase c;
    const auto m = message(c, p, [](domel_control_step_v1& s) { s.level_count = 1; });
    EXPECT_NE(m.find("exactly 2 levels"), std::string::npos) << m;
    EXPECT_NE(m.find("levels[0] the fine level"), std::string::npos) << m;
  }
  {
    StressCase c;
    const auto m = message(c, p, [&](domel_control_step_v1&) { c.L.coarse.grid.view.spacing[1] = 0.02; });
    EXPECT_NE(m.find("grids of levels[0] ('fine') and levels[1] ('coarse') differ"), std::string::npos) << m;
    EXPECT_NE(m.find("spacing[1]"), std::string::npos) << m;
  }
  {
    StressCase c;
    const auto m = message(c, p, [&](domel_control_step_v1&) { c.L.coarse.grid.view.origin[2] = 0.001; });
    EXPECT_NE(m.find("origin[2]"), std::string::npos) << m;
  }
  {
    StressCase c;
    const auto m = message(c, p, [&](domel_control_step_v1&) {
      c.L.coarse.grid.view.nx = 4;  // 4 x 1 x 1: as many cells, another shape
      c.L.coarse.grid.view.nz = 1;
    });
    EXPECT_NE(m.find("cells per axis 2x1x2 vs 4x1x1"), std::string::npos) << m;
  }
  {
    StressCase c;
    json q = p;
    q["cells"] = {4};
    const auto m = message(c, q, [](domel_control_step_v1&) {});
    EXPECT_NE(m.find("cells[0] = 4 lies outside the grid (4 cells"), std::string::npos) << m;
  }
  {
    StressCase c;
    const auto m = message(c, p, [](domel_control_step_v1& s) { s.interval = 0.0; });
    EXPECT_NE(m.find("control interval"), std::string::npos) << m;
  }
  {  // origins equal to rounding (1e-9 of the spacing) are the same grid
    StressCase c;
    const auto m = message(c, p, [&](domel_control_step_v1&) { c.L.coarse.grid.view.origin[0] = 1e-13; });
    EXPECT_EQ(m, "");
  }
}

namespace {

template <class M>
std::string refusal(const json& params) {
  try {
    const M model{Params(params)};
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// Guards the constructor's refusals: cells, directions, gains and layer parameters.
TEST(StressPi, RefusesBadParameters) {
  const json good = StressCase::params();
  EXPECT_EQ(refusal<StressPi>(good), "");
  auto without = [&](const char* key) {
    json j = good;
    j.erase(key);
    return refusal<StressPi>(j);
  };
  auto with = [&](const char* key, const json& v) {
    json j = good;
    j[key] = v;
    return refusal<StressPi>(j);
  };
  auto has = [](const std::string& msg, const char* part) {
    return ::testing::AssertionResult(msg.find(part) != std::string::npos) << "'" << msg << "' lacks '" << part << "'";
  };
  // cells and directions go together; without both, and without gains, the defaults come from the setup
  EXPECT_TRUE(has(without("cells"), "give 'cells' and 'directions' together"));
  EXPECT_TRUE(has(without("directions"), "give 'cells' and 'directions' together"));
  EXPECT_EQ(without("kp"), "");
  EXPECT_EQ(without("ki"), "");
  EXPECT_TRUE(has(with("cells", json::array()), "non-empty array"));
  EXPECT_TRUE(has(with("cells", {-1}), "cells[0] must be an integer cell index >= 0"));
  EXPECT_TRUE(has(with("cells", {1.5}), "cells[0] must be an integer"));
  {
    json j = good;
    j["cells"] = {2, 2};
    j["directions"] = {{0, 0, -1}, {0, 0, -1}};
    EXPECT_TRUE(has(refusal<StressPi>(j), "cell 2 is listed twice"));
  }
  EXPECT_TRUE(has(with("directions", {{0, 0, -1}, {0, 0, 1}}), "one entry per cell (1), got 2 entries"));
  EXPECT_TRUE(has(with("directions", {{0, -1}}), "directions[0] must be a 3-vector"));
  EXPECT_TRUE(has(with("directions", {{0, 2, 0}}), "directions[0] has component 2; each must be -1, 0 or 1"));
  EXPECT_TRUE(has(with("directions", {{0, 0.5, 0}}), "each must be -1, 0 or 1"));
  EXPECT_TRUE(has(with("directions", {{0, 0, 0}}), "is [0, 0, 0]"));
  EXPECT_TRUE(has(with("kp", -0.1), "'kp' must be a finite number >= 0"));
  EXPECT_TRUE(has(with("ki", -1), "'ki' must be a finite number >= 0"));
  EXPECT_TRUE(has(with("kd", -1), "'kd' must be a finite number >= 0"));
  EXPECT_TRUE(has(with("kp", "1"), "'kp' must be a number"));
  EXPECT_TRUE(has(with("layer_diameters", 0), "'layer_diameters' must be > 0"));
  EXPECT_TRUE(has(with("fade_fraction", 1.5), "'fade_fraction' must lie in [0, 1]"));
  EXPECT_TRUE(has(with("velocity_limit", -0.2), "'velocity_limit' must be a finite number >= 0"));
  for (const std::string& m : {without("cells"), with("kp", -0.1)}) EXPECT_EQ(m.rfind("stress_pi: ", 0), 0u) << m;
}

// ---------------------------------------------------------------- velocity_p
//
// The base case: cell 1 (x in [1, 2] cm, z in [0, 1] cm). Coarse particles
// of cell 1 with masses 1, 2, 4 g and vz = -0.05, -0.1, -0.1125 m/s: their
// Favre mean is (-0.05e-3 - 0.2e-3 - 0.45e-3)/7e-3 = -0.1 m/s = the coarse
// grid's uz (PV). The fine mean uz is -0.3 m/s (target), phi equal on both
// levels (c_mf = 1). Coarse time step dt = 2e-6 s, N = 10: T = 2e-5 s,
// kp = 1/N = 0.1. Then e = -0.3 + 0.1 = -0.2 m/s, u = kp e = -0.02 m/s and
// F_i = m_i u/dt = -1e4 m_i N: -10, -20, -40 N.
namespace {

struct VelocityCase {
  TwoLevels L;
  std::size_t c0, c1, c2, other0, other2, outside, fine0;
  static constexpr double kDt = 2e-6, kT = 2e-5;
  VelocityCase() {
    Particles& p = L.coarse.p;
    c0 = p.add(0.015, 0.005, 0.002, 0.001, 1e-3, 1, -0.05);
    c1 = p.add(0.016, 0.005, 0.005, 0.001, 2e-3, 1, -0.1);
    c2 = p.add(0.017, 0.005, 0.008, 0.001, 4e-3, 1, -0.1125);
    other0 = p.add(0.005, 0.005, 0.005, 0.001, 1e-3, 0, -0.1);
    other2 = p.add(0.005, 0.005, 0.015, 0.001, 1e-3, 2, -0.1);
    outside = p.add(0.005, 0.005, 0.025, 0.001, 1e-3, kOut, -0.1);
    Grid& gc = L.coarse.grid;
    gc.count = {1, 3, 1, 0};
    gc.phi = {0.2, 0.3, 0.2, 0.0};
    gc.u[2] = {-0.1, -0.1, -0.1, 0.0};
    Grid& gf = L.fine.grid;
    gf.count = {8, 5, 8, 0};
    gf.phi = {0.3, 0.3, 0.3, 0.0};
    gf.u[2] = {-0.3, -0.3, -0.3, 0.0};
    fine0 = L.fine.p.add(0.015, 0.005, 0.005, 0.0005, 1e-4, 1, -0.3);
  }
  static json params() { return {{"cells", {1}}, {"kp", 0.1}, {"velocity_limit", 0}}; }
  /// The coarse level's step dt and N = T/dt = 10 steps per interval come from the setup.
  static HostSetup setup() { return HostSetup(kDt / 2, 20, kDt, 10); }
  static VelocityP make(const json& p) {
    VelocityP m{Params(p)};
    m.setup(setup().view);
    return m;
  }
};

}  // namespace

// Guards F_i = m_i u/dt with kp = 1/N: held for N steps of dt it changes every velocity by e (§5.4).
TEST(VelocityP, ClosesTheErrorInOneInterval) {
  VelocityCase c;
  VelocityP model = VelocityCase::make(VelocityCase::params());
  model.control(c.L.step(VelocityCase::kT));
  const auto& s = model.state()[0];
  EXPECT_TRUE(s.controlled);
  EXPECT_EQ(s.correction, 1.0);
  EXPECT_TRUE(close(s.process[2], -0.1));
  EXPECT_TRUE(close(s.setpoint[2], -0.3));
  EXPECT_TRUE(close(s.error[2], -0.2));
  EXPECT_TRUE(close(s.command[2], -0.02));
  Particles& p = c.L.coarse.p;
  EXPECT_TRUE(close(p.fz[c.c0], -10.0));
  EXPECT_TRUE(close(p.fz[c.c1], -20.0));
  EXPECT_TRUE(close(p.fz[c.c2], -40.0));
  for (std::size_t i : {c.c0, c.c1, c.c2}) {
    EXPECT_EQ(p.fx[i], 0.0);  // x and y: e = 0, no force
    EXPECT_EQ(p.fy[i], 0.0);
  }
  // cells not listed, particles outside the grid and the fine level get nothing
  for (std::size_t i : {c.other0, c.other2, c.outside}) EXPECT_EQ(p.fz[i], 0.0) << i;
  EXPECT_EQ(c.L.fine.p.fz[c.fine0], 0.0);
  // hold the forces for N = T/dt steps of explicit Euler: each velocity changes by e = -0.2,
  // and the Favre mean goes from PV = -0.1 to SP = -0.3
  double momentum = 0.0, mass = 0.0;
  for (std::size_t i : {c.c0, c.c1, c.c2}) {
    double v = p.vz[i];
    for (int step = 0; step < 10; ++step) v += p.fz[i] / p.m[i] * VelocityCase::kDt;
    EXPECT_NEAR(v - p.vz[i], -0.2, 1e-14) << i;
    momentum += p.m[i] * v;
    mass += p.m[i];
  }
  EXPECT_NEAR(momentum / mass, -0.3, 1e-14);
}

// Guards the mass-flow correction: SP = clamp(phi_f/phi_c) u_fine per cell when on, 1 when off.
TEST(VelocityP, MassFlowCorrectionScalesAndClamps) {
  json p = VelocityCase::params();
  p["cells"] = {1, 2};
  p["mass_flow_correction"] = {true, false};
  // phi_f/phi_c in cell 1 -> c_mf (bounds [0.5, 2]): 0.3/0.2 -> 1.5; 0.5/0.1 = 5 -> 2; 0.05/0.2 = 0.25 -> 0.5
  for (const auto& [phi_f, phi_c, c_mf] :
       {std::tuple{0.3, 0.2, 1.5}, std::tuple{0.5, 0.1, 2.0}, std::tuple{0.05, 0.2, 0.5}}) {
    VelocityCase c;
    c.L.fine.grid.phi[1] = phi_f;
    c.L.coarse.grid.phi[1] = phi_c;
    c.L.fine.grid.phi[2] = 0.5;  // cell 2, correction off: c_mf = 1 whatever the ratio (5)
    c.L.coarse.grid.phi[2] = 0.1;
    VelocityP model = VelocityCase::make(p);
    model.control(c.L.step(VelocityCase::kT));
    const auto& s1 = model.state()[0];
    EXPECT_TRUE(close(s1.correction, c_mf)) << phi_f;
    EXPECT_TRUE(close(s1.setpoint[2], -0.3 * c_mf)) << phi_f;
    // F = m kp (SP - PV)/dt = 1e-3 0.1 (-0.3 c_mf + 0.1)/2e-6 for c0
    EXPECT_TRUE(close(c.L.coarse.p.fz[c.c0], 1e-3 * 0.1 * (-0.3 * c_mf + 0.1) / 2e-6)) << phi_f;
    const auto& s2 = model.state()[1];
    EXPECT_EQ(s2.correction, 1.0);
    EXPECT_TRUE(close(s2.setpoint[2], -0.3));
    EXPECT_TRUE(close(c.L.coarse.p.fz[c.other2], 1e-3 * 0.1 * (-0.2) / 2e-6));
  }
  // correction on by default; bounds configurable: [0.8, 1.25] clamps 1.5 to 1.25
  VelocityCase c;
  c.L.fine.grid.phi[1] = 0.3;
  c.L.coarse.grid.phi[1] = 0.2;
  json q = VelocityCase::params();
  q["correction_bounds"] = {0.8, 1.25};
  VelocityP model = VelocityCase::make(q);
  model.control(c.L.step(VelocityCase::kT));
  EXPECT_TRUE(close(model.state()[0].correction, 1.25));
}

// Guards the velocity limit against the fine cell's range, predicted over T: v + (T/m) F lands on it.
TEST(VelocityP, VelocityLimitLandsExactlyOnTheBound) {
  VelocityCase c;
  // fine cell 1: u_min_z = -0.25, u_max_z = -0.05, r = 0.2 -> [-0.3, -0.04] m/s; dv = T u/dt = -0.2 m/s
  c.L.fine.grid.u_min[2][1] = -0.25;
  c.L.fine.grid.u_max[2][1] = -0.05;
  Particles& p = c.L.coarse.p;
  p.vz[c.c1] = -0.2;   // would reach -0.4: lambda = (-0.3 + 0.2)/(-0.2) = 0.5
  p.vz[c.c2] = -0.35;  // already beyond the limit: lambda = 0
  json q = VelocityCase::params();
  q["velocity_limit"] = 0.2;
  VelocityP model = VelocityCase::make(q);
  model.control(c.L.step(VelocityCase::kT));
  EXPECT_TRUE(close(p.fz[c.c0], -10.0));  // -0.05 -> -0.25: inside, lambda = 1
  EXPECT_TRUE(close(p.fz[c.c1], -10.0, 1e-12));  // -20 N times 0.5
  EXPECT_NEAR(p.vz[c.c1] + VelocityCase::kT * p.fz[c.c1] / p.m[c.c1], -0.3, 1e-14);
  EXPECT_EQ(p.fz[c.c2], 0.0);
}

// Guards the integral (u = kp e + ki I over two calls) and its reset when a cell empties (on either level,
// or in the coarse particle view).
TEST(VelocityP, IntegralAccumulatesAndEmptyCellResets) {
  VelocityCase c;
  json q = VelocityCase::params();
  q["ki"] = 1.0 / VelocityCase::kT;  // 5e4 1/s
  VelocityP model = VelocityCase::make(q);
  model.control(c.L.step(VelocityCase::kT));
  // I = e T = -4e-6 m, u = -0.02 + 5e4 (-4e-6) = -0.22 m/s
  EXPECT_TRUE(close(model.state()[0].integral[2], -4e-6));
  EXPECT_TRUE(close(model.state()[0].command[2], -0.22));
  model.control(c.L.step(VelocityCase::kT));
  // I = -8e-6 m, u = -0.02 - 0.4 = -0.42 m/s; F(c0) = 1e-3 (-0.42)/2e-6 = -210 N
  EXPECT_TRUE(close(model.state()[0].integral[2], -8e-6));
  EXPECT_TRUE(close(c.L.coarse.p.fz[c.c0], -210.0));
  for (int which = 0; which < 3; ++which) {
    VelocityCase d;
    VelocityP m = VelocityCase::make(q);
    m.control(d.L.step(VelocityCase::kT));
    if (which < 2) {
      (which == 0 ? d.L.fine.grid : d.L.coarse.grid).count[1] = 0;
    } else {  // the averages still count 3, but the view holds none of them in cell 1
      for (std::size_t i : {d.c0, d.c1, d.c2}) d.L.coarse.p.cell[i] = kOut;
    }
    m.control(d.L.step(VelocityCase::kT));
    EXPECT_FALSE(m.state()[0].controlled);
    EXPECT_EQ(m.state()[0].integral[2], 0.0);
    for (double f : d.L.coarse.p.fz) EXPECT_EQ(f, 0.0);
  }
}

// Guards the constructor's refusals: cells, gains, time step, per-cell flags, correction bounds.
TEST(VelocityP, RefusesBadParameters) {
  const json good = VelocityCase::params();
  EXPECT_EQ(refusal<VelocityP>(good), "");
  auto without = [&](const char* key) {
    json j = good;
    j.erase(key);
    return refusal<VelocityP>(j);
  };
  auto with = [&](const char* key, const json& v) {
    json j = good;
    j[key] = v;
    return refusal<VelocityP>(j);
  };
  auto has = [](const std::string& msg, const char* part) {
    return ::testing::AssertionResult(msg.find(part) != std::string::npos) << "'" << msg << "' lacks '" << part << "'";
  };
  EXPECT_EQ(without("cells"), "");  // every cell of the grid, from the setup
  EXPECT_EQ(without("kp"), "");     // 1/N, from the setup
  EXPECT_EQ(with("mass_flow_correction", false), "");
  EXPECT_TRUE(has(with("kp", -1), "'kp' must be a finite number >= 0"));
  EXPECT_TRUE(has(with("ki", -1), "'ki' must be a finite number >= 0"));
  EXPECT_TRUE(has(with("cells", {3, 1, 3}), "cell 3 is listed twice"));
  EXPECT_TRUE(has(with("mass_flow_correction", {true, false}), "one entry per entry of 'cells' (1)"));
  EXPECT_TRUE(has(with("mass_flow_correction", {1}), "mass_flow_correction[0] must be true or false"));
  EXPECT_TRUE(has(with("correction_bounds", {0.5}), "'correction_bounds' must be [lower, upper]"));
  EXPECT_TRUE(has(with("correction_bounds", {0, 2}), "0 < lower <= 1 <= upper"));
  EXPECT_TRUE(has(with("correction_bounds", {1.2, 2}), "0 < lower <= 1 <= upper"));
  EXPECT_TRUE(has(with("correction_bounds", {0.5, 0.9}), "0 < lower <= 1 <= upper"));
  EXPECT_EQ(with("correction_bounds", {1, 1}), "");  // a clamp to 1 switches the correction off
}

// Guards the schemas the host validates against: accepted by domel's validator, a description on
// every property, an x-unit on every number, the documented defaults; bad blocks refused there too.
TEST(ControllerSchema, DocumentsEveryParameter) {
  for (const char* text : {StressPi::kSchema, VelocityP::kSchema}) {
    const json s = json::parse(text);
    EXPECT_EQ(s.at("type"), "object");
    EXPECT_EQ(s.at("additionalProperties"), false);
    for (const auto& [key, prop] : s.at("properties").items()) {
      EXPECT_TRUE(prop.contains("description")) << key;
      if (prop.value("type", "") == "number") {
        EXPECT_TRUE(prop.contains("x-unit")) << key;
      }
    }
  }
  const json sp = json::parse(StressPi::kSchema);
  EXPECT_EQ(sp.at("required"), json::array());  // the rest defaults from the setup
  EXPECT_EQ(sp.at("properties").at("kd").at("default"), 0);
  EXPECT_EQ(sp.at("properties").at("layer_diameters").at("default"), 1.4);
  EXPECT_EQ(sp.at("properties").at("fade_fraction").at("default"), 0.125);
  EXPECT_EQ(sp.at("properties").at("velocity_limit").at("default"), 0.2);
  EXPECT_EQ(sp.at("properties").at("ki").at("x-unit"), "1/s");
  EXPECT_EQ(sp.at("properties").at("kd").at("x-unit"), "s");
  const json vp = json::parse(VelocityP::kSchema);
  EXPECT_EQ(vp.at("required"), json::array());
  EXPECT_FALSE(vp.at("properties").contains("time_step"));  // the setup's, not a parameter
  EXPECT_EQ(vp.at("properties").at("mass_flow_correction").at("default"), true);
  EXPECT_EQ(vp.at("properties").at("ki").at("default"), 0);
  EXPECT_EQ(vp.at("properties").at("velocity_limit").at("default"), 0.2);
  EXPECT_EQ(vp.at("properties").at("correction_bounds").at("default"), json::array({0.5, 2}));

  using domel::platform::SchemaValidator;
  const SchemaValidator vs(sp), vv(vp);
  EXPECT_TRUE(vs.is_valid(StressCase::params()));
  EXPECT_TRUE(vv.is_valid(VelocityCase::params()));
  json bad = StressCase::params();
  bad["directions"] = {{0, 2, 0}};
  EXPECT_FALSE(vs.is_valid(bad));
  bad = StressCase::params();
  bad["kp"] = -1;
  EXPECT_FALSE(vs.is_valid(bad));
  bad = StressCase::params();
  bad["gain"] = 1;
  EXPECT_FALSE(vs.is_valid(bad));
  bad = StressCase::params();
  bad["directions"] = {{0, 0}};
  EXPECT_FALSE(vs.is_valid(bad));
  json vbad = VelocityCase::params();
  vbad["time_step"] = 1e-5;
  EXPECT_FALSE(vv.is_valid(vbad));
  vbad = VelocityCase::params();
  vbad["mass_flow_correction"] = {1};
  EXPECT_FALSE(vv.is_valid(vbad));
}

// Guards the generated C callbacks: create from JSON text, control with the same result as the class,
// a refused step as DOMEL_ERR_RUNTIME with the message, refused parameters as DOMEL_ERR_PARAMETER.
TEST(ControllerAbi, GeneratedCallbacksMatchTheClasses) {
  using ExportStress = domel::sdk::detail::Export<StressPi>;
  using ExportVelocity = domel::sdk::detail::Export<VelocityP>;
  char err[512] = {0};
  void* inst = nullptr;
  ASSERT_EQ(ExportStress::create(StressCase::params().dump().c_str(), nullptr, &inst, err, sizeof err), DOMEL_OK)
      << err;
  StressCase c;
  ASSERT_EQ(ExportStress::control(inst, &c.L.step(StressCase::kT), err, sizeof err), DOMEL_OK) << err;
  StressCase direct;
  StressPi model{Params(StressCase::params())};
  model.control(direct.L.step(StressCase::kT));
  EXPECT_EQ(c.L.fine.p.fz, direct.L.fine.p.fz);
  EXPECT_TRUE(close(c.L.fine.p.fz[c.p0], -StressCase::u1()));
  domel_control_step_v1& one = c.L.step(StressCase::kT);
  one.level_count = 1;
  EXPECT_EQ(ExportStress::control(inst, &one, err, sizeof err), DOMEL_ERR_RUNTIME);
  EXPECT_NE(std::string(err).find("stress_pi: needs exactly 2 levels"), std::string::npos) << err;
  ExportStress::destroy(inst);

  inst = nullptr;
  EXPECT_EQ(ExportStress::create(R"({"cells":[2],"directions":[[0,2,0]],"kp":0.1,"ki":1})", nullptr, &inst, err,
                                 sizeof err),
            DOMEL_ERR_PARAMETER);
  EXPECT_EQ(inst, nullptr);
  EXPECT_NE(std::string(err).find("component 2"), std::string::npos) << err;

  ASSERT_EQ(ExportVelocity::create(VelocityCase::params().dump().c_str(), nullptr, &inst, err, sizeof err), DOMEL_OK)
      << err;
  VelocityCase v;
  const HostSetup& vs = VelocityCase::setup();
  ASSERT_EQ(ExportVelocity::control_setup(inst, &vs.view, err, sizeof err), DOMEL_OK) << err;
  ASSERT_EQ(ExportVelocity::control(inst, &v.L.step(VelocityCase::kT), err, sizeof err), DOMEL_OK) << err;
  EXPECT_TRUE(close(v.L.coarse.p.fz[v.c2], -40.0));
  v.L.step(VelocityCase::kT);
  v.L.fine.grid.view.nz = 3;
  EXPECT_EQ(ExportVelocity::control(inst, &v.L.s, err, sizeof err), DOMEL_ERR_RUNTIME);
  EXPECT_NE(std::string(err).find("velocity_p:"), std::string::npos) << err;
  // a setup the model refuses is DOMEL_ERR_PARAMETER with its message: cell 7 beyond the 4 cells
  ExportVelocity::destroy(inst);
  inst = nullptr;
  ASSERT_EQ(ExportVelocity::create(R"({"cells":[7]})", nullptr, &inst, err, sizeof err), DOMEL_OK) << err;
  EXPECT_EQ(ExportVelocity::control_setup(inst, &vs.view, err, sizeof err), DOMEL_ERR_PARAMETER);
  EXPECT_NE(std::string(err).find("cells[0] = 7 lies outside the coupling's grid (2 x 1 x 2 = 4 cells"),
            std::string::npos)
      << err;
  ExportVelocity::destroy(inst);
}

// Guards the built library: domel_controller_std loads through the host's registry with both models
// as controllers, and a model runs through the host's ModelInstance.
TEST(ControllerLibrary, LoadsThroughThePluginRegistry) {
  using namespace domel::platform;
  PluginRegistry registry;
  registry.load(std::string(DOMEL_BINARY_DIR) + "/plugins/libdomel_controller_std.so");
  ASSERT_EQ(registry.libraries().size(), 1u);
  EXPECT_EQ(registry.libraries()[0].name, "domel_controller_std");
  EXPECT_EQ(registry.names(DOMEL_KIND_CONTROLLER), (std::vector<std::string>{"stress_pi", "velocity_p"}));
  const RegisteredModel* m = registry.find(DOMEL_KIND_CONTROLLER, "velocity_p");
  ASSERT_NE(m, nullptr);
  EXPECT_NE(m->summary.find("levels[0] (FINE)"), std::string::npos);
  EXPECT_NE(registry.find(DOMEL_KIND_CONTROLLER, "stress_pi")->summary.find("levels[1] (COARSE)"), std::string::npos);
  ModelInstance inst(*m, VelocityCase::params(), "controller_test");
  EXPECT_TRUE(inst.control_setup(VelocityCase::setup().view));
  VelocityCase v;
  inst.control(v.L.step(VelocityCase::kT));
  EXPECT_TRUE(close(v.L.coarse.p.fz[v.c1], -20.0));
  v.L.step(VelocityCase::kT).level_count = 3;
  try {
    inst.control(v.L.s);
    ADD_FAILURE() << "a step of 3 levels was accepted";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("needs exactly 2 levels"), std::string::npos) << e.what();
  }
}

// Checkpoints (ABI 2.3): a state saved after one call and loaded into a
// fresh instance makes the second call give exactly what the first
// instance's second call gives (the integral, the previous PV), through the
// registry's save_state/load_state; a state of another size is refused.
TEST(ControllerLibrary, SavedStateContinuesExactlyAndAWrongStateIsRefused) {
  using namespace domel::platform;
  PluginRegistry registry;
  registry.load(std::string(DOMEL_BINARY_DIR) + "/plugins/libdomel_controller_std.so");
  const RegisteredModel* m = registry.find(DOMEL_KIND_CONTROLLER, "stress_pi");
  ASSERT_NE(m, nullptr);
  json p = StressCase::params();
  p["kd"] = StressCase::kT;  // the second call reads the previous PV too
  ModelInstance a(*m, p, "a"), b(*m, p, "b");
  ASSERT_TRUE(a.has_state());
  StressCase c1, c2;
  a.control(c1.L.step(StressCase::kT));
  b.load_state(a.save_state());
  c1.L.fine.grid.stress[6 * 2 + 2] = c2.L.fine.grid.stress[6 * 2 + 2] = -2000.0 / 3.0;
  c1.L.fine.p.fz[c1.p0] = c2.L.fine.p.fz[c2.p0] = 0.0;
  a.control(c1.L.step(StressCase::kT));
  b.control(c2.L.step(StressCase::kT));
  EXPECT_EQ(c1.L.fine.p.fz[c1.p0], c2.L.fine.p.fz[c2.p0]);
  EXPECT_NE(c2.L.fine.p.fz[c2.p0], 0.0);
  EXPECT_EQ(a.save_state(), b.save_state());

  std::vector<unsigned char> state = a.save_state();
  state.pop_back();
  try {
    b.load_state(state);
    ADD_FAILURE() << "a truncated state was accepted";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  state = a.save_state();
  state.push_back(0);
  try {
    b.load_state(state);
    ADD_FAILURE() << "a state with bytes left over was accepted";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("bytes more"), std::string::npos) << e.what();
  }
  ModelInstance v(*registry.find(DOMEL_KIND_CONTROLLER, "velocity_p"), VelocityCase::params(), "v");
  try {
    v.load_state(a.save_state());
    ADD_FAILURE() << "a stress_pi state was accepted by velocity_p";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("load_state failed"), std::string::npos) << e.what();
  }
}

// Guards the defaults taken from the setup (ABI 2.5): stress_pi without kp,
// ki, cells, directions and limit_horizon pushes exactly as with kp = 1/N,
// ki = 1/(N dt_fine), the inflow cells with their inward normals and a
// horizon of one fine step written out (N = 15 fine steps of 1e-6 s: the
// hand-computed case above); without setup it refuses to run; a setup with
// no inflow cell, or cells beyond the grid, is refused.
TEST(StressPi, DefaultsComeFromTheSetup) {
  json explicit_p = StressCase::params();
  explicit_p["velocity_limit"] = 0.2;  // the limiter on, so that the horizon matters
  explicit_p["limit_horizon"] = 1e-6;
  explicit_p["cells"] = {2, 3};
  explicit_p["directions"] = {{0, 0, -1}, {0, 0, -1}};
  const json defaults = {{"velocity_limit", 0.2}};
  StressCase a, b;
  // a coarse velocity range of +-1 mm/s in cell 2: over one fine step the push of P0 (u1/m = 213 m/s^2)
  // stays inside it, over the whole interval T it would not
  for (StressCase* c : {&a, &b}) {
    c->L.coarse.grid.u_min[2][2] = -1e-3;
    c->L.coarse.grid.u_max[2][2] = 1e-3;
  }
  StressPi written{Params(explicit_p)};
  written.control(a.L.step(StressCase::kT));
  StressPi derived{Params(defaults)};
  EXPECT_THROW(derived.control(b.L.step(StressCase::kT)), std::runtime_error);  // no setup: no gains
  const HostSetup top(1e-6, 15, 2e-6, 8, {2, 3}, {0, 0, -1, 0, 0, -1});  // cells 2, 3 under the +z face
  derived.setup(top.view);
  derived.control(b.L.step(StressCase::kT));
  EXPECT_EQ(derived.cells(), (std::vector<uint32_t>{2, 3}));
  EXPECT_EQ(a.L.fine.p.fz, b.L.fine.p.fz);
  EXPECT_TRUE(close(b.L.fine.p.fz[b.p0], -StressCase::u1()));  // not throttled: the horizon is one fine step

  StressPi none{Params(defaults)};
  EXPECT_THROW(none.setup(HostSetup(1e-6, 15, 2e-6, 8).view), ParameterError);  // no inflow cell, no cells
  StressPi beyond{Params(StressCase::params())};
  json p = StressCase::params();
  p["cells"] = {4};
  StressPi outside{Params(p)};
  EXPECT_NO_THROW(beyond.setup(top.view));
  EXPECT_THROW(outside.setup(top.view), ParameterError);
}

// velocity_p without kp and cells pushes exactly as with kp = 1/N_c (N_c = 10
// coarse steps per interval) and every cell listed; its force m u/dt takes dt
// from the setup's coarse level.
TEST(VelocityP, DefaultsComeFromTheSetup) {
  json explicit_p = VelocityCase::params();
  explicit_p["cells"] = {0, 1, 2, 3};
  VelocityCase a, b;
  VelocityP written = VelocityCase::make(explicit_p);
  written.control(a.L.step(VelocityCase::kT));
  VelocityP derived = VelocityCase::make({{"velocity_limit", 0}});
  derived.control(b.L.step(VelocityCase::kT));
  EXPECT_EQ(derived.cells(), (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(a.L.coarse.p.fz, b.L.coarse.p.fz);
  EXPECT_TRUE(close(b.L.coarse.p.fz[b.c0], -10.0));  // the hand-computed case: kp = 0.1, dt = 2e-6 s
  VelocityP unset{Params(VelocityCase::params())};
  EXPECT_THROW(unset.control(b.L.step(VelocityCase::kT)), std::runtime_error);  // no dt without setup
}
