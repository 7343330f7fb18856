// SPDX-License-Identifier: MIT
// Guards the angle-of-repose probe (platform/subdomain/repose_probe.cpp) on
// heaps built with a known slope: a cone, a symmetric planar heap, and half a
// planar heap against a wall with its crest line given. Spheres are stacked in
// columns on a square grid of pitch d up to the surface h(r) = H - r tan(theta),
// so the highest particle top in each surface cell lies on the surface to
// within one diameter. The tolerance is the worst that staircase can do to the
// fitted line: a height error of one diameter across the fitted run L (the band
// of heights over tan(theta)) tilts the slope by d/L, i.e. the angle by
// (d/L) cos^2(theta).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "subdomain/repose_probe.hpp"

using domel::platform::ParticleStore;
using domel::platform::repose_angle;
using domel::platform::ReposeProbeSettings;

namespace {

constexpr double kD = 0.002;  // [m] sphere diameter
constexpr double kPi = 3.14159265358979323846;

// Columns of spheres on a grid of pitch kD over [x0, x1] x [y0, y1], each as high as surface(x, y) allows.
ParticleStore stack(double x0, double x1, double y0, double y1, const std::function<double(double, double)>& surface) {
  ParticleStore s;
  std::uint64_t id = 0;
  for (double x = x0 + 0.5 * kD; x < x1; x += kD)
    for (double y = y0 + 0.5 * kD; y < y1; y += kD)
      for (double z = 0.5 * kD; z + 0.5 * kD <= surface(x, y); z += kD) s.add(id++, x, y, z, 0.5 * kD, 2500.0);
  return s;
}

double tand(double deg) { return std::tan(deg * kPi / 180.0); }

constexpr double kHeight = 24 * kD;  // the heaps' height: a fitted run of about 40 diameters at 20 deg

// Half-width of the ground a heap of slope theta covers, with a margin of two diameters.
double foot(double theta, double height = kHeight) { return height / tand(theta) + 2 * kD; }

// [deg] The staircase's worst tilt of the fitted line (see the header) for a heap of this height and band width.
double tolerance(double theta, double height = kHeight, double band = 0.6) {
  const double run = band * height / tand(theta), c = std::cos(theta * kPi / 180.0);
  return kD / run * c * c * 180.0 / kPi;
}

}  // namespace

TEST(ReposeProbe, ConeGivesItsSlope) {
  for (double theta : {20.0, 30.0}) {
    const double h = kHeight, e = foot(theta);
    const auto s = stack(-e, e, -e, e, [&](double x, double y) { return h - std::hypot(x, y) * tand(theta); });
    ReposeProbeSettings p;
    const auto a = repose_angle(s, p);
    ASSERT_TRUE(a.has_value());
    EXPECT_NEAR(*a, theta, tolerance(theta)) << "cone of " << theta << " deg";
  }
}

TEST(ReposeProbe, SymmetricPlanarHeapAlongEitherAxis) {
  const double theta = 22.0, h = kHeight, e = foot(theta), w = 10 * kD;
  for (int axis : {0, 1}) {
    const auto s = axis == 0 ? stack(-e, e, -w, w, [&](double x, double) { return h - std::abs(x) * tand(theta); })
                             : stack(-w, w, -e, e, [&](double, double y) { return h - std::abs(y) * tand(theta); });
    ReposeProbeSettings p;
    p.planar = true;
    p.axis = axis;
    const auto a = repose_angle(s, p);
    ASSERT_TRUE(a.has_value());
    EXPECT_NEAR(*a, theta, tolerance(theta)) << "axis " << axis;
    // Along the other axis the ridge is level: no slope, or none near theta.
    p.axis = 1 - axis;
    const auto across = repose_angle(s, p);
    EXPECT_TRUE(!across || std::abs(*across - theta) > 3 * tolerance(theta)) << "axis " << axis;
  }
}

// Half a planar heap of slope theta leaning on a wall at x = wall.
ParticleStore half_heap(double theta, double wall) {
  return stack(wall, wall + foot(theta), 0.0, 10 * kD, [&](double x, double) {
    return kHeight - (x - wall) * tand(theta);
  });
}

TEST(ReposeProbe, HalfPlanarHeapMeasuredFromItsCrestLine) {
  // Half a heap leaning on a wall at x = 0.01 m: its centroid lies a third of the way down the slope, so the crest
  // line is given (the wall).
  const double theta = 25.0, wall = 0.01;
  const auto s = half_heap(theta, wall);
  ReposeProbeSettings p;
  p.planar = true;
  p.crest = wall;
  const auto a = repose_angle(s, p);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(*a, theta, tolerance(theta));
}

// A crest line so far away that no cell index can hold the distance (1e300 m: run-time fuzzing start 12, where
// the conversion to an integer key was undefined) leaves nothing to fit: no angle, and no undefined behaviour
// (the sanitized build checks that).
TEST(ReposeProbe, ACrestBeyondAnyCellGivesNoAngle) {
  const auto s = half_heap(25.0, 0.01);
  ReposeProbeSettings p;
  p.planar = true;
  for (double crest : {1e300, -1e300, 1e30}) {
    p.crest = crest;
    EXPECT_FALSE(repose_angle(s, p).has_value()) << crest;
  }
}

TEST(ReposeProbe, BaseHeightAndBandSelectTheFittedPart) {
  // A cone on a 10 mm bed of particles: base_height at the bed's top keeps the bed out of the band.
  const double theta = 20.0, floor = 0.01, h = kHeight, e = foot(theta);
  const auto s = stack(-e, e, -e, e, [&](double x, double y) { return floor + h - std::hypot(x, y) * tand(theta); });
  ReposeProbeSettings p;
  p.base_height = floor;
  const auto a = repose_angle(s, p);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(*a, theta, tolerance(theta));
  // The middle fifth of a taller planar heap's flank (band 0.4-0.6) gives its slope too.
  const double tall = 2.5 * kHeight, et = foot(theta, tall);
  const auto t = stack(-et, et, -5 * kD, 5 * kD, [&](double x, double) { return tall - std::abs(x) * tand(theta); });
  ReposeProbeSettings q;
  q.planar = true;
  q.band_lo = 0.4;
  q.band_hi = 0.6;
  const auto b = repose_angle(t, q);
  ASSERT_TRUE(b.has_value());
  EXPECT_NEAR(*b, theta, tolerance(theta, tall, 0.2));
}

TEST(ReposeProbe, NoHeapNoAngle) {
  ParticleStore s;
  for (int k = 0; k < 5; ++k) s.add(k, k * kD, 0, 0.5 * kD, 0.5 * kD, 2500.0);
  EXPECT_FALSE(repose_angle(s, ReposeProbeSettings{}).has_value());  // under 10 particles
}

TEST(ReposeProbe, RegionAndSpeedLimitSelectTheHeap) {
  // A cone heap on a plate at the origin, a second heap 0.5 m away (the rest
  // of a scene) and particles flying fast over the first heap: with a region
  // around the plate and a speed limit the fit sees the first heap alone.
  const double theta = 25.0, h = kHeight, e = foot(theta);
  auto s = stack(-e, e, -e, e, [&](double x, double y) { return h - std::hypot(x, y) * tand(theta); });
  std::uint64_t id = s.size();
  for (double x = 0.5 - e; x < 0.5 + e; x += kD)  // a flat layer elsewhere, 6 diameters thick
    for (double y = -e; y < e; y += kD)
      for (int k = 0; k < 6; ++k) s.add(id++, x, y, (k + 0.5) * kD, 0.5 * kD, 2500.0);
  for (int k = 0; k < 40; ++k) {  // a cloud of fast particles above the heap's slope
    s.add(id, 0.3 * e * std::cos(k), 0.3 * e * std::sin(k), h + (2 + k % 5) * kD, 0.5 * kD, 2500.0);
    s.vz[s.size() - 1] = 1.0;
    ++id;
  }
  ReposeProbeSettings p;
  const auto everything = repose_angle(s, p);
  EXPECT_TRUE(!everything || std::abs(*everything - theta) > 3 * tolerance(theta))
      << "the unfiltered fit should not find the heap's slope (check that the test's distractors distract)";
  p.region = domel_region_v1{};
  p.region->struct_size = sizeof(domel_region_v1);
  p.region->shape = 2;  // cylinder about z
  p.region->axis = 2;
  p.region->radius = e;
  p.region->lo[2] = 0.0;
  p.region->hi[2] = 1.0;
  p.max_speed = 0.05;
  const auto a = repose_angle(s, p);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(*a, theta, tolerance(theta));
}
