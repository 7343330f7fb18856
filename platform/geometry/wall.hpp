// SPDX-License-Identifier: MIT
// Wall primitives. Scenario walls (plane, box, cylinder and cone containers,
// disk, triangle mesh) are expanded into primitives: an infinite plane, the
// inside of a finite axis-aligned cylinder mantle, the inside of an
// axis-aligned frustum (cone) mantle, a flat annulus (a disk, or a plate with
// a round hole), or a triangle mesh. An analytic primitive answers one
// question per particle: how far is the sphere centre from the surface (on
// the particle side), and along which unit normal (from the wall towards the
// centre). Meshes have many features per particle and are evaluated by
// mesh_contacts() (geometry/triangle_mesh.hpp) instead of gap().
//
// A primitive may move (WallPrimitive::moving): its wall's list of motion
// items (geometry/wall_motion.hpp). place() moves the geometry to a given
// time; surface_velocity() gives the velocity of a surface point there.
// Analytic primitives rotate only about axes parallel to their own (a plane
// or a disk about its normal); meshes rotate about any axis.
#pragma once

#include "geometry/triangle_mesh.hpp"
#include "geometry/wall_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

struct WallPrimitive {
  enum class Shape { plane, cylinder_inside, cone_inside, annulus, mesh };
  Shape shape = Shape::plane;
  std::string name;          ///< e.g. "container.zmin"
  std::size_t wall = 0;      ///< index of the scenario wall it belongs to (output.wall_loads, walls.pvd)
  std::size_t material = 0;  ///< index into the scenario's materials
  // plane: a point on it and the unit normal pointing to the particles' side
  // annulus: its centre and the unit normal pointing to the particles' side
  double p[3] = {0, 0, 0};
  double n[3] = {0, 0, 1};
  // cylinder / cone mantle, particles inside: axis 0/1/2, axis passes through
  // c, radius (cone: radius at lo), radius_hi (cone: radius at hi), extent
  // [lo, hi] along the axis
  int axis = 2;
  double c[3] = {0, 0, 0};
  double radius = 0.0;
  double radius_hi = 0.0;
  double lo = 0.0, hi = 0.0;
  // annulus: inner (hole) and outer radius; no contact beyond the outer one
  double r_inner = 0.0;
  double r_outer = std::numeric_limits<double>::infinity();
  // mesh: the reference geometry and the current vertex positions (x, y, z per vertex)
  std::shared_ptr<const TriangleMesh> mesh;
  std::vector<double> verts;
  std::vector<double> tri_bounds;  ///< enclosing sphere per triangle at `verts` (triangle_bounds())
  // Drawing only (walls.pvd): how far an unbounded primitive is drawn. A
  // plane with draw_in_box is the face of a box, drawn as its rectangle
  // [draw_lo, draw_hi]; a plane or an annulus with draw_radius > 0 closes a
  // container, drawn as a disk (a ring) out to that radius about p. Other
  // planes are clipped to the scene's box, other annuli without an outer
  // radius drawn out to the scene's reach.
  double draw_radius = 0.0;
  bool draw_in_box = false;
  double draw_lo[3] = {0, 0, 0}, draw_hi[3] = {0, 0, 0};
  /// simulated time from which the wall is gone (an outlet plug, a lifted cylinder)
  double remove_at = std::numeric_limits<double>::infinity();
  /// simulated time from which the wall acts (an outlet that opens); contacts start with zero history
  double active_from = -std::numeric_limits<double>::infinity();
  /// sum the contact forces on it (Subdomain::wall_load: a servo wall)
  bool track_load = false;

  // motion (geometry/wall_motion.hpp): null for a wall at rest
  bool moving = false;
  std::shared_ptr<const WallMotion> motion;
  std::vector<double> reach;  ///< per motion item: a rotation's reach (WallMotion::displacement_bound)
  WallPose pose;              ///< the placement applied by the last place()

  bool active(double t) const { return t >= active_from && t < remove_at; }

  /// Give this primitive (in its reference placement) a motion; a null or
  /// empty one leaves it at rest.
  void set_motion(std::shared_ptr<const WallMotion> m) {
    moving = m && !m->items.empty();
    motion = moving ? std::move(m) : nullptr;
    reach.assign(moving ? motion->items.size() : 0, 0.0);
    for (std::size_t i = 0; i < reach.size(); ++i) {
      const MotionItem& it = motion->items[i];
      if (it.kind != MotionItem::Kind::rotation) continue;
      if (shape == Shape::mesh) {
        reach[i] = mesh ? mesh->max_distance_from(it.origin) : 0.0;
        continue;
      }
      // an analytic primitive turns about an axis parallel to its own: it
      // moves only by the distance of its own axis (centre) from that one
      const double w = std::sqrt(it.vec[0] * it.vec[0] + it.vec[1] * it.vec[1] + it.vec[2] * it.vec[2]);
      if (shape == Shape::plane || w <= 0.0) continue;
      const double* ref = shape == Shape::annulus ? p : c;
      const double r[3] = {ref[0] - it.origin[0], ref[1] - it.origin[1], ref[2] - it.origin[2]};
      const double along = (r[0] * it.vec[0] + r[1] * it.vec[1] + r[2] * it.vec[2]) / w;
      reach[i] = std::sqrt(std::max(0.0, r[0] * r[0] + r[1] * r[1] + r[2] * r[2] - along * along));
    }
  }

  /// Upper bound of how far any point of the primitive moved between t0 and
  /// t1 (the wall list is rebuilt beyond skin/2).
  double displacement_bound(double t0, double t1) const {
    return moving ? motion->displacement_bound(t0, t1, reach) : 0.0;
  }

  /// Move the geometry of `base` (this primitive's reference state) to time
  /// t. Analytic primitives keep their normal and axis (their rotations are
  /// about an axis parallel to it: validated with the scenario).
  void place(const WallPrimitive& base, double t) {
    if (!moving) return;
    pose = motion->pose_at(t);
    pose.apply(base.p, p);
    pose.apply(base.c, c);
    lo = base.lo + pose.d[axis];
    hi = base.hi + pose.d[axis];
    if (shape != Shape::mesh || !mesh) return;
    const std::vector<double>& ref = mesh->vertices;
    verts.resize(ref.size());
    for (std::size_t v = 0; v < ref.size(); v += 3) pose.apply(&ref[v], &verts[v]);
    triangle_bounds(*mesh, verts, tri_bounds);
  }

  /// Velocity of the surface point (x, y, z) at the time of the last place().
  void surface_velocity(double x, double y, double z, double& ux, double& uy, double& uz) const {
    if (!moving) {
      ux = uy = uz = 0.0;
      return;
    }
    const double xp[3] = {x, y, z};
    double u[3];
    pose.velocity(xp, u);
    ux = u[0]; uy = u[1]; uz = u[2];
  }

  /// Distance `d` of the point from the surface (positive on the particle
  /// side) and unit normal (nx, ny, nz) from the wall to the point. Returns
  /// false when the point has no defined contact (outside a mantle's extent,
  /// beyond an annulus' outer radius). Not for meshes.
  bool gap(double x, double y, double z, double& d, double& nx, double& ny, double& nz) const {
    switch (shape) {
      case Shape::plane:
        d = (x - p[0]) * n[0] + (y - p[1]) * n[1] + (z - p[2]) * n[2];
        nx = n[0]; ny = n[1]; nz = n[2];
        return true;
      case Shape::cylinder_inside: {
        const double q[3] = {x - c[0], y - c[1], z - c[2]};
        const double along = (axis == 0 ? x : axis == 1 ? y : z);
        if (along < lo || along > hi) return false;
        double rx = q[0], ry = q[1], rz = q[2];
        if (axis == 0) rx = 0; else if (axis == 1) ry = 0; else rz = 0;
        const double rho = std::sqrt(rx * rx + ry * ry + rz * rz);
        if (rho <= 0.0) return false;
        d = radius - rho;
        nx = -rx / rho; ny = -ry / rho; nz = -rz / rho;
        return true;
      }
      case Shape::cone_inside: return cone_gap(x, y, z, d, nx, ny, nz);
      case Shape::annulus: return annulus_gap(x, y, z, d, nx, ny, nz);
      case Shape::mesh: return false;
    }
    return false;
  }

  /// Frustum mantle, a container like the cylinder: the wall is solid
  /// behind the mantle within its axial extent, i.e. where lo <= s <= hi and
  /// rho > R(s), the mantle's radius there. In the half-plane (rho, s)
  /// through the axis and the point, the mantle is the segment from
  /// (radius, lo) to (radius_hi, hi) and the contact point is the segment's
  /// closest point: on its interior a face contact along the segment's
  /// inward normal, past an end the rim circle (an edge contact, from any
  /// side outside the solid). The distance is that to the closest point,
  /// negative in the solid, so it is continuous everywhere but across the
  /// solid's ends beside the mantle (s = lo or hi, rho beyond the rim),
  /// where a cylinder's jumps too; near() keeps the points that can cross
  /// them. Returns false only on the rim circle itself.
  bool cone_gap(double x, double y, double z, double& d, double& nx, double& ny, double& nz) const {
    const double q[3] = {x - c[0], y - c[1], z - c[2]};
    const double s = (axis == 0 ? x : axis == 1 ? y : z);
    double r[3] = {q[0], q[1], q[2]};
    r[axis] = 0.0;
    const double rho = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    double er[3] = {0, 0, 0};
    if (rho > 0.0) {
      for (int a = 0; a < 3; ++a) er[a] = r[a] / rho;
    } else {  // exactly on the axis (a sphere seated in the outlet): any radial direction will do
      er[(axis + 1) % 3] = 1.0;
    }
    const double tr = radius_hi - radius, ts = hi - lo;
    const double len2 = tr * tr + ts * ts;
    // the side of the segment's line, positive on the axis side (unnormalised: only its sign is needed here)
    const bool solid = (rho - radius) * -ts + (s - lo) * tr < 0.0 && s >= lo && s <= hi;  // behind the mantle
    double u = ((rho - radius) * tr + (s - lo) * ts) / len2;
    double dr, ds;  // unit direction from the closest point to the point, in (rho, s)
    if (u > 0.0 && u < 1.0) {
      const double len = std::sqrt(len2);
      const double mr = -ts / len, ms = tr / len;  // inward unit normal of the segment
      d = (rho - radius) * mr + (s - lo) * ms;     // signed distance from the segment
      dr = mr; ds = ms;
      if (d < 0.0 && !solid) {  // behind the line beyond the extent (under a flat funnel): the outer face
        d = -d;
        dr = -mr; ds = -ms;
      }
    } else {
      u = u <= 0.0 ? 0.0 : 1.0;
      dr = rho - (radius + u * tr);
      ds = s - (lo + u * ts);
      d = std::sqrt(dr * dr + ds * ds);
      if (d <= 0.0) return false;
      dr /= d; ds /= d;
      if (solid) {  // in the solid, its nearest surface point is the rim: pushed towards it
        d = -d;
        dr = -dr; ds = -ds;
      }
    }
    double nv[3] = {dr * er[0], dr * er[1], dr * er[2]};
    nv[axis] += ds;
    nx = nv[0]; ny = nv[1]; nz = nv[2];
    return true;
  }

  /// Flat annulus r_inner <= rho <= r_outer in the plane through p with
  /// normal n: a face contact over the annulus from either side (a thin plate),
  /// an edge contact with the nearest point of the inner rim inside the hole
  /// and of the outer rim beyond the outer radius (from either side).
  bool annulus_gap(double x, double y, double z, double& d, double& nx, double& ny, double& nz) const {
    const double q[3] = {x - p[0], y - p[1], z - p[2]};
    const double h = q[0] * n[0] + q[1] * n[1] + q[2] * n[2];
    const double r[3] = {q[0] - h * n[0], q[1] - h * n[1], q[2] - h * n[2]};
    const double rho = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (rho > r_outer) {
      // Beyond the outer radius: the outer rim edge (the mirror of the hole's
      // rim below), so that a particle sliding in over the edge meets a
      // contact that grows from zero instead of a face overlap of up to R.
      const double dr = rho - r_outer;  // > 0
      d = std::sqrt(dr * dr + h * h);
      if (d <= 0.0) return false;
      const double a = dr / (d * rho), b = h / d;
      nx = a * r[0] + b * n[0]; ny = a * r[1] + b * n[1]; nz = a * r[2] + b * n[2];
      return true;
    }
    if (rho >= r_inner) {
      // Two-sided: a plate is thin, and a particle that left through the
      // hole may drift under it (silo_ci found one: as one-sided face its
      // "overlap" R - h exceeded R and the particle was shot away).
      const double sgn = h >= 0 ? 1.0 : -1.0;
      d = sgn * h;
      nx = sgn * n[0]; ny = sgn * n[1]; nz = sgn * n[2];
      return true;
    }
    const double dr = rho - r_inner;  // < 0: the rim is farther out than the point
    d = std::sqrt(dr * dr + h * h);
    if (d <= 0.0) return false;
    if (rho <= 1e-12 * r_inner) {  // on the hole's axis: the whole rim is equidistant; push along the axis
      const double sgn = h >= 0 ? 1.0 : -1.0;
      nx = sgn * n[0]; ny = sgn * n[1]; nz = sgn * n[2];
      return true;
    }
    const double a = dr / (d * rho), b = h / d;
    nx = a * r[0] + b * n[0]; ny = a * r[1] + b * n[1]; nz = a * r[2] + b * n[2];
    return true;
  }

  /// Conservative list-build test: may a sphere of radius `reach` (radius +
  /// skin) centred at the point touch this primitive?
  bool near(double x, double y, double z, double reach) const {
    double d, nx, ny, nz;
    switch (shape) {
      case Shape::cylinder_inside: {
        if (gap(x, y, z, d, nx, ny, nz)) return d < reach;
        const double along = (axis == 0 ? x : axis == 1 ? y : z);
        return along >= lo - reach && along <= hi + reach;
      }
      case Shape::annulus: {
        const double q[3] = {x - p[0], y - p[1], z - p[2]};
        const double h = q[0] * n[0] + q[1] * n[1] + q[2] * n[2];
        const double r[3] = {q[0] - h * n[0], q[1] - h * n[1], q[2] - h * n[2]};
        const double rho = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if (rho > r_outer + reach) return false;
        return gap(x, y, z, d, nx, ny, nz) && d < reach;
      }
      case Shape::cone_inside: {
        if (!gap(x, y, z, d, nx, ny, nz)) return true;  // on the rim circle: keep it (rare, cheap)
        if (d < reach) return true;
        // a point that can step into the solid behind the mantle (across its
        // ends, where the distance jumps) within `reach`: near the extent and
        // within reach of the segment's line (both move at most as far as
        // the point)
        const double s = (axis == 0 ? x : axis == 1 ? y : z);
        if (s < lo - reach || s > hi + reach) return false;
        double r[3] = {x - c[0], y - c[1], z - c[2]};
        r[axis] = 0.0;
        const double rho = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        const double tr = radius_hi - radius, ts = hi - lo;
        const double across = ((rho - radius) * -ts + (s - lo) * tr) / std::sqrt(tr * tr + ts * ts);
        return across < reach;
      }
      default: return gap(x, y, z, d, nx, ny, nz) && d < reach;
    }
  }
};

}  // namespace domel::platform
