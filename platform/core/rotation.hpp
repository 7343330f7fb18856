// SPDX-License-Identifier: MIT
// Rotation by an angle about a unit axis (Rodrigues' formula), shared by the
// wall motion (geometry/wall_motion.cpp) and gravity over time (core/gravity.cpp).
#pragma once

#include <cmath>

namespace domel::platform {

/// R = cos a I + sin a [k]x + (1 - cos a) k k^T, row-major; k a unit vector.
inline void rotation_matrix(const double k[3], double angle, double R[9]) {
  const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
  R[0] = c + k[0] * k[0] * t;        R[1] = k[0] * k[1] * t - k[2] * s; R[2] = k[0] * k[2] * t + k[1] * s;
  R[3] = k[1] * k[0] * t + k[2] * s; R[4] = c + k[1] * k[1] * t;        R[5] = k[1] * k[2] * t - k[0] * s;
  R[6] = k[2] * k[0] * t - k[1] * s; R[7] = k[2] * k[1] * t + k[0] * s; R[8] = c + k[2] * k[2] * t;
}

/// out = M v, M row-major 3x3.
inline void mat_vec(const double M[9], const double v[3], double out[3]) {
  for (int a = 0; a < 3; ++a) out[a] = M[3 * a] * v[0] + M[3 * a + 1] * v[1] + M[3 * a + 2] * v[2];
}

/// Whether two vectors are parallel (or either is zero), to 1e-9 of their lengths' product.
inline bool parallel(const double a[3], const double b[3]) {
  const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  return std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) <= 1e-9 * la * lb;
}

}  // namespace domel::platform
