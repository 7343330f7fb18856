// SPDX-License-Identifier: MIT
// Walls drawn for ParaView (io/wall_surfaces.hpp): each primitive's polygons
// lie on its surface and span what it is (a cylinder's mantle between its
// ends, a box's face as its rectangle, a plane clipped to the scene's box, a
// ring between its radii, a mesh's own triangles), and a moving wall is drawn
// where its motion has taken it, with its surface velocity.
#include "io/wall_surfaces.hpp"

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <unistd.h>

namespace dp = domel::platform;
namespace io = domel::platform::io;
namespace fs = std::filesystem;

namespace {

const double kLo[3] = {-1, -1, -1}, kHi[3] = {1, 1, 1};

dp::WallPrimitive cylinder() {
  dp::WallPrimitive w;
  w.shape = dp::WallPrimitive::Shape::cylinder_inside;
  w.axis = 2;
  w.c[0] = 0.1;
  w.c[1] = -0.2;
  w.radius = 0.3;
  w.lo = 0.0;
  w.hi = 0.5;
  w.wall = 4;
  return w;
}

}  // namespace

TEST(WallSurfaces, ACylinderMantleLiesAtItsRadiusBetweenItsEnds) {
  io::SurfacePolygons s;
  io::append_wall_surface(cylinder(), kLo, kHi, s);
  ASSERT_EQ(s.polygons(), static_cast<std::size_t>(io::kWallSegments));
  for (std::size_t k = 0; k < s.points.size(); k += 3) {
    EXPECT_NEAR(std::hypot(s.points[k] - 0.1, s.points[k + 1] + 0.2), 0.3, 1e-12);
    EXPECT_TRUE(s.points[k + 2] == 0.0 || s.points[k + 2] == 0.5);
  }
  for (int w : s.wall) EXPECT_EQ(w, 4);
}

TEST(WallSurfaces, ABoxFaceIsItsRectangleAndAPlaneIsClippedToTheScene) {
  dp::WallPrimitive face;  // the xmin face of a box [0.2, 0.4] x [0, 1] x [-1, 2]
  face.p[0] = 0.2;
  face.n[0] = 1;
  face.n[2] = 0;
  face.draw_in_box = true;
  const double lo[3] = {0.2, 0.0, -1.0}, hi[3] = {0.4, 1.0, 2.0};
  std::copy(lo, lo + 3, face.draw_lo);
  std::copy(hi, hi + 3, face.draw_hi);
  io::SurfacePolygons s;
  io::append_wall_surface(face, kLo, kHi, s);
  ASSERT_EQ(s.polygons(), 1u);
  ASSERT_EQ(s.points.size(), 12u);
  double area2 = 0;  // twice the polygon's area, in the y-z plane
  for (int k = 0; k < 4; ++k) {
    const int j = (k + 1) % 4;
    EXPECT_EQ(s.points[3 * k], 0.2);
    area2 += s.points[3 * k + 1] * s.points[3 * j + 2] - s.points[3 * j + 1] * s.points[3 * k + 2];
  }
  EXPECT_NEAR(std::fabs(area2) / 2, 1.0 * 3.0, 1e-12);

  dp::WallPrimitive tilted;  // z = x: cuts the scene's cube [-1, 1]^3 in a rectangle 2 x 2 sqrt(2)
  tilted.n[0] = -std::sqrt(0.5);
  tilted.n[2] = std::sqrt(0.5);
  io::SurfacePolygons t;
  io::append_wall_surface(tilted, kLo, kHi, t);
  ASSERT_EQ(t.polygons(), 1u);
  const std::size_t corners = t.points.size() / 3;
  EXPECT_EQ(corners, 4u);
  double cross[3] = {0, 0, 0};  // the polygon's vector area
  for (std::size_t k = 0; k < corners; ++k) {
    const double* a = &t.points[3 * k];
    const double* b = &t.points[3 * ((k + 1) % corners)];
    EXPECT_NEAR(a[2], a[0], 1e-12);
    cross[0] += a[1] * b[2] - a[2] * b[1];
    cross[1] += a[2] * b[0] - a[0] * b[2];
    cross[2] += a[0] * b[1] - a[1] * b[0];
  }
  EXPECT_NEAR(std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]) / 2, 4 * std::sqrt(2.0),
              1e-12);
}

TEST(WallSurfaces, AnAnnulusIsARingBetweenItsRadiiAndAContainerBottomADisk) {
  dp::WallPrimitive ring;
  ring.shape = dp::WallPrimitive::Shape::annulus;
  ring.r_inner = 0.1;
  ring.r_outer = 0.25;
  io::SurfacePolygons s;
  io::append_wall_surface(ring, kLo, kHi, s);
  EXPECT_EQ(s.polygons(), static_cast<std::size_t>(io::kWallSegments));
  for (std::size_t k = 0; k < s.points.size(); k += 3) {
    const double r = std::hypot(s.points[k], s.points[k + 1]);
    EXPECT_TRUE(std::fabs(r - 0.1) < 1e-12 || std::fabs(r - 0.25) < 1e-12) << r;
    EXPECT_EQ(s.points[k + 2], 0.0);
  }
  dp::WallPrimitive bottom;  // a plane closing a cylinder of radius 0.3: one disk polygon
  bottom.draw_radius = 0.3;
  io::SurfacePolygons d;
  io::append_wall_surface(bottom, kLo, kHi, d);
  ASSERT_EQ(d.polygons(), 1u);
  for (std::size_t k = 0; k < d.points.size(); k += 3) EXPECT_NEAR(std::hypot(d.points[k], d.points[k + 1]), 0.3, 1e-12);
}

TEST(WallSurfaces, AMovingWallIsWrittenWhereItsMotionTookItWithItsSurfaceVelocity) {
  dp::WallPrimitive w = cylinder();  // translating along x at 0.2 m/s, turning about its axis at 3 rad/s
  const double vel[3] = {0.2, 0, 0}, om[3] = {0, 0, 3.0};
  w.set_motion(std::make_shared<dp::WallMotion>(dp::WallMotion::constant(vel, om, w.c, 0.0)));
  dp::WallPrimitive gone = cylinder();  // removed before the frame: not drawn
  gone.remove_at = 0.5;
  const fs::path dir = fs::temp_directory_path() / ("domel_wall_surfaces_" + std::to_string(getpid()));
  fs::remove_all(dir);
  io::WallSurfaceSeries series(dir, "walls");
  const fs::path file = series.write(1.0, {w, gone}, kLo, kHi);
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(file.c_str());
  r->Update();
  vtkPolyData* p = r->GetOutput();
  ASSERT_EQ(p->GetNumberOfCells(), io::kWallSegments);
  vtkDataArray* v = p->GetPointData()->GetArray("velocity");
  ASSERT_NE(v, nullptr);
  for (vtkIdType k = 0; k < p->GetNumberOfPoints(); ++k) {
    double x[3];
    p->GetPoint(k, x);
    const double rx = x[0] - (0.1 + 0.2), ry = x[1] + 0.2;  // the axis moved by 0.2 m along x
    EXPECT_NEAR(std::hypot(rx, ry), 0.3, 1e-12);
    const double* u = v->GetTuple3(k);
    EXPECT_NEAR(u[0], 0.2 - 3.0 * ry, 1e-12);  // v + omega x r
    EXPECT_NEAR(u[1], 3.0 * rx, 1e-12);
  }
  EXPECT_EQ(p->GetCellData()->GetArray("wall")->GetTuple1(0), 4.0);
  EXPECT_TRUE(fs::exists(dir / "walls.pvd"));
  fs::remove_all(dir);
}
