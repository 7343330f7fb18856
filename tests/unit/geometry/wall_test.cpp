// Guards the analytic wall primitives' gap() against hand-computed values:
// the annulus (face, inner-rim edge, nothing beyond the outer radius) and
// the cone frustum (mantle face with its signed distance, rim edges from
// inside and from below), and the motion of a wall (place, surface velocity).
#include "geometry/wall.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace dp = domel::platform;

TEST(AnnulusWall, FaceRimAndOuterEdge) {
  dp::WallPrimitive a;
  a.shape = dp::WallPrimitive::Shape::annulus;
  a.p[2] = 1.0;  // plate z = 1, particles above, hole of radius 0.1, outer radius 0.5
  a.r_inner = 0.1;
  a.r_outer = 0.5;
  double d, nx, ny, nz;
  ASSERT_TRUE(a.gap(0.3, 0.0, 1.02, d, nx, ny, nz));  // over the plate: face
  EXPECT_NEAR(d, 0.02, 1e-15);
  EXPECT_EQ(nz, 1.0);
  ASSERT_TRUE(a.gap(0.07, 0.0, 1.04, d, nx, ny, nz));  // over the hole: the rim point (0.1, 0, 1)
  EXPECT_NEAR(d, 0.05, 1e-15);
  EXPECT_NEAR(nx, -0.6, 1e-14);
  EXPECT_NEAR(nz, 0.8, 1e-14);
  ASSERT_TRUE(a.gap(0.0, 0.07, 0.96, d, nx, ny, nz));  // in the hole, below the plate: rim from below
  EXPECT_NEAR(d, 0.05, 1e-15);
  EXPECT_NEAR(ny, -0.6, 1e-14);
  EXPECT_NEAR(nz, -0.8, 1e-14);
  // beyond the outer radius: the outer rim edge, distance sqrt(0.01^2 + 0.01^2), normal (1, 0, 1)/sqrt 2
  ASSERT_TRUE(a.gap(0.51, 0.0, 1.01, d, nx, ny, nz));
  EXPECT_NEAR(d, std::sqrt(2e-4), 1e-12);
  EXPECT_NEAR(nx, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(ny, 0.0, 1e-12);
  EXPECT_NEAR(nz, std::sqrt(0.5), 1e-12);
  EXPECT_TRUE(a.near(0.51, 0.0, 1.01, 0.02));            // but a list candidate
}

TEST(ConeWall, MantleFaceAndRimEdges) {
  // hopper about z through the origin: radius 0.1 at z = 0, 0.4 at z = 0.3 (45 degrees)
  dp::WallPrimitive c;
  c.shape = dp::WallPrimitive::Shape::cone_inside;
  c.axis = 2;
  c.radius = 0.1;
  c.radius_hi = 0.4;
  c.lo = 0.0;
  c.hi = 0.3;
  double d, nx, ny, nz;
  const double s = std::sqrt(0.5);
  // a point inside at z = 0.1 (mantle radius 0.2), rho = 0.15: distance 0.05 cos 45
  ASSERT_TRUE(c.gap(0.15, 0.0, 0.1, d, nx, ny, nz));
  EXPECT_NEAR(d, 0.05 * s, 1e-14);
  EXPECT_NEAR(nx, -s, 1e-14);
  EXPECT_NEAR(nz, s, 1e-14);
  // outside the mantle: negative
  ASSERT_TRUE(c.gap(0.0, 0.25, 0.1, d, nx, ny, nz));
  EXPECT_NEAR(d, -0.05 * s, 1e-14);
  // below the lower rim, inside its radius: the rim edge (0.1, 0, 0) from below
  ASSERT_TRUE(c.gap(0.07, 0.0, -0.04, d, nx, ny, nz));
  EXPECT_NEAR(d, 0.05, 1e-14);
  EXPECT_NEAR(nx, -0.6, 1e-14);
  EXPECT_NEAR(nz, -0.8, 1e-14);
  // just above the upper rim, outside: the rim edge (0.4, 0, 0.3)
  ASSERT_TRUE(c.gap(0.43, 0.0, 0.34, d, nx, ny, nz));
  EXPECT_NEAR(d, 0.05, 1e-14);
  EXPECT_NEAR(nx, 0.6, 1e-14);
  EXPECT_NEAR(nz, 0.8, 1e-14);
  // a straight cone (equal radii) agrees with the cylinder mantle inside its extent
  dp::WallPrimitive cyl;
  cyl.shape = dp::WallPrimitive::Shape::cylinder_inside;
  cyl.radius = 0.2;
  cyl.lo = 0;
  cyl.hi = 1;
  c.radius = c.radius_hi = 0.2;
  c.hi = 1.0;
  double d2, mx, my, mz;
  ASSERT_TRUE(c.gap(0.1, 0.05, 0.5, d, nx, ny, nz));
  ASSERT_TRUE(cyl.gap(0.1, 0.05, 0.5, d2, mx, my, mz));
  EXPECT_NEAR(d, d2, 1e-15);
  EXPECT_NEAR(nx, mx, 1e-15);
  EXPECT_NEAR(ny, my, 1e-15);
}

TEST(ConeWall, TheSolidBehindTheMantleWithinItsExtent) {
  // The hopper of MantleFaceAndRimEdges. Behind the mantle within the extent
  // the wall is solid everywhere, also where the mantle's closest point is a
  // rim (fuzzing start 13 found particles there counted clear, 25 mm deep a
  // step later): the distance is minus that to the rim, the normal towards it.
  dp::WallPrimitive c;
  c.shape = dp::WallPrimitive::Shape::cone_inside;
  c.axis = 2;
  c.radius = 0.1;
  c.radius_hi = 0.4;
  c.lo = 0.0;
  c.hi = 0.3;
  double d, nx, ny, nz;
  const double s2 = std::sqrt(0.5);
  // rho 0.6 at z = 0.25: the top rim (0.4, 0.3) is closest; distance hypot(0.2, 0.05)
  ASSERT_TRUE(c.gap(0.6, 0.0, 0.25, d, nx, ny, nz));
  const double h = std::hypot(0.2, 0.05);
  EXPECT_NEAR(d, -h, 1e-14);
  EXPECT_NEAR(nx, -0.2 / h, 1e-14);
  EXPECT_NEAR(nz, 0.05 / h, 1e-14);
  // the same rho just above the top: outside the solid, the rim's distance, positive
  ASSERT_TRUE(c.gap(0.6, 0.0, 0.31, d, nx, ny, nz));
  EXPECT_NEAR(d, std::hypot(0.2, 0.01), 1e-14);
  EXPECT_NEAR(nx, 0.2 / std::hypot(0.2, 0.01), 1e-14);
  // continuous across the edge of the face's band behind the mantle: the
  // line through the top rim along the outward normal (1, -1)/sqrt 2
  const double e = 1e-9;
  double d_in, d_out;
  ASSERT_TRUE(c.gap(0.4 + 0.05 - e, 0.0, 0.3 - 0.05 - e, d_in, nx, ny, nz));   // in the face's band
  ASSERT_TRUE(c.gap(0.4 + 0.05 + e, 0.0, 0.3 - 0.05 + e, d_out, nx, ny, nz));  // the rim's zone
  EXPECT_NEAR(d_in, -0.05 / s2, 1e-8);
  EXPECT_NEAR(d_out, -0.05 / s2, 1e-8);
  // beside and below the lower end: outside the extent, the underside of the
  // funnel (the outer face, normal outwards and down) or the lower rim
  ASSERT_TRUE(c.gap(0.3, 0.0, -0.01, d, nx, ny, nz));
  EXPECT_NEAR(d, (0.2 + 0.01) * s2, 1e-14);
  EXPECT_NEAR(nx, s2, 1e-14);
  EXPECT_NEAR(nz, -s2, 1e-14);
  ASSERT_TRUE(c.gap(0.15, 0.0, -0.1, d, nx, ny, nz));
  EXPECT_NEAR(d, std::hypot(0.05, 0.1), 1e-14);
  EXPECT_NEAR(nz, -0.1 / std::hypot(0.05, 0.1), 1e-14);
  // a flat funnel (radius 0.01 at z = 0 to 0.1 at z = 0.01): a point 1 mm
  // under it past its lower end sees the underside (the outer face), not the solid
  dp::WallPrimitive f = c;
  f.radius = 0.01;
  f.radius_hi = 0.1;
  f.hi = 0.01;
  ASSERT_TRUE(f.gap(0.06, 0.0, -0.001, d, nx, ny, nz));
  const double len = std::hypot(0.09, 0.01);
  const double across = ((0.06 - 0.01) * -0.01 + -0.001 * 0.09) / len;  // < 0: behind the line
  EXPECT_NEAR(d, -across, 1e-15);
  EXPECT_NEAR(nx, 0.01 / len, 1e-15);   // the outward normal: away from the funnel, down
  EXPECT_NEAR(nz, -0.09 / len, 1e-15);
  // ... and 1 mm higher it is within the extent: in the solid
  ASSERT_TRUE(f.gap(0.06, 0.0, 0.0005, d, nx, ny, nz));
  EXPECT_LT(d, 0.0);
}

TEST(ConeWall, AListCandidateWhereverItCanStepIntoTheSolid) {
  dp::WallPrimitive c;
  c.shape = dp::WallPrimitive::Shape::cone_inside;
  c.axis = 2;
  c.radius = 0.1;
  c.radius_hi = 0.4;
  c.lo = 0.0;
  c.hi = 0.3;
  // 0.2 beside the top rim, 1 mm above the extent: 0.2 from the wall, but
  // 2 mm down it is 0.2 deep in it, so a candidate at a reach of 2 mm
  EXPECT_TRUE(c.near(0.6, 0.0, 0.301, 0.002));
  EXPECT_FALSE(c.near(0.6, 0.0, 0.304, 0.002));  // 4 mm above: out of reach of the extent
  // inside the hopper, far from the mantle and its line: no candidate
  EXPECT_FALSE(c.near(0.0, 0.0, 0.29, 0.002));
  EXPECT_FALSE(c.near(0.0, 0.0, 0.31, 0.002));
  // in the solid: always
  EXPECT_TRUE(c.near(5.0, 0.0, 0.2, 0.002));
}

TEST(WallMotion, PlaceAndSurfaceVelocity) {
  dp::WallPrimitive base;
  base.shape = dp::WallPrimitive::Shape::plane;
  const double v[3] = {0.5, 0, 0}, w[3] = {0, 0, 2.0}, o[3] = {0, 0, 0};
  base.set_motion(std::make_shared<dp::WallMotion>(dp::WallMotion::constant(v, w, o, 1.0, 3.0)));
  dp::WallPrimitive wall = base;
  wall.place(base, 2.0);
  EXPECT_DOUBLE_EQ(wall.p[0], 0.5);
  wall.place(base, 10.0);  // stopped at 3 s
  EXPECT_DOUBLE_EQ(wall.p[0], 1.0);
  double ux, uy, uz;
  wall.place(base, 2.0);
  wall.surface_velocity(0.5, 1.0, 0.0, ux, uy, uz);  // r = (0, 1, 0) from the moved origin
  EXPECT_DOUBLE_EQ(ux, 0.5 - 2.0);
  EXPECT_NEAR(uy, 0.0, 1e-15);
  wall.place(base, 3.5);
  wall.surface_velocity(0.5, 1.0, 0.0, ux, uy, uz);
  EXPECT_EQ(ux, 0.0);
}

TEST(WallMotion, MeshRotatesAboutAnAxisThroughItsMovingOrigin) {
  // one triangle, turned a quarter turn about z through (1, 0, 0) while the
  // origin moves at (0, 0, 1) m/s; its displacement bound covers the motion
  const std::vector<double> soup = {2, 0, 0, 3, 0, 0, 2, 1, 0};
  auto mesh = std::make_shared<dp::TriangleMesh>(dp::TriangleMesh::from_soup(soup, 1e-9));
  dp::WallPrimitive base;
  base.shape = dp::WallPrimitive::Shape::mesh;
  base.mesh = mesh;
  base.verts = mesh->vertices;
  const double v[3] = {0, 0, 1.0}, w[3] = {0, 0, M_PI / 2}, o[3] = {1.0, 0, 0};
  base.set_motion(std::make_shared<dp::WallMotion>(dp::WallMotion::constant(v, w, o, 0.0)));
  dp::WallPrimitive wall = base;
  wall.place(base, 1.0);
  // (2,0,0) -> origin + R(90)(1,0,0) + (0,0,1) = (1, 1, 1); (3,0,0) -> (1, 2, 1); (2,1,0) -> (0, 1, 1)
  const double expected[9] = {1, 1, 1, 1, 2, 1, 0, 1, 1};
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(wall.verts[k], expected[k], 1e-12) << k;
  // the moved vertices lie within the bound
  const double moved = std::hypot(std::hypot(3 - 1.0, 0 - 2.0), 1.0);
  EXPECT_GE(wall.displacement_bound(0.0, 1.0), moved);
  // surface velocity of the vertex (1, 2, 1): omega x (0, 2, 0) + v = (-pi, 0, 1)
  double ux, uy, uz;
  wall.surface_velocity(1, 2, 1, ux, uy, uz);
  EXPECT_NEAR(ux, -M_PI, 1e-12);
  EXPECT_NEAR(uy, 0.0, 1e-12);
  EXPECT_NEAR(uz, 1.0, 1e-12);
}

// A motion list: a rotation about z through the origin (0 to 1 s), then a
// translation (from 1 s) that carries the turned wall, superposed with a
// vibration along x. Each placement is checked against the composition
// written out by hand, and every surface velocity against the central
// difference of the placement (the pose's rates are its time derivative).
TEST(WallMotion, ListsComposeInOrderAndTheirVelocityIsTheDerivative) {
  auto m = std::make_shared<dp::WallMotion>();
  dp::MotionItem rot;
  rot.kind = dp::MotionItem::Kind::rotation;
  rot.vec[2] = M_PI / 2;  // a quarter turn in 1 s
  rot.end = 1.0;
  dp::MotionItem tr;
  tr.kind = dp::MotionItem::Kind::translation;
  tr.vec[1] = 0.3;
  tr.start = 1.0;
  dp::MotionItem vib;
  vib.kind = dp::MotionItem::Kind::vibration;
  vib.vec[0] = 0.01;
  vib.omega_f = 2 * M_PI * 5.0;
  vib.phase = 0.4;
  m->items = {rot, tr, vib};
  const double x0[3] = {1.0, 0.0, 0.5};
  auto placed = [&](double t, double x[3]) { m->pose_at(t).apply(x0, x); };
  // at t = 2: turned a quarter (1, 0, .5) -> (0, 1, .5), then moved 0.3 in y, then the vibration's displacement
  double x[3];
  placed(2.0, x);
  const double vib_d = 0.01 * (std::sin(2 * M_PI * 5.0 * 2.0 + 0.4) - std::sin(0.4));
  EXPECT_NEAR(x[0], vib_d, 1e-12);
  EXPECT_NEAR(x[1], 1.0 + 0.3, 1e-12);
  EXPECT_NEAR(x[2], 0.5, 1e-12);
  for (double t : {0.3, 0.7, 1.5, 2.05}) {
    const double h = 1e-6;
    double xp[3], xm[3], xc[3], u[3];
    placed(t + h, xp);
    placed(t - h, xm);
    placed(t, xc);
    m->pose_at(t).velocity(xc, u);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(u[a], (xp[a] - xm[a]) / (2 * h), 1e-6) << "t " << t << " axis " << a;
    // the bound covers the move from any earlier time
    const std::vector<double> reach = {std::hypot(x0[0], x0[1]), 0, 0};
    for (double t0 : {0.0, 0.5 * t}) {
      double x0p[3];
      placed(t0, x0p);
      EXPECT_GE(m->displacement_bound(t0, t, reach) + 1e-12,
                std::hypot(std::hypot(xc[0] - x0p[0], xc[1] - x0p[1]), xc[2] - x0p[2]));
    }
  }
}

// A servo's travel is continuous and piecewise linear in time; its bound is
// its speed limit times the time.
TEST(WallMotion, ServoTravelFollowsTheVelocitiesItIsGiven) {
  auto state = std::make_shared<dp::ServoState>();
  state->max_velocity = 0.2;
  dp::MotionItem s;
  s.kind = dp::MotionItem::Kind::servo;
  s.vec[2] = -1.0;
  s.servo = state;
  dp::WallMotion m;
  m.items = {s};
  state->set_velocity(0.0, 0.2);
  state->set_velocity(1.0, -0.1);
  EXPECT_NEAR(state->travel(1.0), 0.2, 1e-15);
  EXPECT_NEAR(state->travel(3.0), 0.0, 1e-15);
  const dp::WallPose p = m.pose_at(1.5);
  EXPECT_NEAR(p.d[2], -0.15, 1e-15);
  EXPECT_NEAR(p.d_dot[2], 0.1, 1e-15);
  EXPECT_NEAR(m.displacement_bound(1.0, 1.5, {0.0}), 0.1, 1e-15);
}
