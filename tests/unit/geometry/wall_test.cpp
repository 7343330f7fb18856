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

TEST(WallMotion, PlaceAndSurfaceVelocity) {
  dp::WallPrimitive base;
  base.shape = dp::WallPrimitive::Shape::plane;
  base.moving = true;
  base.velocity[0] = 0.5;
  base.omega[2] = 2.0;
  base.motion_start = 1.0;
  base.motion_end = 3.0;
  dp::WallPrimitive w = base;
  w.place(base, 2.0);
  EXPECT_DOUBLE_EQ(w.p[0], 0.5);
  w.place(base, 10.0);  // stopped at 3 s
  EXPECT_DOUBLE_EQ(w.p[0], 1.0);
  double ux, uy, uz;
  w.place(base, 2.0);
  w.surface_velocity(2.0, 0.5, 1.0, 0.0, ux, uy, uz);  // r = (0, 1, 0) from the moved origin
  EXPECT_DOUBLE_EQ(ux, 0.5 - 2.0);
  EXPECT_DOUBLE_EQ(uy, 0.0);
  w.surface_velocity(3.5, 0.5, 1.0, 0.0, ux, uy, uz);
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
  base.moving = true;
  base.omega[2] = M_PI / 2;
  base.velocity[2] = 1.0;
  base.origin[0] = 1.0;
  dp::WallPrimitive w = base;
  w.place(base, 1.0);
  // (2,0,0) -> origin + R(90)(1,0,0) + (0,0,1) = (1, 1, 1); (3,0,0) -> (1, 2, 1); (2,1,0) -> (0, 1, 1)
  const double expected[9] = {1, 1, 1, 1, 2, 1, 0, 1, 1};
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(w.verts[k], expected[k], 1e-12) << k;
  // the moved vertices lie within the bound
  const double moved = std::hypot(std::hypot(3 - 1.0, 0 - 2.0), 1.0);
  EXPECT_GE(w.displacement_bound(0.0, 1.0), moved);
  // surface velocity of the vertex (1, 2, 1): omega x (0, 2, 0) + v = (-pi, 0, 1)
  double ux, uy, uz;
  w.surface_velocity(1.0, 1, 2, 1, ux, uy, uz);
  EXPECT_NEAR(ux, -M_PI, 1e-12);
  EXPECT_NEAR(uy, 0.0, 1e-12);
  EXPECT_NEAR(uz, 1.0, 1e-12);
}
