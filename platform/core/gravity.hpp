// SPDX-License-Identifier: MIT
// Gravity over simulated time (the scenario's `gravity`): a constant
// vector, a table of vectors interpolated linearly in time (held at its
// first and last rows outside it), or a vector turned at a constant rate
// about an axis between two times (a tilting test). The subdomains read it
// once per step, for the forces of the step's end.
#pragma once

#include <array>
#include <limits>
#include <vector>

namespace domel::platform {

class GravitySchedule {
 public:
  static GravitySchedule constant(const double g[3]);
  /// rows (t, gx, gy, gz), t strictly increasing
  static GravitySchedule table(std::vector<std::array<double, 4>> rows);
  /// g0 turned by rate (t - start) about the unit axis, from start to end (held after)
  static GravitySchedule rotating(const double g0[3], const double axis[3], double rate, double start,
                                  double end = std::numeric_limits<double>::infinity());

  /// False for a constant vector.
  bool varies() const { return kind_ != Kind::constant; }
  /// Gravity at time t [m/s^2].
  void at(double t, double g[3]) const;

 private:
  enum class Kind { constant, table, rotating };
  Kind kind_ = Kind::constant;
  std::vector<std::array<double, 4>> rows_;  ///< constant: one row
  double axis_[3] = {0, 0, 1};
  double rate_ = 0, start_ = 0, end_ = std::numeric_limits<double>::infinity();
};

}  // namespace domel::platform
