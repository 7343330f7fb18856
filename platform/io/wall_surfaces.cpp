// SPDX-License-Identifier: MIT
// Wall primitives as polygons (append_wall_surface) and their series.
#include "io/wall_surfaces.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>


namespace domel::platform::io {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Two unit vectors completing the unit n to a right-handed basis.
void basis(const double n[3], double u[3], double v[3]) {
  const int a = std::fabs(n[0]) < 0.9 ? 0 : 1;  // the axis least parallel to n
  double e[3] = {0, 0, 0};
  e[a] = 1.0;
  u[0] = n[1] * e[2] - n[2] * e[1];
  u[1] = n[2] * e[0] - n[0] * e[2];
  u[2] = n[0] * e[1] - n[1] * e[0];
  const double l = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (int k = 0; k < 3; ++k) u[k] /= l;
  v[0] = n[1] * u[2] - n[2] * u[1];
  v[1] = n[2] * u[0] - n[0] * u[2];
  v[2] = n[0] * u[1] - n[1] * u[0];
}

std::int64_t add_point(SurfacePolygons& out, double x, double y, double z) {
  out.points.insert(out.points.end(), {x, y, z});
  return static_cast<std::int64_t>(out.points.size() / 3 - 1);
}

void add_polygon(SurfacePolygons& out, std::initializer_list<std::int64_t> ids, std::int32_t wall) {
  out.connectivity.insert(out.connectivity.end(), ids);
  out.offsets.push_back(static_cast<std::int64_t>(out.connectivity.size()));
  out.wall.push_back(wall);
}

/// The farthest corner of [lo, hi] from p.
double reach(const double p[3], const double lo[3], const double hi[3]) {
  double r2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max(std::fabs(p[a] - lo[a]), std::fabs(p[a] - hi[a]));
    r2 += d * d;
  }
  return std::sqrt(r2);
}

/// A ring r0 <= rho <= r1 (a disk for r0 = 0) about p in the plane of normal n.
void ring(SurfacePolygons& out, const double p[3], const double n[3], double r0, double r1, std::int32_t wall) {
  double u[3], v[3];
  basis(n, u, v);
  auto at = [&](double r, int s) {
    const double phi = 2.0 * kPi * s / kWallSegments;
    const double c = r * std::cos(phi), d = r * std::sin(phi);
    return add_point(out, p[0] + c * u[0] + d * v[0], p[1] + c * u[1] + d * v[1], p[2] + c * u[2] + d * v[2]);
  };
  if (r0 <= 0.0) {  // one polygon
    for (int s = 0; s < kWallSegments; ++s) out.connectivity.push_back(at(r1, s));
    out.offsets.push_back(static_cast<std::int64_t>(out.connectivity.size()));
    out.wall.push_back(wall);
    return;
  }
  std::vector<std::int64_t> in, outer;
  for (int s = 0; s < kWallSegments; ++s) {
    in.push_back(at(r0, s));
    outer.push_back(at(r1, s));
  }
  for (int s = 0; s < kWallSegments; ++s) {
    const int t = (s + 1) % kWallSegments;
    add_polygon(out, {in[s], outer[s], outer[t], in[t]}, wall);
  }
}

/// The mantle of an axis-aligned frustum (a cylinder when r_lo = r_hi).
void mantle(SurfacePolygons& out, const WallPrimitive& w, double r_lo, double r_hi, std::int32_t wall) {
  const int a = w.axis, b = (w.axis + 1) % 3, c = (w.axis + 2) % 3;
  std::vector<std::int64_t> bottom, top;
  for (int s = 0; s < kWallSegments; ++s) {
    const double phi = 2.0 * kPi * s / kWallSegments;
    double p[3];
    for (const auto& [r, along, ring_ids] : {std::tuple{r_lo, w.lo, &bottom}, std::tuple{r_hi, w.hi, &top}}) {
      p[a] = along;
      p[b] = w.c[b] + r * std::cos(phi);
      p[c] = w.c[c] + r * std::sin(phi);
      ring_ids->push_back(add_point(out, p[0], p[1], p[2]));
    }
  }
  for (int s = 0; s < kWallSegments; ++s) {
    const int t = (s + 1) % kWallSegments;
    add_polygon(out, {bottom[s], bottom[t], top[t], top[s]}, wall);
  }
}

/// The plane through p with unit normal n clipped to the box [lo, hi]: the
/// points where it cuts the box's twelve edges, in order around their centre.
void clipped_plane(SurfacePolygons& out, const double p[3], const double n[3], const double lo[3],
                   const double hi[3], std::int32_t wall) {
  std::vector<std::array<double, 3>> cut;
  auto corner = [&](int k, double q[3]) {
    for (int a = 0; a < 3; ++a) q[a] = (k >> a) & 1 ? hi[a] : lo[a];
  };
  auto side = [&](const double q[3]) {
    return (q[0] - p[0]) * n[0] + (q[1] - p[1]) * n[1] + (q[2] - p[2]) * n[2];
  };
  for (int k = 0; k < 8; ++k)
    for (int a = 0; a < 3; ++a) {
      if ((k >> a) & 1) continue;  // each edge once, from its lower corner
      double q0[3], q1[3];
      corner(k, q0);
      corner(k | (1 << a), q1);
      const double s0 = side(q0), s1 = side(q1);
      if ((s0 < 0) == (s1 < 0) && s0 != 0 && s1 != 0) continue;
      if (s0 == s1) continue;  // the edge lies in the plane: its corners come from the edges that cross
      const double f = s0 / (s0 - s1);
      std::array<double, 3> x{};
      for (int b = 0; b < 3; ++b) x[b] = q0[b] + f * (q1[b] - q0[b]);
      bool seen = false;
      for (const auto& y : cut)
        seen = seen || (std::fabs(y[0] - x[0]) + std::fabs(y[1] - x[1]) + std::fabs(y[2] - x[2]) <
                        1e-12 * (1.0 + reach(p, lo, hi)));
      if (!seen) cut.push_back(x);
    }
  if (cut.size() < 3) return;
  double m[3] = {0, 0, 0};
  for (const auto& x : cut)
    for (int a = 0; a < 3; ++a) m[a] += x[a] / static_cast<double>(cut.size());
  double u[3], v[3];
  basis(n, u, v);
  std::sort(cut.begin(), cut.end(), [&](const auto& x, const auto& y) {
    const double ax = std::atan2((x[0] - m[0]) * v[0] + (x[1] - m[1]) * v[1] + (x[2] - m[2]) * v[2],
                                 (x[0] - m[0]) * u[0] + (x[1] - m[1]) * u[1] + (x[2] - m[2]) * u[2]);
    const double ay = std::atan2((y[0] - m[0]) * v[0] + (y[1] - m[1]) * v[1] + (y[2] - m[2]) * v[2],
                                 (y[0] - m[0]) * u[0] + (y[1] - m[1]) * u[1] + (y[2] - m[2]) * u[2]);
    return ax < ay;
  });
  for (const auto& x : cut) out.connectivity.push_back(add_point(out, x[0], x[1], x[2]));
  out.offsets.push_back(static_cast<std::int64_t>(out.connectivity.size()));
  out.wall.push_back(wall);
}

}  // namespace

void append_wall_surface(const WallPrimitive& w, const double lo[3], const double hi[3], SurfacePolygons& out) {
  const auto wall = static_cast<std::int32_t>(w.wall);
  switch (w.shape) {
    case WallPrimitive::Shape::plane: {
      if (w.draw_in_box) {  // a box's face: its rectangle, moved with the wall
        const int a = std::fabs(w.n[0]) > 0.5 ? 0 : std::fabs(w.n[1]) > 0.5 ? 1 : 2;
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        double q[4][3];
        for (int k = 0; k < 4; ++k) {
          q[k][a] = w.p[a];
          q[k][b] = ((k == 1 || k == 2) ? w.draw_hi[b] : w.draw_lo[b]) + w.pose.d[b];
          q[k][c] = (k >= 2 ? w.draw_hi[c] : w.draw_lo[c]) + w.pose.d[c];
        }
        add_polygon(out,
                    {add_point(out, q[0][0], q[0][1], q[0][2]), add_point(out, q[1][0], q[1][1], q[1][2]),
                     add_point(out, q[2][0], q[2][1], q[2][2]), add_point(out, q[3][0], q[3][1], q[3][2])},
                    wall);
      } else if (w.draw_radius > 0) {
        ring(out, w.p, w.n, 0.0, w.draw_radius, wall);
      } else {
        clipped_plane(out, w.p, w.n, lo, hi, wall);
      }
      return;
    }
    case WallPrimitive::Shape::cylinder_inside: mantle(out, w, w.radius, w.radius, wall); return;
    case WallPrimitive::Shape::cone_inside: mantle(out, w, w.radius, w.radius_hi, wall); return;
    case WallPrimitive::Shape::annulus: {
      const double r1 = std::isfinite(w.r_outer) ? w.r_outer : w.draw_radius > 0 ? w.draw_radius : reach(w.p, lo, hi);
      ring(out, w.p, w.n, w.r_inner, r1, wall);
      return;
    }
    case WallPrimitive::Shape::mesh: {
      if (!w.mesh) return;
      const auto first = static_cast<std::int64_t>(out.points.size() / 3);
      out.points.insert(out.points.end(), w.verts.begin(), w.verts.end());
      const std::vector<std::uint32_t>& tri = w.mesh->tri;
      for (std::size_t t = 0; t + 2 < tri.size(); t += 3)
        add_polygon(out, {first + tri[t], first + tri[t + 1], first + tri[t + 2]}, wall);
      return;
    }
  }
}

WallSurfaceSeries::WallSurfaceSeries(fs::path directory, std::string basename)
    : frames_(std::move(directory), std::move(basename), "vtp") {}

fs::path WallSurfaceSeries::write(double time, const std::vector<WallPrimitive>& base, const double lo[3],
                                  const double hi[3]) {
  SurfacePolygons s;
  std::vector<double> velocity;
  for (const WallPrimitive& b : base) {
    if (!b.active(time)) continue;
    WallPrimitive w = b;
    if (w.moving) w.place(b, time);
    const std::size_t first = s.points.size();
    append_wall_surface(w, lo, hi, s);
    for (std::size_t k = first; k < s.points.size(); k += 3) {
      double u[3];
      w.surface_velocity(s.points[k], s.points[k + 1], s.points[k + 2], u[0], u[1], u[2]);
      velocity.insert(velocity.end(), u, u + 3);
    }
  }
  const auto np = static_cast<vtkIdType>(s.points.size() / 3);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(np);
  std::copy(s.points.begin(), s.points.end(), static_cast<double*>(points->GetData()->GetVoidPointer(0)));
  vtkNew<vtkDoubleArray> vel;
  vel->SetName("velocity");
  vel->SetNumberOfComponents(3);
  vel->SetNumberOfTuples(np);
  std::copy(velocity.begin(), velocity.end(), vel->GetPointer(0));
  vtkNew<vtkTypeInt64Array> offsets, connectivity;
  offsets->SetNumberOfTuples(static_cast<vtkIdType>(s.offsets.size()));
  std::copy(s.offsets.begin(), s.offsets.end(), offsets->GetPointer(0));
  connectivity->SetNumberOfTuples(static_cast<vtkIdType>(s.connectivity.size()));
  std::copy(s.connectivity.begin(), s.connectivity.end(), connectivity->GetPointer(0));
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);
  vtkNew<vtkIntArray> wall;
  wall->SetName("wall");
  wall->SetNumberOfTuples(static_cast<vtkIdType>(s.wall.size()));
  std::copy(s.wall.begin(), s.wall.end(), wall->GetPointer(0));

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetPolys(polys);
  poly->GetPointData()->AddArray(vel);
  poly->GetCellData()->AddArray(wall);

  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(poly);
  return frames_.write(*writer, time);
}

}  // namespace domel::platform::io
