// Guards how far a sphere reaches into the walls outside the step (issue 41:
// insertions and pours keep clear of every wall, the start-up check names a
// particle in a wall): hand-computed overlaps for a plane, a cylinder mantle,
// a cone mantle and a one-triangle mesh, walls that are not there yet or any
// more, a moving wall at its pose; a region wholly inside the walls; and a
// random insertion whose cylinder region reaches past a hopper's cone (the
// case the issue found: overlaps of up to 78 % of a diameter) placing every
// particle clear of the cone, checked against the cone's distance written
// out here, and a pour through the same cone placing its first event clear of
// it; a fixed floor may stand in a wall. Cost: about a second.
#include "geometry/wall_clearance.hpp"

#include "scenario/scenario.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <unistd.h>
#include <vector>

namespace dp = domel::platform;
namespace dt = domel::test;

namespace {

dp::WallPrimitive floor_plane() {
  dp::WallPrimitive w;
  w.shape = dp::WallPrimitive::Shape::plane;
  w.name = "floor";
  return w;  // z = 0, particles above
}

dp::WallPrimitive can(double radius) {
  dp::WallPrimitive w;
  w.shape = dp::WallPrimitive::Shape::cylinder_inside;
  w.name = "can";
  w.axis = 2;
  w.radius = radius;
  w.lo = 0.0;
  w.hi = 1.0;
  return w;
}

}  // namespace

TEST(WallClearance, OverlapsOfAPlaneACylinderAConeAndAMesh) {
  const double r = 0.01;
  {
    const dp::WallClearance c({floor_plane()}, 0.0, r);
    const double half_in[3] = {0.3, 0.2, 0.5 * r};  // centre half a radius above the floor
    EXPECT_NEAR(c.overlap(half_in, r), 0.5 * r, 1e-15);
    const double behind[3] = {0.0, 0.0, -0.02};  // centre behind the plane: the whole radius and more
    EXPECT_NEAR(c.overlap(behind, r), r + 0.02, 1e-15);
    const double touching[3] = {0.0, 0.0, r};
    EXPECT_TRUE(c.clear(touching, r));
  }
  {
    const dp::WallClearance c({can(0.1)}, 0.0, r);
    const double near_mantle[3] = {0.1 - 0.3 * r, 0.0, 0.5};
    EXPECT_NEAR(c.overlap(near_mantle, r), 0.7 * r, 1e-15);
    const double outside[3] = {0.0, 0.12, 0.5};  // outside the mantle: in the wall
    EXPECT_NEAR(c.overlap(outside, r), r + 0.02, 1e-15);
    const double above[3] = {0.0, 0.12, 1.5};  // beyond the mantle's extent: no contact
    EXPECT_TRUE(c.clear(above, r));
  }
  {
    // hopper cone radius 0.1 at z = 0 to 0.4 at z = 0.3 (45 degrees): a centre at rho = 0.19, z = 0.1
    // (mantle radius 0.2) is 0.01 cos 45 from the mantle
    dp::WallPrimitive cone;
    cone.shape = dp::WallPrimitive::Shape::cone_inside;
    cone.axis = 2;
    cone.radius = 0.1;
    cone.radius_hi = 0.4;
    cone.lo = 0.0;
    cone.hi = 0.3;
    const dp::WallClearance c({cone}, 0.0, r);
    const double p[3] = {0.19, 0.0, 0.1};
    EXPECT_NEAR(c.overlap(p, r), r - 0.01 * std::sqrt(0.5), 1e-14);
  }
  {
    // one triangle in z = 0 over [0, 1]^2 (its lower left half): a sphere 0.4 r above its face, and one
    // beside its hypotenuse (the closest point on the edge)
    const std::vector<double> soup = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    dp::WallPrimitive m;
    m.shape = dp::WallPrimitive::Shape::mesh;
    m.mesh = std::make_shared<dp::TriangleMesh>(dp::TriangleMesh::from_soup(soup, 1e-9));
    m.verts = m.mesh->vertices;
    const dp::WallClearance c({m}, 0.0, r);
    const double over_face[3] = {0.2, 0.2, 0.4 * r};
    EXPECT_NEAR(c.overlap(over_face, r), 0.6 * r, 1e-15);
    const double below_face[3] = {0.2, 0.2, -0.4 * r};  // a mesh acts from both sides
    EXPECT_NEAR(c.overlap(below_face, r), 0.6 * r, 1e-15);
    const double off_edge[3] = {0.5 + 0.5 * r / std::sqrt(2.0), 0.5 + 0.5 * r / std::sqrt(2.0), 0.0};
    EXPECT_NEAR(c.overlap(off_edge, r), 0.5 * r, 1e-14);
    const double far[3] = {3.0, 3.0, 0.0};
    EXPECT_TRUE(c.clear(far, r));
  }
}

TEST(WallClearance, OnlyTheWallsThatStandAtThatTimeWhereTheyStand) {
  const double r = 0.01;
  dp::WallPrimitive plug = floor_plane();
  plug.remove_at = 0.5;  // an outlet plug pulled at 0.5 s
  dp::WallPrimitive later = can(0.1);
  later.active_from = 0.2;
  const double p[3] = {0.0, 0.12, 0.0};  // below the floor and outside the can
  const dp::WallClearance at0({plug, later}, 0.0, r);
  std::size_t which = 99;
  EXPECT_NEAR(at0.overlap(p, r, &which), r, 1e-15);  // the plug only (the can is not there yet)
  EXPECT_EQ(which, 0u);
  const dp::WallClearance at1({plug, later}, 1.0, r);
  EXPECT_NEAR(at1.overlap(p, r, &which), r + 0.02, 1e-15);  // the can only (the plug has gone)
  EXPECT_EQ(which, 1u);
  // a floor moving up at 0.1 m/s: at 0.5 s it stands at z = 0.05
  dp::WallPrimitive lift = floor_plane();
  auto motion = std::make_shared<dp::WallMotion>();
  dp::MotionItem item;
  item.kind = dp::MotionItem::Kind::translation;
  item.vec[2] = 0.1;
  motion->items.push_back(item);
  lift.set_motion(motion);
  const double q[3] = {0.0, 0.0, 0.05 + 0.25 * r};
  EXPECT_NEAR(dp::WallClearance({lift}, 0.5, r).overlap(q, r), 0.75 * r, 1e-12);
  EXPECT_TRUE(dp::WallClearance({lift}, 0.0, r).clear(q, r));
}

TEST(WallClearance, ARegionWhollyInsideTheWalls) {
  domel_region_v1 outside{};
  outside.shape = 1;  // a box outside the can's mantle
  const double lo[3] = {0.12, 0.12, 0.1}, hi[3] = {0.2, 0.2, 0.3};
  for (int a = 0; a < 3; ++a) outside.lo[a] = lo[a], outside.hi[a] = hi[a];
  const dp::WallClearance walls({floor_plane(), can(0.1)}, 0.0, 0.0);
  std::size_t which = 99;
  EXPECT_TRUE(walls.covers(outside, &which));
  EXPECT_EQ(which, 1u);
  domel_region_v1 straddling = outside;  // reaches into the can: there is room
  straddling.lo[0] = straddling.lo[1] = 0.0;
  EXPECT_FALSE(walls.covers(straddling));
  // a flat mesh floor a metre across beside them (mpi_run_np3's STL floor once made the grid of a
  // zero-radius query hold cells of 1e-12 m): a mesh holds no point, so it changes nothing and costs nothing
  dp::WallPrimitive mesh;
  mesh.shape = dp::WallPrimitive::Shape::mesh;
  mesh.mesh = std::make_shared<dp::TriangleMesh>(
      dp::TriangleMesh::from_soup({-0.5, -0.5, -0.01, 0.5, -0.5, -0.01, -0.5, 0.5, -0.01}, 1e-9));
  mesh.verts = mesh.mesh->vertices;
  EXPECT_TRUE(dp::WallClearance({floor_plane(), can(0.1), mesh}, 0.0, 0.0).covers(outside, &which));
  const double just_above[3] = {-0.4, -0.4, -0.01 + 0.5e-9};
  EXPECT_NEAR(dp::WallClearance({mesh}, 0.0, 1e-9).overlap(just_above, 1e-9), 0.5e-9, 1e-15);
  domel_region_v1 below = straddling;  // under the floor
  below.lo[2] = -0.3;
  below.hi[2] = -0.1;
  EXPECT_TRUE(walls.covers(below, &which));
  EXPECT_EQ(which, 0u);
}

namespace {

/// The hopper of scenarios/examples/hopper.json (radius 4 mm at z = 0 to 20 mm at z = 30 mm).
constexpr double kR0 = 0.004, kR1 = 0.02, kH = 0.03;

/// The least clearance of the store's particles from the hopper's mantle,
/// in radii: the signed distance from the mantle's line (kR0, 0)-(kR1, kH)
/// in the (rho, z) half-plane, positive inside, less the radius.
double least_cone_clearance(const dp::ParticleStore& s) {
  const double len = std::hypot(kR1 - kR0, kH);
  double closest = INFINITY;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double rho = std::hypot(s.x[k], s.y[k]);
    const double d = ((kR0 - rho) * kH + s.z[k] * (kR1 - kR0)) / len;
    closest = std::min(closest, (d - s.radius[k]) / s.radius[k]);
  }
  return closest;
}

/// That hopper, and a cylinder region 12 mm wide from z = 5 mm: its lower part reaches through the cone.
nlohmann::json hopper_reached_through() {
  nlohmann::json doc = dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  doc["walls"] = {{{"name", "hopper"}, {"type", "cone"}, {"material", "m"}, {"axis", "z"}, {"center", {0, 0, 0}},
                   {"bottom", 0.0}, {"top", kH}, {"radius_bottom", kR0}, {"radius_top", kR1}, {"closed_bottom", true}}};
  return doc;
}

const nlohmann::json kWideRegion = {
    {"cylinder", {{"axis", "z"}, {"center", {0, 0, 0}}, {"radius", 0.012}, {"bottom", 0.005}, {"top", kH}}}};

}  // namespace

TEST(WallClearance, APourReachingPastAHopperConePlacesNothingInIt) {
  nlohmann::json doc = hopper_reached_through();
  doc["subdomains"][0]["pour"] = {{{"insert", {{"model", "random"}, {"diameter", 0.0014}, {"volume_fraction", 0.2},
                                               {"region", kWideRegion}}},
                                   {"mass_rate", 0.5}, {"interval", 0.01}}};
  auto sim = dt::build(doc);
  dp::RunOptions opt;
  opt.progress = false;
  opt.max_steps = 1;  // the first event, then one step of 1e-5 s (far less than 1e-3 r of motion)
  opt.output_directory = std::filesystem::temp_directory_path() / ("domel_wall_clearance_" + std::to_string(getpid()));
  sim->run(opt, dt::builtin_registry());
  std::filesystem::remove_all(opt.output_directory);
  const dp::ParticleStore& s = sim->subdomains[0]->store();
  ASSERT_GT(s.size(), 50u);
  const double closest = least_cone_clearance(s);
  std::printf("[hopper pour] %zu particles, least clearance from the cone %.3g radii\n", s.size(), closest);
  EXPECT_GE(closest, -1e-3);
}

TEST(WallClearance, AFixedFloorMayStandInAWall) {
  // a rough floor of fixed particles on a lattice across the whole box under a can: those outside the can's
  // mantle stand in its wall (they feel none), and a region wholly outside it is no error either
  nlohmann::json doc = hopper_reached_through();
  doc["walls"] = {{{"name", "can"}, {"type", "cylinder"}, {"material", "m"}, {"axis", "z"}, {"center", {0, 0, 0}},
                   {"radius", 0.01}, {"bottom", 0.0}, {"top", 0.05}, {"closed_bottom", false}}};
  const nlohmann::json floor_everywhere = {{"box", {{"min", {-0.02, -0.02, 0}}, {"max", {0.02, 0.02, 0.0014}}}}};
  const nlohmann::json floor_outside = {{"box", {{"min", {0.012, 0.012, 0.0014}}, {"max", {0.02, 0.02, 0.0028}}}}};
  doc["subdomains"][0]["insert"] = {
      {{"model", "lattice"}, {"diameter", 0.0014}, {"fixed", true}, {"region", floor_everywhere}},
      {{"model", "lattice"}, {"diameter", 0.0014}, {"fixed", true}, {"region", floor_outside}}};
  const auto sim = dt::build(doc);
  const dp::ParticleStore& s = sim->subdomains[0]->store();
  std::size_t in_the_wall = 0;
  for (std::size_t k = 0; k < s.size(); ++k) in_the_wall += std::hypot(s.x[k], s.y[k]) > 0.01 ? 1 : 0;
  // the lattice's sites: region minimum + (i + 0.5) d (plugins/insertion/lattice.hpp), 28 per side here
  std::size_t inside = 0, sites = 0;
  for (int i = 0; i < 28; ++i)
    for (int j = 0; j < 28; ++j, ++sites)
      inside += std::hypot(-0.02 + (i + 0.5) * 0.0014, -0.02 + (j + 0.5) * 0.0014) > 0.01 ? 0 : 1;
  EXPECT_EQ(s.size() - in_the_wall, inside);          // the first layer's sites inside the can
  EXPECT_GT(in_the_wall, sites - inside + 20);        // the rest of it in the wall, and the second region's
}

TEST(WallClearance, AnInsertionReachingPastAHopperConePlacesNothingInIt) {
  nlohmann::json doc = hopper_reached_through();
  doc["subdomains"][0]["insert"] = {
      {{"model", "random"}, {"diameter", 0.0014}, {"count", 300}, {"seed", 7}, {"region", kWideRegion}}};
  const auto sim = dt::build(doc);
  const dp::ParticleStore& s = sim->subdomains[0]->store();
  ASSERT_GT(s.size(), 100u);
  const double closest = least_cone_clearance(s);
  std::printf("[hopper insertion] %zu particles, least clearance from the cone %.3g radii\n", s.size(), closest);
  EXPECT_GE(closest, -1e-9);  // round-off of the two distance formulas
}

TEST(WallClearance, AnInsertionBoxWiderThanAHopperPlacesNothingBesideIt) {
  // Fuzzing start 13: a box wider than the hopper placed 13 of 14 particles
  // around the cone, where the mantle's closest point is a rim and the
  // distance used to be the rim's, unsigned: clear. Beside the mantle within
  // its extent is the container's solid, so every particle placed from a box
  // three times the hopper's width and as tall as it lies inside the cone.
  nlohmann::json doc = hopper_reached_through();
  doc["subdomains"][0]["insert"] = {{{"model", "random"}, {"diameter", 0.0014}, {"count", 400}, {"seed", 3},
                                     {"region", {{"box", {{"min", {-0.03, -0.03, 0.005}}, {"max", {0.03, 0.03, kH}}}}}}}};
  const auto sim = dt::build(doc);
  const dp::ParticleStore& s = sim->subdomains[0]->store();
  ASSERT_GT(s.size(), 20u);
  std::size_t beside = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
    beside += std::hypot(s.x[k], s.y[k]) > kR0 + (kR1 - kR0) * s.z[k] / kH ? 1 : 0;
  const double closest = least_cone_clearance(s);
  std::printf("[hopper in a wide box] %zu particles, %zu beside the cone, least clearance %.3g radii\n", s.size(),
              beside, closest);
  EXPECT_EQ(beside, 0u);
  EXPECT_GE(closest, -1e-9);
}
