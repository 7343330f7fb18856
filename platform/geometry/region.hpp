// SPDX-License-Identifier: MIT
// Point-in-region test for the scenario's regions (the same box and
// axis-aligned cylinder the insertion ABI describes, domel_region_v1): used
// by deletion regions and pour bookkeeping.
#pragma once

#include <domel/sdk/abi.h>

namespace domel::platform {

/// True when (x, y, z) lies inside the region (boundary included).
inline bool region_contains(const domel_region_v1& r, double x, double y, double z) {
  const double p[3] = {x, y, z};
  if (r.shape == 1) {
    for (int a = 0; a < 3; ++a)
      if (p[a] < r.lo[a] || p[a] > r.hi[a]) return false;
    return true;
  }
  const int ax = static_cast<int>(r.axis);
  if (p[ax] < r.lo[ax] || p[ax] > r.hi[ax]) return false;
  double rho2 = 0.0;
  for (int a = 0; a < 3; ++a)
    if (a != ax) rho2 += (p[a] - r.center[a]) * (p[a] - r.center[a]);
  return rho2 <= r.radius * r.radius;
}

/// Extent of the region along the unit direction u (for the pour interval).
inline double region_extent(const domel_region_v1& r, const double u[3]) {
  double e = 0.0;
  if (r.shape == 1) {
    for (int a = 0; a < 3; ++a) e += (r.hi[a] - r.lo[a]) * (u[a] < 0 ? -u[a] : u[a]);
    return e;
  }
  const int ax = static_cast<int>(r.axis);
  const double along = u[ax] < 0 ? -u[ax] : u[ax];
  const double across2 = 1.0 - along * along;
  return (r.hi[ax] - r.lo[ax]) * along + 2.0 * r.radius * (across2 > 0 ? __builtin_sqrt(across2) : 0.0);
}

}  // namespace domel::platform
