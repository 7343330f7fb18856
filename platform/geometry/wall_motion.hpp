// SPDX-License-Identifier: MIT
// How a wall moves: a list of motion items (walls[].motion), each active
// from its `start` to its `end`, composed in list order into one rigid
// placement x = R(t) x0 + d(t) of the wall's reference geometry x0:
//
//   translation  d += v e                                 (e: time spent in the item, clamped to its window)
//   vibration    d += A (sin(2 pi f e + phi) - sin(phi))  (no jump at its start)
//   rotation     x -> R(omega e) (x - o) + o              (about an axis through o, fixed in space)
//   servo        d += u s(t)                              (s: the servo's travel along u, ServoState)
//
// Items that overlap in time superpose; items one after the other form a
// sequence. An item acts on the wall as the earlier items left it, so a
// rotation listed before a translation turns about an axis that the
// translation then carries along (a drum on a cart), while one listed after
// it turns about an axis fixed in space.
//
// The surface velocity of a point x is ddot + Omega x (x - d), with the
// world angular velocity Omega and the rate ddot of the composition
// (derived beside WallMotion::pose_at). A servo's travel is state, not a function
// of time: its controller (scheduler/servo.hpp) sets its velocity between
// macro steps.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

namespace domel::platform {

/// A servo item's travel s(t) along its direction: s_ref at t_ref, then the
/// velocity `velocity` the controller last set (piecewise linear in time).
struct ServoState {
  double s_ref = 0.0;     ///< [m] travel at t_ref
  double t_ref = 0.0;     ///< [s]
  double velocity = 0.0;  ///< [m/s] along the servo's direction, from t_ref on
  double max_velocity = std::numeric_limits<double>::infinity();  ///< [m/s] |velocity| never exceeds it
  double travel(double t) const { return s_ref + velocity * std::max(0.0, t - t_ref); }
  /// Set a new velocity from time t on (travel stays continuous).
  void set_velocity(double t, double v) {
    s_ref = travel(t);
    t_ref = std::max(t, t_ref);
    velocity = v;
  }
};

struct MotionItem {
  enum class Kind { translation, vibration, rotation, servo };
  Kind kind = Kind::translation;
  double start = 0.0;
  double end = std::numeric_limits<double>::infinity();
  double vec[3] = {0, 0, 0};     ///< translation: velocity; vibration: amplitude; rotation: angular velocity; servo: unit direction
  double origin[3] = {0, 0, 0};  ///< rotation: a point on the axis
  double omega_f = 0.0;          ///< vibration: angular frequency 2 pi f [rad/s]
  double phase = 0.0;            ///< vibration: phase [rad]
  std::shared_ptr<ServoState> servo;  ///< servo: its travel (shared with the controller)

  bool active(double t) const { return t >= start && t < end; }
  /// Time spent in the item up to t.
  double elapsed(double t) const { return std::max(0.0, std::min(t, end) - start); }
};

/// The placement of a wall at one time: x = R x0 + d, and its rates.
struct WallPose {
  double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major
  double d[3] = {0, 0, 0};
  double omega[3] = {0, 0, 0};  ///< world angular velocity [rad/s]
  double d_dot[3] = {0, 0, 0};  ///< [m/s]

  void apply(const double x0[3], double x[3]) const {
    for (int a = 0; a < 3; ++a) x[a] = R[3 * a] * x0[0] + R[3 * a + 1] * x0[1] + R[3 * a + 2] * x0[2] + d[a];
  }
  void rotate(const double v0[3], double v[3]) const {
    for (int a = 0; a < 3; ++a) v[a] = R[3 * a] * v0[0] + R[3 * a + 1] * v0[1] + R[3 * a + 2] * v0[2];
  }
  /// Velocity of the point x (already placed): d_dot + omega x (x - d).
  void velocity(const double x[3], double u[3]) const {
    const double r[3] = {x[0] - d[0], x[1] - d[1], x[2] - d[2]};
    u[0] = d_dot[0] + omega[1] * r[2] - omega[2] * r[1];
    u[1] = d_dot[1] + omega[2] * r[0] - omega[0] * r[2];
    u[2] = d_dot[2] + omega[0] * r[1] - omega[1] * r[0];
  }
};

struct WallMotion {
  std::vector<MotionItem> items;

  /// One item of constant translation and/or rotation (the rotation first,
  /// so that the translation carries its axis), as a single motion object.
  static WallMotion constant(const double velocity[3], const double omega[3], const double origin[3], double start,
                             double end = std::numeric_limits<double>::infinity());

  WallPose pose_at(double t) const;

  /// The first rotation item with a non-zero angular velocity (null if none).
  const MotionItem* first_rotation() const;

  /// Upper bound of how far any point of a geometry moved between t0 and t1
  /// (the wall list is rebuilt beyond skin/2). reach[i] bounds the distance
  /// of the reference geometry from rotation item i's axis (unused for other
  /// items); a geometry an item's rotation maps onto itself has reach 0.
  double displacement_bound(double t0, double t1, const std::vector<double>& reach) const;
};

}  // namespace domel::platform
