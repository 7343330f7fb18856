// SPDX-License-Identifier: MIT
#include "core/gravity.hpp"

#include "core/rotation.hpp"

#include <algorithm>
#include <cmath>

namespace domel::platform {

GravitySchedule GravitySchedule::constant(const double g[3]) {
  GravitySchedule s;
  s.rows_.push_back({0.0, g[0], g[1], g[2]});
  return s;
}

GravitySchedule GravitySchedule::table(std::vector<std::array<double, 4>> rows) {
  GravitySchedule s;
  s.kind_ = rows.size() > 1 ? Kind::table : Kind::constant;
  s.rows_ = std::move(rows);
  return s;
}

GravitySchedule GravitySchedule::rotating(const double g0[3], const double axis[3], double rate, double start,
                                          double end) {
  GravitySchedule s;
  s.kind_ = Kind::rotating;
  s.rows_.push_back({0.0, g0[0], g0[1], g0[2]});
  const double l = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  for (int a = 0; a < 3; ++a) s.axis_[a] = axis[a] / l;
  s.rate_ = rate;
  s.start_ = start;
  s.end_ = end;
  return s;
}

void GravitySchedule::at(double t, double g[3]) const {
  switch (kind_) {
    case Kind::constant:
      for (int a = 0; a < 3; ++a) g[a] = rows_[0][a + 1];
      return;
    case Kind::table: {
      if (t <= rows_.front()[0]) {
        for (int a = 0; a < 3; ++a) g[a] = rows_.front()[a + 1];
        return;
      }
      if (t >= rows_.back()[0]) {
        for (int a = 0; a < 3; ++a) g[a] = rows_.back()[a + 1];
        return;
      }
      const auto hi = std::upper_bound(rows_.begin(), rows_.end(), t,
                                       [](double x, const std::array<double, 4>& r) { return x < r[0]; });
      const auto& r1 = *hi;
      const auto& r0 = *(hi - 1);
      const double u = (t - r0[0]) / (r1[0] - r0[0]);
      for (int a = 0; a < 3; ++a) g[a] = r0[a + 1] + u * (r1[a + 1] - r0[a + 1]);
      return;
    }
    case Kind::rotating: {
      double R[9];
      rotation_matrix(axis_, rate_ * std::max(0.0, std::min(t, end_) - start_), R);
      mat_vec(R, rows_[0].data() + 1, g);
      return;
    }
  }
}

}  // namespace domel::platform
