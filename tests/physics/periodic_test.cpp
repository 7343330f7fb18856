// Guards periodic boundaries (subdomains[].periodic): an oblique, frictional
// collision of two spheres that travel through the periodic face while in
// contact (the lists are rebuilt and the positions wrapped several times
// during the contact, so the tangential history must follow the pair
// through each wrap) ends exactly as the same collision in the middle of a
// box without periodic boundaries; a sphere sliding on a floor crosses the
// face with its wall contact's history too.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace dt = domel::test;
using nlohmann::json;

namespace {
constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kL = 0.02;

struct Pair {
  double v[2][3], w[2][3], x[2][3];
  std::size_t builds = 0;
};

/// Two spheres, centres offset by (d - 0.1 mm, 0.6 mm, 0) at first contact
/// in x, moving at 5 m/s and 4 m/s along x (approach 1 m/s), starting at
/// x0; with `periodic`, x wraps at [0, kL).
Pair collide(double x0, bool periodic) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, 0.5);
  if (periodic) doc["subdomains"][0]["periodic"] = {{"x", {0.0, kL}}};
  auto sim = dt::build(doc);
  auto& sd = *sim->subdomains[0];
  auto& s = sd.store();
  s.add(1, x0, 0, 0, kR, kRho);
  s.add(2, x0 + kD + 0.0005, 0.0006, 0, kR, kRho);
  s.vx[0] = 5.0;
  s.vx[1] = 4.0;
  s.wz[0] = 30.0;  // a spin, so that the tangential force matters
  sd.set_time_step(2e-7);
  sd.set_skin(0.2 * kD);
  sd.setup();
  for (int k = 0; k < 20000; ++k) sd.step();  // 4 ms: 17 mm along x, the contact ~0.3 ms
  Pair p;
  for (int q = 0; q < 2; ++q) {
    const double v[3] = {s.vx[q], s.vy[q], s.vz[q]}, w[3] = {s.wx[q], s.wy[q], s.wz[q]},
                 x[3] = {s.x[q], s.y[q], s.z[q]};
    for (int a = 0; a < 3; ++a) {
      p.v[q][a] = v[a];
      p.w[q][a] = w[a];
      p.x[q][a] = x[a];
    }
  }
  p.builds = sd.neighbor_builds();
  return p;
}
}  // namespace

TEST(Periodic, ACollisionThroughThePeriodicFaceEndsAsOneInsideABox) {
  // The contact (about 0.3 ms) starts at x ~ 0.0178 and lasts while the
  // pair moves ~1.4 mm: through the face at x = 0.02. The reference starts
  // 0.1 m further on, in open space. Only round-off separates them (the
  // positions differ by 0.1 m and by the wraps): the post-collision
  // velocities agree to 1e-9 m/s, about 1e-9 of the speeds.
  const Pair per = collide(0.0178 - 0.0015, true);
  const Pair ref = collide(0.1178 - 0.0015, false);
  ASSERT_GT(std::fabs(ref.v[0][0] - 5.0), 0.1) << "no collision in the reference";
  ASSERT_GT(std::fabs(ref.v[0][1]), 0.01) << "an oblique collision moves the spheres apart in y";
  for (int q = 0; q < 2; ++q)
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(per.v[q][a], ref.v[q][a], 1e-9) << "sphere " << q << " v axis " << a;
      EXPECT_NEAR(per.w[q][a], ref.w[q][a], 1e-6) << "sphere " << q << " w axis " << a;  // w ~ v / R: 1e-9 / 1.4e-3
    }
  for (int q = 0; q < 2; ++q) {
    EXPECT_GE(per.x[q][0], -0.5 * 0.2 * kD) << "wrapped into the box (within half a skin)";
    EXPECT_LT(per.x[q][0], kL + 0.5 * 0.2 * kD);
    const double unwrapped = ref.x[q][0] - 0.1;
    EXPECT_NEAR(std::remainder(per.x[q][0] - unwrapped, kL), 0.0, 1e-9) << "one or more periods apart";
    EXPECT_NEAR(per.x[q][1], ref.x[q][1], 1e-9);
  }
  EXPECT_GT(per.builds, 10u) << "the lists were rebuilt (and the positions wrapped) along the way";
}

TEST(Periodic, ASphereSlidingOnAFloorCrossesTheFaceWithItsWallContact) {
  // A sphere launched along a floor at 1 m/s without spin slides until it
  // rolls at 5/7 of its speed (no rolling resistance), crossing x = kL
  // several times on the way: the same velocity as without periodic
  // boundaries, to round-off (1e-12 m/s).
  auto run = [](bool periodic) {
    json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, 0.5);
    doc["gravity"] = {0, 0, -9.81};
    dt::add_plane(doc, "floor", {0, 0, 0}, {0, 0, 1});
    if (periodic) doc["subdomains"][0]["periodic"] = {{"x", {0.0, kL}}};
    auto sim = dt::build(doc);
    auto& sd = *sim->subdomains[0];
    auto& s = sd.store();
    s.add(1, 0.01, 0, kR, kR, kRho);
    sd.set_time_step(2e-6);
    sd.set_skin(0.2 * kD);
    sd.setup();
    for (int k = 0; k < 5000; ++k) sd.step();  // settle
    s.vx[0] = 1.0;
    for (int k = 0; k < 50000; ++k) sd.step();  // 0.1 m: five periods
    return std::array<double, 3>{s.vx[0], s.wy[0], s.x[0]};
  };
  const auto per = run(true), ref = run(false);
  EXPECT_NEAR(ref[0], 5.0 / 7.0, 0.01 * 5.0 / 7.0);  // rolling: the physics the comparison rests on
  EXPECT_NEAR(per[0], ref[0], 1e-12);
  EXPECT_NEAR(per[1], ref[1], 1e-9);
  EXPECT_NEAR(std::remainder(per[2] - ref[2], kL), 0.0, 1e-9);
  EXPECT_LT(per[2], kL + 0.5 * 0.2 * kD);
}

TEST(Periodic, APairThroughTheFaceIsRecordedWithItsPartnersNearestImage) {
  // Two spheres overlapping by 0.1 mm through the face x = 0 / kL: the
  // contact record (contact files, the cell grids' contact stress) carries
  // the partner at its image, one period away, so the branch vector is the
  // short one, of length 2R - 0.1 mm.
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, 0.5);
  doc["subdomains"][0]["periodic"] = {{"x", {0.0, kL}}};
  auto sim = dt::build(doc);
  auto& sd = *sim->subdomains[0];
  auto& s = sd.store();
  const double gap = kD - 1e-4;  // centre distance through the face
  s.add(1, 0.5 * gap, 0.005, 0, kR, kRho);
  s.add(2, kL - 0.5 * gap, 0.005, 0, kR, kRho);
  sd.set_time_step(1e-7);
  sd.set_skin(0.2 * kD);
  sd.set_record_contacts(true);
  sd.setup();
  sd.step();
  std::size_t pairs = 0;
  for (const auto* list : sd.contact_records())
    for (const auto& r : *list) {
      if (r.j == domel::platform::ContactRecord::kWall) continue;
      ++pairs;
      const double l = std::hypot(std::hypot(s.x[r.i] - r.px, s.y[r.i] - r.py), s.z[r.i] - r.pz);
      EXPECT_NEAR(l, gap, 1e-6) << "the branch vector to the nearest image";
      EXPECT_NEAR(std::fabs(r.px - s.x[r.j]), kL, 1e-12);
      EXPECT_GT(std::fabs(r.fx), 0.0);
    }
  EXPECT_EQ(pairs, 1u);
}
