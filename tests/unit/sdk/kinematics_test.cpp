// Guards the SDK's rolling kinematics helpers (sdk/include/domel/sdk/kinematics.hpp,
// docs/physics.md §2 and §3.4): omega_r is the part of omega_i - omega_j
// perpendicular to n, and a history vector carried into a new tangent plane
// lies in it and keeps its length. Tolerance: a few ulps of the vectors'
// size (1e-15 relative), as each result is a handful of roundings.
#include <domel/sdk/kinematics.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using domel::sdk::Vec3;

double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
Vec3 unit(double x, double y, double z) {
  const double l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}

}  // namespace

TEST(SdkKinematics, RollingVelocityIsThePartPerpendicularToN) {
  const Vec3 n = unit(1.0, -2.0, 0.5);
  const Vec3 w{3.0, 1.0, -4.0};
  const Vec3 r = domel::sdk::rolling_velocity(w.x, w.y, w.z, n.x, n.y, n.z);
  EXPECT_NEAR(dot(r, n), 0.0, 1e-15 * norm(w));
  // w = r + (w.n) n
  const double wn = dot(w, n);
  EXPECT_NEAR(r.x + wn * n.x, w.x, 1e-15 * norm(w));
  EXPECT_NEAR(r.y + wn * n.y, w.y, 1e-15 * norm(w));
  EXPECT_NEAR(r.z + wn * n.z, w.z, 1e-15 * norm(w));
  // a pure twist has no rolling part
  const Vec3 t = domel::sdk::rolling_velocity(2.0 * n.x, 2.0 * n.y, 2.0 * n.z, n.x, n.y, n.z);
  EXPECT_LT(norm(t), 1e-15 * 2.0);
}

TEST(SdkKinematics, TangentKeepLengthLiesInThePlaneWithTheSameLength) {
  const Vec3 h{1e-3, -2e-3, 5e-4};
  const Vec3 n = unit(0.3, 0.4, 1.0);
  const Vec3 t = domel::sdk::tangent_keep_length(h.x, h.y, h.z, n.x, n.y, n.z);
  EXPECT_NEAR(dot(t, n), 0.0, 1e-15 * norm(h));
  EXPECT_NEAR(norm(t), norm(h), 1e-15 * norm(h));
  // the direction is the projection's
  const double p = dot(h, n);
  const Vec3 proj{h.x - p * n.x, h.y - p * n.y, h.z - p * n.z};
  EXPECT_NEAR(dot(t, proj) / (norm(t) * norm(proj)), 1.0, 1e-15);
  // already in the plane: unchanged to rounding; along n: zero, returned as is
  const Vec3 same = domel::sdk::tangent_keep_length(proj.x, proj.y, proj.z, n.x, n.y, n.z);
  EXPECT_NEAR(same.x, proj.x, 1e-15 * norm(proj));
  const Vec3 along = domel::sdk::tangent_keep_length(0.0, 0.0, 0.0, n.x, n.y, n.z);
  EXPECT_EQ(norm(along), 0.0);
}

TEST(SdkKinematics, CapForceClampsAttractionToZero) {
  EXPECT_EQ(domel::sdk::cap_force(2.5), 2.5);
  EXPECT_EQ(domel::sdk::cap_force(-1.0), 0.0);
}
