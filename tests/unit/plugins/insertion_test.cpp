// SPDX-License-Identifier: MIT
// Unit tests of the built-in insertion library (plugins/insertion): the
// models are used directly through their C++ classes, and once through the
// C callbacks the SDK generates for them (the ABI the host calls).
#include "loader/plugin_registry.hpp"
#include "plugins/insertion/lattice.hpp"
#include "plugins/insertion/random_fill.hpp"
#include "plugins/insertion/region.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using domel::plugins::insertion::Lattice;
using domel::plugins::insertion::RandomFill;
using domel::sdk::Inserted;
using domel::sdk::ParameterError;
using domel::sdk::Params;
using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;

domel_insert_request_v1 box_request(double x0, double y0, double z0, double x1, double y1, double z1,
                                    uint64_t seed = 1, double alpha = 1.0) {
  domel_insert_request_v1 q{};
  q.struct_size = sizeof q;
  q.region.struct_size = sizeof q.region;
  q.region.shape = domel::plugins::insertion::kRegionBox;
  q.region.lo[0] = x0; q.region.lo[1] = y0; q.region.lo[2] = z0;
  q.region.hi[0] = x1; q.region.hi[1] = y1; q.region.hi[2] = z1;
  q.seed = seed;
  q.length_scale = alpha;
  return q;
}

domel_insert_request_v1 cylinder_request(uint32_t axis, double cx, double cy, double cz, double radius,
                                         double bottom, double top, uint64_t seed = 1) {
  domel_insert_request_v1 q{};
  q.struct_size = sizeof q;
  q.region.struct_size = sizeof q.region;
  q.region.shape = domel::plugins::insertion::kRegionCylinder;
  q.region.axis = axis;
  q.region.center[0] = cx; q.region.center[1] = cy; q.region.center[2] = cz;
  q.region.radius = radius;
  // Off-axis components of lo/hi are deliberately junk: only lo/hi[axis] count.
  for (int k = 0; k < 3; ++k) { q.region.lo[k] = -123.0; q.region.hi[k] = 456.0; }
  q.region.lo[axis] = bottom;
  q.region.hi[axis] = top;
  q.seed = seed;
  q.length_scale = 1.0;
  return q;
}

template <class M>
Inserted run(const json& params, const domel_insert_request_v1& req) {
  const M model{Params(params)};
  Inserted out;
  model.insert(req, out);
  return out;
}

template <class M>
std::string refusal(const json& params) {
  try {
    const M model{Params(params)};
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}

// Number of pairs closer than the sum of their radii (beyond rounding).
std::size_t overlapping_pairs(const Inserted& p) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double dx = p.x[i] - p.x[j], dy = p.y[i] - p.y[j], dz = p.z[i] - p.z[j];
      const double s = p.r[i] + p.r[j];
      if (std::sqrt(dx * dx + dy * dy + dz * dz) < s * (1.0 - 1e-12)) ++bad;
    }
  return bad;
}

// Number of particles whose sphere pokes out of the region (beyond rounding).
std::size_t outside(const Inserted& p, const domel_region_v1& g) {
  std::size_t bad = 0;
  const double eps = 1e-12;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double c[3] = {p.x[i], p.y[i], p.z[i]};
    if (g.shape == domel::plugins::insertion::kRegionCylinder) {
      const uint32_t a = g.axis, u = (a + 1) % 3, v = (a + 2) % 3;
      const double rho = std::hypot(c[u] - g.center[u], c[v] - g.center[v]);
      if (rho + p.r[i] > g.radius + eps || c[a] - p.r[i] < g.lo[a] - eps || c[a] + p.r[i] > g.hi[a] + eps) ++bad;
    } else {
      for (int k = 0; k < 3; ++k)
        if (c[k] - p.r[i] < g.lo[k] - eps || c[k] + p.r[i] > g.hi[k] + eps) { ++bad; break; }
    }
  }
  return bad;
}

bool same(const Inserted& a, const Inserted& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.r == b.r;
}

}  // namespace

// Guards the LIGGGHTS benchmark packing: 17x17x35 simple cubic sites, x fastest, from the corner.
TEST(LatticeInsertion, ReproducesBenchmarkDeck) {
  const double d = 0.0028, a = 1.02 * d;
  const auto out = run<Lattice>({{"diameter", d}, {"spacing", 1.02}},
                                box_request(0, 0, 0, 17 * a, 17 * a, 35 * a));
  ASSERT_EQ(out.size(), 17u * 17u * 35u);
  ASSERT_EQ(out.size(), 10115u);
  EXPECT_DOUBLE_EQ(out.x[0], a / 2);
  EXPECT_DOUBLE_EQ(out.y[0], a / 2);
  EXPECT_DOUBLE_EQ(out.z[0], a / 2);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double ix = static_cast<double>(k % 17), iy = static_cast<double>((k / 17) % 17),
                 iz = static_cast<double>(k / (17 * 17));
    ASSERT_NEAR(out.x[k], (ix + 0.5) * a, 1e-15) << "particle " << k;
    ASSERT_NEAR(out.y[k], (iy + 0.5) * a, 1e-15) << "particle " << k;
    ASSERT_NEAR(out.z[k], (iz + 0.5) * a, 1e-15) << "particle " << k;
    ASSERT_DOUBLE_EQ(out.r[k], d / 2);
  }
  EXPECT_EQ(overlapping_pairs(out), 0u);
}

// Guards the trimming of lattice sites to spheres fully inside a cylinder (both axis mappings).
TEST(LatticeInsertion, CylinderKeepsSpheresInside) {
  const double d = 0.01, big_r = 5 * d;
  const auto q = cylinder_request(2, 0.3, -0.2, 0.0, big_r, 1.0, 1.0 + 10 * d);
  const auto out = run<Lattice>({{"diameter", d}}, q);
  // Independent count: a 10x10 layer of sites at -5d + (i+0.5)d, kept when hypot + d/2 <= 5d.
  std::size_t per_layer = 0;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      if (std::hypot((i + 0.5 - 5) * d, (j + 0.5 - 5) * d) + d / 2 <= big_r + 1e-12) ++per_layer;
  ASSERT_GT(per_layer, 0u);
  ASSERT_LT(per_layer, 100u);
  EXPECT_EQ(out.size(), 10 * per_layer);
  EXPECT_EQ(outside(out, q.region), 0u);
  EXPECT_NEAR(out.z[0], 1.0 + d / 2, 1e-12);

  const auto qx = cylinder_request(0, 0.0, 0.0, 0.0, 3 * d, -0.05, 0.05);
  const auto along_x = run<Lattice>({{"diameter", d}, {"spacing", 1.1}}, qx);
  EXPECT_GT(along_x.size(), 0u);
  EXPECT_EQ(outside(along_x, qx.region), 0u);
}

// Guards jitter: bounded by jitter*d per coordinate, no overlaps, reproducible per seed.
TEST(LatticeInsertion, JitterIsDeterministicAndBounded) {
  const double d = 0.002, jitter = 0.1;
  const json plain = {{"diameter", d}, {"spacing", 1.2}};
  json jittered = plain;
  jittered["jitter"] = jitter;
  const auto base = run<Lattice>(plain, box_request(0, 0, 0, 0.03, 0.02, 0.04, 7));
  const auto a = run<Lattice>(jittered, box_request(0, 0, 0, 0.03, 0.02, 0.04, 7));
  const auto b = run<Lattice>(jittered, box_request(0, 0, 0, 0.03, 0.02, 0.04, 7));
  const auto c = run<Lattice>(jittered, box_request(0, 0, 0, 0.03, 0.02, 0.04, 8));
  ASSERT_EQ(a.size(), base.size());
  EXPECT_TRUE(same(a, b));
  EXPECT_FALSE(same(a, c));
  double largest = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    largest = std::max({largest, std::fabs(a.x[k] - base.x[k]), std::fabs(a.y[k] - base.y[k]),
                        std::fabs(a.z[k] - base.z[k])});
  }
  EXPECT_LE(largest, jitter * d * (1 + 1e-9));
  EXPECT_GT(largest, 0.5 * jitter * d);  // it really moved
  EXPECT_EQ(overlapping_pairs(a), 0u);
  EXPECT_EQ(outside(a, box_request(0, 0, 0, 0.03, 0.02, 0.04).region), 0u);
  // In a cylinder a jittered edge sphere could cross the curved wall; it must stay inside.
  const auto cyl = cylinder_request(2, 0, 0, 0, 12 * d, 0, 0.02, 9);
  const auto in_cyl = run<Lattice>({{"diameter", d}, {"spacing", 1.4}, {"jitter", 0.2}}, cyl);
  EXPECT_GT(in_cyl.size(), 100u);
  EXPECT_EQ(outside(in_cyl, cyl.region), 0u);
  EXPECT_EQ(overlapping_pairs(in_cyl), 0u);
}

// Guards the constructor's refusals: jitter beyond (spacing-1)/2, bad arrangement, bad numbers.
TEST(LatticeInsertion, RefusesUnsafeParameters) {
  const std::string msg = refusal<Lattice>({{"diameter", 0.001}, {"spacing", 1.1}, {"jitter", 0.06}});
  EXPECT_NE(msg.find("(spacing - 1)/2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("overlap"), std::string::npos) << msg;
  EXPECT_EQ(refusal<Lattice>({{"diameter", 0.001}, {"spacing", 1.1}, {"jitter", 0.05}}), "");
  EXPECT_NE(refusal<Lattice>({{"diameter", 0.001}, {"jitter", 0.01}}), "");  // spacing 1: no room
  EXPECT_NE(refusal<Lattice>({{"diameter", 0.001}, {"arrangement", "fcc"}}), "");
  EXPECT_NE(refusal<Lattice>({{"diameter", -0.001}}), "");
  EXPECT_NE(refusal<Lattice>({{"spacing", 1.5}}), "");
  EXPECT_NE(refusal<Lattice>({{"diameter", 0.001}, {"spacing", 0.9}}), "");
  EXPECT_NE(refusal<Lattice>({{"diameter", 0.001}, {"count", 2.5}}), "");
}

// Guards `count`: insertion stops after that many sites, which are the first of the full fill.
TEST(LatticeInsertion, StopsAtCount) {
  const double d = 0.0028, a = 1.02 * d;
  const auto q = box_request(0, 0, 0, 17 * a, 17 * a, 35 * a);
  const auto all = run<Lattice>({{"diameter", d}, {"spacing", 1.02}}, q);
  const auto some = run<Lattice>({{"diameter", d}, {"spacing", 1.02}, {"count", 300}}, q);
  ASSERT_EQ(some.size(), 300u);
  for (std::size_t k = 0; k < some.size(); ++k) {
    EXPECT_EQ(some.x[k], all.x[k]);
    EXPECT_EQ(some.y[k], all.y[k]);
    EXPECT_EQ(some.z[k], all.z[k]);
  }
  // A count above the number of sites simply fills every site.
  EXPECT_EQ(run<Lattice>({{"diameter", d}, {"spacing", 1.02}, {"count", 100000}}, q).size(), all.size());
}

// Guards that sites overlapping existing particles are skipped and do not count toward `count`.
TEST(LatticeInsertion, SkipsExistingParticles) {
  const double d = 0.01;
  auto q = box_request(0, 0, 0, 4 * d, 4 * d, 4 * d);
  const std::vector<double> ex_x = {0.5 * d, 2.5 * d, 10.0}, ex_y = {0.5 * d, 0.5 * d, 10.0},
                            ex_z = {0.5 * d, 0.5 * d, 10.0}, ex_r = {0.4 * d, 0.4 * d, 0.5};
  q.n_existing = ex_x.size();
  q.ex_x = ex_x.data(); q.ex_y = ex_y.data(); q.ex_z = ex_z.data(); q.ex_r = ex_r.data();
  const auto all = run<Lattice>({{"diameter", d}}, q);
  EXPECT_EQ(all.size(), 64u - 2u);
  EXPECT_DOUBLE_EQ(all.x[0], 1.5 * d);  // site 0 taken; site 1 is the first
  EXPECT_DOUBLE_EQ(all.x[1], 3.5 * d);  // site 2 taken
  const auto five = run<Lattice>({{"diameter", d}, {"count", 5}}, q);
  EXPECT_EQ(five.size(), 5u);
  // Touching is not overlapping: an existing sphere touching site 0 from below the box.
  const std::vector<double> tx = {0.5 * d}, ty = {-0.5 * d}, tz = {0.5 * d}, tr = {0.5 * d};
  q.n_existing = 1;
  q.ex_x = tx.data(); q.ex_y = ty.data(); q.ex_z = tz.data(); q.ex_r = tr.data();
  EXPECT_EQ(run<Lattice>({{"diameter", d}}, q).size(), 64u);
}

// Guards coarse graining: radius d*alpha/2 and lattice constant spacing*d*alpha.
TEST(LatticeInsertion, ScalesWithCoarseGrainRatio) {
  const double d = 0.001, s = 1.5, alpha = 3.0, a = s * d * alpha;
  const auto out = run<Lattice>({{"diameter", d}, {"spacing", s}},
                                box_request(0, 0, 0, 4 * a, 5 * a, 6.5 * a, 1, alpha));
  ASSERT_EQ(out.size(), 4u * 5u * 6u);
  EXPECT_DOUBLE_EQ(out.r[0], d * alpha / 2);
  EXPECT_DOUBLE_EQ(out.x[0], a / 2);
  EXPECT_DOUBLE_EQ(out.x[1], 1.5 * a);
  EXPECT_DOUBLE_EQ(out.y[4], 1.5 * a);
}

// Guards that a region too small for one site is an error, not a silent empty insertion.
TEST(LatticeInsertion, TooSmallRegionIsAnError) {
  try {
    run<Lattice>({{"diameter", 0.01}}, box_request(0, 0, 0, 0.005, 0.1, 0.1));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
  }
}

// Guards RSA in a box: the requested count, no overlapping pair, every sphere inside.
TEST(RandomInsertion, ReachesCountWithoutOverlapInBox) {
  const double d = 0.002;
  const auto q = box_request(-0.01, 0.0, 0.1, 0.014, 0.024, 0.124, 3);
  const auto out = run<RandomFill>({{"diameter", d}, {"count", 400}}, q);
  ASSERT_EQ(out.size(), 400u);
  EXPECT_EQ(overlapping_pairs(out), 0u);
  EXPECT_EQ(outside(out, q.region), 0u);
  for (double r : out.r) EXPECT_DOUBLE_EQ(r, d / 2);
}

// Guards the RSA grid of a box far longer than wide (1e300 m by 1 cm, found by the run-time
// fuzzer, docs/reliability.md): its cell counts were converted to integers before they were
// bounded (2.4e202 cells along y; undefined behaviour, reported by UBSan); now the cells grow
// until the count fits, and the fill places its particles as in any other box.
TEST(RandomInsertion, ABoxFarLongerThanWideIsFilled) {
  const auto q = box_request(0.001, -0.005, 0.001, 0.011, 1e300, 0.008, 5);
  const auto out = run<RandomFill>({{"diameter", 0.0015}, {"diameter_max", 0.0025}, {"count", 30}}, q);
  ASSERT_EQ(out.size(), 30u);
  EXPECT_EQ(overlapping_pairs(out), 0u);
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_GE(out.x[i] - out.r[i], 0.001 - 1e-12);
    EXPECT_LE(out.x[i] + out.r[i], 0.011 + 1e-12);
    EXPECT_GE(out.y[i], -0.005);
  }
}

// Guards RSA in a cylinder (axis y, off-axis lo/hi junk): count reached, inside, no overlap.
TEST(RandomInsertion, ReachesCountWithoutOverlapInCylinder) {
  const double d = 0.002;
  const auto q = cylinder_request(1, 0.5, 0.0, -0.5, 0.012, 0.0, 0.03, 4);
  const auto out = run<RandomFill>({{"diameter", d}, {"count", 300}}, q);
  ASSERT_EQ(out.size(), 300u);
  EXPECT_EQ(overlapping_pairs(out), 0u);
  EXPECT_EQ(outside(out, q.region), 0u);
}

// Guards determinism: the same seed gives identical output, another seed a different one.
TEST(RandomInsertion, SeedDeterminesOutput) {
  const json p = {{"diameter", 0.001}, {"diameter_max", 0.0015}, {"count", 200}};
  const auto a = run<RandomFill>(p, box_request(0, 0, 0, 0.02, 0.02, 0.02, 42));
  const auto b = run<RandomFill>(p, box_request(0, 0, 0, 0.02, 0.02, 0.02, 42));
  const auto c = run<RandomFill>(p, box_request(0, 0, 0, 0.02, 0.02, 0.02, 43));
  EXPECT_TRUE(same(a, b));
  EXPECT_FALSE(same(a, c));
}

// Guards the volume_fraction -> count rule, monodisperse and polydisperse (E[d^3]), box and cylinder.
TEST(RandomInsertion, VolumeFractionGivesExpectedCount) {
  const double d = 0.001, side = 20 * d, phi = 0.2;
  const auto mono = run<RandomFill>({{"diameter", d}, {"volume_fraction", phi}},
                                    box_request(0, 0, 0, side, side, side));
  const double expected_mono = std::round(side * side * side * phi / (kPi / 6 * d * d * d));
  EXPECT_EQ(static_cast<double>(mono.size()), expected_mono);
  EXPECT_EQ(mono.size(), 3056u);

  const double lo = 0.001, hi = 0.002, radius = 0.015, length = 0.03;
  const auto q = cylinder_request(2, 0, 0, 0, radius, 0.0, length);
  const auto poly = run<RandomFill>({{"diameter", lo}, {"diameter_max", hi}, {"volume_fraction", 0.15}}, q);
  const double mean_d3 = (std::pow(hi, 4) - std::pow(lo, 4)) / (4 * (hi - lo));
  const double expected_poly = std::round(kPi * radius * radius * length * 0.15 / (kPi / 6 * mean_d3));
  EXPECT_EQ(static_cast<double>(poly.size()), expected_poly);
  EXPECT_EQ(overlapping_pairs(poly), 0u);
  EXPECT_EQ(outside(poly, q.region), 0u);
}

// Guards polydispersity: diameters uniform in [diameter, diameter_max]; inverted range refused.
TEST(RandomInsertion, PolydisperseDiametersStayInRange) {
  const double lo = 0.001, hi = 0.003;
  const auto out = run<RandomFill>({{"diameter", lo}, {"diameter_max", hi}, {"count", 300}},
                                   box_request(0, 0, 0, 0.04, 0.04, 0.04, 5));
  ASSERT_EQ(out.size(), 300u);
  double smallest = 1, largest = 0, sum = 0;
  for (double r : out.r) {
    smallest = std::min(smallest, 2 * r);
    largest = std::max(largest, 2 * r);
    sum += 2 * r;
  }
  EXPECT_GE(smallest, lo);
  EXPECT_LE(largest, hi);
  EXPECT_LT(smallest, lo + 0.1 * (hi - lo));
  EXPECT_GT(largest, hi - 0.1 * (hi - lo));
  EXPECT_NEAR(sum / 300, 0.5 * (lo + hi), 0.1 * (hi - lo));
  EXPECT_EQ(overlapping_pairs(out), 0u);
  const std::string msg = refusal<RandomFill>({{"diameter", hi}, {"diameter_max", lo}, {"count", 3}});
  EXPECT_NE(msg.find("diameter_max"), std::string::npos) << msg;
}

// Guards the jamming failure: an impossible target throws and says how far it got and what to do.
TEST(RandomInsertion, ImpossibleTargetThrowsWithExplanation) {
  const double d = 0.001;
  try {
    run<RandomFill>({{"diameter", d}, {"count", 500}, {"max_attempts", 200}},
                    box_request(0, 0, 0, 5 * d, 5 * d, 5 * d));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("random: placed ", 0), 0u) << m;
    EXPECT_NE(m.find(" of 500 particles"), std::string::npos) << m;
    EXPECT_NE(m.find("200 attempts failed"), std::string::npos) << m;
    EXPECT_NE(m.find("0.38"), std::string::npos) << m;
    EXPECT_NE(m.find("lattice model"), std::string::npos) << m;
  }
  // A particle larger than the region is explained as such.
  try {
    run<RandomFill>({{"diameter", 0.01}, {"count", 1}}, box_request(0, 0, 0, 0.005, 1, 1));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("does not fit"), std::string::npos) << e.what();
  }
}

// A host that says stop (abi.h stop_requested, ABI 2.6) ends a long fill with
// StopRequested saying how far it got (a fill that jams with a billion
// attempts per particle would otherwise run for minutes inside one step); a
// host of ABI 2.5, whose struct ends before stop_requested, is never asked.
TEST(RandomInsertion, AStopRequestEndsALongFillAndAnOlderHostIsNeverAsked) {
  struct Fake {
    static int stop(void*) { return 1; }
  };
  domel_host_v2 host{};
  host.struct_size = sizeof host;
  host.abi_minor = 6;
  host.stop_requested = &Fake::stop;
  const double d = 0.001;
  const json params = {{"diameter", d}, {"count", 500}, {"max_attempts", 1000000000}};
  const domel_insert_request_v1 jam = box_request(0, 0, 0, 5 * d, 5 * d, 5 * d);
  try {
    const RandomFill model{Params(params, domel::sdk::Host(&host))};
    Inserted out;
    model.insert(jam, out);
    FAIL() << "expected StopRequested";
  } catch (const domel::sdk::StopRequested& e) {
    EXPECT_NE(std::string(e.what()).find("random: stopped on request after placing "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(" of 500 particles"), std::string::npos) << e.what();
  }
  host.struct_size = offsetof(domel_host_v2, stop_requested);  // ABI 2.5's host
  host.abi_minor = 5;
  const RandomFill older{Params({{"diameter", d}, {"count", 20}}, domel::sdk::Host(&host))};
  Inserted out;
  older.insert(box_request(0, 0, 0, 20 * d, 20 * d, 20 * d), out);
  EXPECT_EQ(out.x.size(), 20u);
}

// Guards the exactly-one-of rule for count and volume_fraction and their ranges.
TEST(RandomInsertion, RefusesBadCountParameters) {
  EXPECT_NE(refusal<RandomFill>({{"diameter", 0.001}}), "");
  EXPECT_NE(refusal<RandomFill>({{"diameter", 0.001}, {"count", 10}, {"volume_fraction", 0.1}}), "");
  EXPECT_NE(refusal<RandomFill>({{"diameter", 0.001}, {"volume_fraction", 0.5}}), "");
  EXPECT_NE(refusal<RandomFill>({{"diameter", 0.001}, {"volume_fraction", 0.0}}), "");
  EXPECT_NE(refusal<RandomFill>({{"diameter", 0.001}, {"count", 0}}), "");
  EXPECT_NE(refusal<RandomFill>({{"diameter", 0.001}, {"count", 5}, {"max_attempts", 0}}), "");
  EXPECT_EQ(refusal<RandomFill>({{"diameter", 0.001}, {"volume_fraction", 0.38}}), "");
  EXPECT_EQ(refusal<RandomFill>({{"diameter", 0.001}, {"count", 5}}), "");
}

// Guards avoidance of particles already present, inside the region and just outside its box.
TEST(RandomInsertion, AvoidsExistingParticles) {
  const double d = 0.002, side = 0.03;
  auto q = box_request(0, 0, 0, side, side, side, 11);
  // A big sphere in the middle, one poking in through a face, one far away (ignored).
  const std::vector<double> ex_x = {0.015, -0.004, 1.0}, ex_y = {0.015, 0.015, 1.0},
                            ex_z = {0.015, 0.015, 1.0}, ex_r = {0.008, 0.006, 0.1};
  q.n_existing = ex_x.size();
  q.ex_x = ex_x.data(); q.ex_y = ex_y.data(); q.ex_z = ex_z.data(); q.ex_r = ex_r.data();
  const auto out = run<RandomFill>({{"diameter", d}, {"count", 800}}, q);
  ASSERT_EQ(out.size(), 800u);
  std::size_t hits = 0;
  for (std::size_t i = 0; i < out.size(); ++i)
    for (std::size_t j = 0; j < ex_x.size(); ++j) {
      const double dist = std::sqrt(std::pow(out.x[i] - ex_x[j], 2) + std::pow(out.y[i] - ex_y[j], 2) +
                                    std::pow(out.z[i] - ex_z[j], 2));
      if (dist < (out.r[i] + ex_r[j]) * (1 - 1e-12)) ++hits;
    }
  EXPECT_EQ(hits, 0u);
  EXPECT_EQ(overlapping_pairs(out), 0u);
}

// Guards coarse graining in RSA: radii d*alpha/2 and a volume-fraction count that scales as alpha^-3.
TEST(RandomInsertion, ScalesWithCoarseGrainRatio) {
  const double d = 0.001, side = 0.04, alpha = 2.0;
  const auto scaled = run<RandomFill>({{"diameter", d}, {"volume_fraction", 0.1}},
                                      box_request(0, 0, 0, side, side, side, 1, alpha));
  for (double r : scaled.r) ASSERT_DOUBLE_EQ(r, d * alpha / 2);
  const double expected = std::round(side * side * side * 0.1 / (kPi / 6 * std::pow(d * alpha, 3)));
  EXPECT_EQ(static_cast<double>(scaled.size()), expected);
}

// Guards the region helpers: volumes, a cylinder's bounding box, sphere-inside margins, bad regions.
TEST(InsertionRegion, VolumeBoundsAndInside) {
  using domel::plugins::insertion::Bounds;
  using domel::plugins::insertion::check_region;
  using domel::plugins::insertion::region_bounds;
  using domel::plugins::insertion::region_volume;
  using domel::plugins::insertion::sphere_inside;
  const auto box = box_request(1, 2, 3, 2, 4, 7).region;
  EXPECT_DOUBLE_EQ(region_volume(box), 8.0);
  EXPECT_TRUE(sphere_inside(box, 1.5, 3, 5, 0.5));
  EXPECT_FALSE(sphere_inside(box, 1.5, 3, 5, 0.51));
  const auto cyl = cylinder_request(0, 0, 1, 2, 0.5, -1, 3).region;
  EXPECT_DOUBLE_EQ(region_volume(cyl), kPi * 0.25 * 4);
  const Bounds b = region_bounds(cyl);
  EXPECT_DOUBLE_EQ(b.lo[0], -1); EXPECT_DOUBLE_EQ(b.hi[0], 3);
  EXPECT_DOUBLE_EQ(b.lo[1], 0.5); EXPECT_DOUBLE_EQ(b.hi[1], 1.5);
  EXPECT_DOUBLE_EQ(b.lo[2], 1.5); EXPECT_DOUBLE_EQ(b.hi[2], 2.5);
  EXPECT_TRUE(sphere_inside(cyl, 0, 1.2, 2, 0.3));
  EXPECT_FALSE(sphere_inside(cyl, 0, 1.3, 2.3, 0.2));  // corner of the bounding box
  EXPECT_FALSE(sphere_inside(cyl, 2.95, 1, 2, 0.1));   // through the top
  auto bad = box;
  bad.shape = 7;
  EXPECT_THROW(check_region(bad, "lattice"), std::runtime_error);
  bad = box;
  bad.hi[1] = bad.lo[1];
  EXPECT_THROW(check_region(bad, "lattice"), std::runtime_error);
  auto q = box_request(0, 0, 0, 1, 1, 1, 1, 0.0);
  Inserted out;
  const json params = {{"diameter", 0.1}};
  EXPECT_THROW(Lattice(Params(params)).insert(q, out), std::runtime_error);  // alpha = 0
}

// Guards the schemas the host validates against: valid JSON, a description on every property,
// an x-unit on every number, the documented defaults and bounds.
TEST(InsertionSchema, DocumentsEveryParameter) {
  for (const char* text : {Lattice::kSchema, RandomFill::kSchema}) {
    const json s = json::parse(text);
    EXPECT_EQ(s.at("type"), "object");
    EXPECT_EQ(s.at("additionalProperties"), false);
    for (const auto& [key, prop] : s.at("properties").items()) {
      EXPECT_TRUE(prop.contains("description")) << key;
      if (prop.value("type", "") == "number") {
        EXPECT_TRUE(prop.contains("x-unit")) << key;
      }
    }
  }
  const json r = json::parse(RandomFill::kSchema);
  EXPECT_EQ(r.at("properties").at("volume_fraction").at("maximum"), 0.38);
  EXPECT_EQ(r.at("properties").at("volume_fraction").at("exclusiveMinimum"), 0);
  // exactly one of count / volume_fraction, and of diameter / distribution
  EXPECT_EQ(r.at("allOf").size(), 2u);
  EXPECT_EQ(r.at("allOf").at(1).at("oneOf").at(1).at("required"), json::array({"distribution"}));
  EXPECT_EQ(r.at("properties").at("max_attempts").at("default"), 1000);
  const json l = json::parse(Lattice::kSchema);
  EXPECT_EQ(l.at("oneOf").at(0).at("required"), json::array({"diameter"}));
  EXPECT_EQ(l.at("oneOf").at(1).at("required"), json::array({"distribution"}));
  EXPECT_EQ(l.at("properties").at("arrangement").at("enum"), json::array({"simple_cubic"}));
}

// Guards the ABI round trip: create from JSON text, DOMEL_ERR_CAPACITY then a retry, errors as messages.
TEST(InsertionAbi, RoundTripWithCapacityRetry) {
  using Export = domel::sdk::detail::Export<Lattice>;
  const double d = 0.0028, a = 1.02 * d;
  const auto q = box_request(0, 0, 0, 17 * a, 17 * a, 35 * a);
  char err[256] = {0};
  void* inst = nullptr;
  ASSERT_EQ(Export::create(R"({"model":"lattice","diameter":0.0028,"spacing":1.02})", nullptr, &inst, err,
                           sizeof err),
            DOMEL_OK)
      << err;
  ASSERT_NE(inst, nullptr);

  std::vector<double> x(10), y(10), z(10), r(10);
  domel_insert_output_v1 out{sizeof(domel_insert_output_v1), x.size(), 0, x.data(), y.data(), z.data(), r.data()};
  ASSERT_EQ(Export::insert(inst, &q, &out, err, sizeof err), DOMEL_ERR_CAPACITY);
  ASSERT_EQ(out.count, 10115u);
  const std::size_t need = out.count;
  x.resize(need); y.resize(need); z.resize(need); r.resize(need);
  out = {sizeof(domel_insert_output_v1), need, need, x.data(), y.data(), z.data(), r.data()};
  ASSERT_EQ(Export::insert(inst, &q, &out, err, sizeof err), DOMEL_OK) << err;
  ASSERT_EQ(out.count, need);
  const auto direct = run<Lattice>({{"diameter", d}, {"spacing", 1.02}}, q);
  EXPECT_EQ(x, direct.x);
  EXPECT_EQ(y, direct.y);
  EXPECT_EQ(z, direct.z);
  EXPECT_EQ(r, direct.r);
  Export::destroy(inst);

  // Refused parameters come back as DOMEL_ERR_PARAMETER with the constructor's message.
  inst = nullptr;
  EXPECT_EQ(Export::create(R"({"diameter":0.001,"spacing":1.1,"jitter":0.3})", nullptr, &inst, err, sizeof err),
            DOMEL_ERR_PARAMETER);
  EXPECT_EQ(inst, nullptr);
  EXPECT_NE(std::string(err).find("jitter"), std::string::npos) << err;

  // A failing insertion comes back as DOMEL_ERR_RUNTIME with the explanation.
  using ExportRandom = domel::sdk::detail::Export<RandomFill>;
  ASSERT_EQ(ExportRandom::create(R"({"diameter":0.001,"count":500,"max_attempts":50})", nullptr, &inst, err,
                                 sizeof err),
            DOMEL_OK)
      << err;
  const auto tiny = box_request(0, 0, 0, 0.005, 0.005, 0.005);
  out = {sizeof(domel_insert_output_v1), need, 0, x.data(), y.data(), z.data(), r.data()};
  EXPECT_EQ(ExportRandom::insert(inst, &tiny, &out, err, sizeof err), DOMEL_ERR_RUNTIME);
  EXPECT_NE(std::string(err).find("jams"), std::string::npos) << err;
  ExportRandom::destroy(inst);
}

// Guards size distributions in the insertion models (issue 18 item 2): a
// random fill of 10^4 spheres from a table by mass holds the requested mass
// fractions within 2 %, and so does the first half of what it hands over
// (a pour keeps a first part: the large ones are placed first but handed
// over shuffled); a lattice of log-normal diameters passes a
// Kolmogorov-Smirnov test (1.63/sqrt(n), the 1 % point; Massey 1951) against the truncated CDF;
// no sphere overlaps another or leaves the region.
TEST(InsertionDistribution, ARandomFillMeetsATablesMassFractionsAndSoDoesItsFirstHalf) {
  const json p = {{"model", "random"}, {"count", 10000},
                  {"distribution", {{"type", "table"}, {"diameters", {1e-3, 2e-3}}, {"fractions", {0.4, 0.6}},
                                    {"by", "mass"}}}};
  const auto req = box_request(0, 0, 0, 0.06, 0.06, 0.06, 11);  // volume fraction about 0.07
  const Inserted out = run<RandomFill>(p, req);
  ASSERT_EQ(out.size(), 10000u);
  auto small_mass_share = [&](std::size_t n) {
    double small = 0, total = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const double m = std::pow(out.r[k], 3);
      total += m;
      if (out.r[k] < 0.75e-3) small += m;
    }
    return small / total;
  };
  EXPECT_NEAR(small_mass_share(out.size()), 0.4, 0.02);
  EXPECT_NEAR(small_mass_share(out.size() / 2), 0.4, 0.02);
  EXPECT_EQ(overlapping_pairs(out), 0u);
  EXPECT_EQ(outside(out, req.region), 0u);
  // by volume fraction: the count follows from E[d^3]
  json q = p;
  q.erase("count");
  q["volume_fraction"] = 0.1;
  const Inserted filled = run<RandomFill>(q, req);
  double solid = 0;
  for (double r : filled.r) solid += 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(solid / (0.06 * 0.06 * 0.06), 0.1, 0.002);
}

TEST(InsertionDistribution, ALatticeOfLogNormalDiametersPassesAKolmogorovSmirnovTest) {
  const json p = {{"model", "lattice"}, {"spacing", 1.0},
                  {"distribution", {{"type", "lognormal"}, {"median", 1e-3}, {"sigma", 0.2}}}};
  const auto req = box_request(0, 0, 0, 0.04, 0.04, 0.04, 3);
  const Inserted out = run<Lattice>(p, req);
  const double largest = 1e-3 * std::exp(0.6);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(std::pow(std::floor(0.04 / largest + 1e-9), 3)));
  std::vector<double> d;
  for (double r : out.r) d.push_back(2 * r);
  std::sort(d.begin(), d.end());
  auto phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  const double l0 = phi(-3), l1 = phi(3), n = static_cast<double>(d.size());
  double worst = 0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    const double f = (phi(std::log(d[k] / 1e-3) / 0.2) - l0) / (l1 - l0);
    worst = std::max({worst, std::fabs(f - k / n), std::fabs((k + 1) / n - f)});
  }
  EXPECT_LT(worst, 1.63 / std::sqrt(n));
  EXPECT_EQ(overlapping_pairs(out), 0u);
  EXPECT_EQ(outside(out, req.region), 0u);
  EXPECT_NE(refusal<Lattice>({{"model", "lattice"}, {"diameter", 1e-3},
                              {"distribution", {{"type", "uniform"}, {"min", 1e-3}, {"max", 2e-3}}}})
                .find("either 'distribution' or 'diameter'"),
            std::string::npos);
}

// Guards mixtures in the insertion models (issue 18 item 2): every particle
// carries its component, and its diameter is that component's (here two
// sizes, 1 and 2 mm, so the radius tells); random fills them together
// (largest first, handed over shuffled: the first half holds the same
// volume shares within 2 %); a lattice draws a component per site, so both
// components fill the bottom and the top half alike (number shares 0.5
// each: binomial standard deviation sqrt(0.25/n), about 0.004 for the
// 18 000 sites of each half; 5 sigma); the ABI hands the components over when the host asks,
// and leaves the host's fill when the model draws no mixture.
TEST(InsertionDistribution, AMixturesParticlesCarryTheirComponentThroughEveryModelAndTheAbi) {
  const json mix = {{"type", "mixture"},
                    {"by", "volume"},
                    {"components", {{{"material", "a"}, {"diameter", 1e-3}, {"fraction", 0.4}},
                                    {{"material", "b"}, {"diameter", 2e-3}, {"fraction", 0.6}}}}};
  const auto req = box_request(0, 0, 0, 0.05, 0.05, 0.05, 4);
  const Inserted out = run<RandomFill>({{"model", "random"}, {"count", 10000}, {"distribution", mix}}, req);
  ASSERT_EQ(out.component.size(), out.size());
  auto share0 = [&](const Inserted& p, std::size_t first, std::size_t last) {
    double v[2] = {0, 0};
    for (std::size_t k = first; k < last; ++k) {
      EXPECT_EQ(p.r[k], p.component[k] == 0 ? 0.5e-3 : 1e-3);
      v[p.component[k]] += std::pow(p.r[k], 3);
    }
    return v[0] / (v[0] + v[1]);
  };
  EXPECT_NEAR(share0(out, 0, out.size()), 0.4, 0.02);
  EXPECT_NEAR(share0(out, 0, out.size() / 2), 0.4, 0.02);
  EXPECT_EQ(overlapping_pairs(out), 0u);

  const json by_number = {{"type", "mixture"},
                          {"by", "number"},
                          {"components", {{{"diameter", 1e-3}, {"fraction", 0.5}}, {{"diameter", 1.5e-3}, {"fraction", 0.5}}}}};
  const Inserted lat = run<Lattice>({{"model", "lattice"}, {"distribution", by_number}}, req);
  ASSERT_EQ(lat.component.size(), lat.size());
  std::size_t n[2] = {0, 0}, ones[2] = {0, 0};
  for (std::size_t k = 0; k < lat.size(); ++k) {
    const int half = lat.z[k] < 0.025 ? 0 : 1;
    ++n[half];
    ones[half] += lat.component[k];
    EXPECT_EQ(lat.r[k], lat.component[k] == 0 ? 0.5e-3 : 0.75e-3);
  }
  for (int h = 0; h < 2; ++h) EXPECT_NEAR(static_cast<double>(ones[h]) / n[h], 0.5, 5 * std::sqrt(0.25 / n[h]));

  // through the ABI: the host's array gets the components; without a mixture it keeps its fill
  using Export = domel::sdk::detail::Export<Lattice>;
  char err[256] = {0};
  for (const bool mixture : {true, false}) {
    void* inst = nullptr;
    const json p = mixture ? json{{"distribution", by_number}} : json{{"diameter", 1e-3}};
    ASSERT_EQ(Export::create(p.dump().c_str(), nullptr, &inst, err, sizeof err), DOMEL_OK) << err;
    const std::size_t cap = 200000;
    std::vector<double> x(cap), y(cap), z(cap), r(cap);
    std::vector<uint32_t> c(cap, 0xFFFFFFFFu);
    domel_insert_output_v1 o{sizeof o, cap, 0, x.data(), y.data(), z.data(), r.data(), c.data()};
    ASSERT_EQ(Export::insert(inst, &req, &o, err, sizeof err), DOMEL_OK) << err;
    if (mixture) {
      ASSERT_EQ(o.count, lat.size());
      EXPECT_TRUE(std::equal(lat.component.begin(), lat.component.end(), c.begin()));
    } else {
      EXPECT_EQ(c[0], 0xFFFFFFFFu);
    }
    Export::destroy(inst);
  }
}

namespace {

/// An insertion model that reads a mixture but pushes its particles without
/// their component, as a model built before ABI 2.4 would.
class NoComponents {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_INSERTION;
  static constexpr const char* kName = "no_components";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "test: a mixture without components";
  static constexpr const char* kSchema = R"json({"type": "object"})json";
  explicit NoComponents(const Params& p)
      : d_(domel::sdk::SizeDistribution::parse(p.json().at("distribution"), "no_components")) {}
  void insert(const domel_insert_request_v1& req, Inserted& out) const {
    std::mt19937_64 rng(req.seed);
    for (int k = 0; k < 10; ++k) out.push(0.01 * k, 0, 0, 0.5 * d_.sample(rng));
  }

 private:
  domel::sdk::SizeDistribution d_;
};

template <class M>
domel::platform::RegisteredModel registered() {
  domel::platform::RegisteredModel m;
  m.desc.kind = M::kKind;
  m.desc.create = &domel::sdk::detail::Export<M>::create;
  m.desc.destroy = &domel::sdk::detail::Export<M>::destroy;
  m.insertion.insert = &domel::sdk::detail::Export<M>::insert;
  m.name = M::kName;
  m.library_name = "test";
  return m;
}

}  // namespace

// Guards the host's side of mixtures (ABI 2.4): asked for components, it
// gets lattice's; a model that reads the mixture but names no component is
// refused with a message that names the model and what to do.
TEST(InsertionAbi, TheHostGetsEachParticlesComponentOrRefusesAModelThatNamesNone) {
  const json mix = {{"distribution", {{"type", "mixture"}, {"by", "number"},
                                      {"components", {{{"diameter", 1e-3}, {"fraction", 0.5}},
                                                      {{"diameter", 2e-3}, {"fraction", 0.5}}}}}}};
  const auto req = box_request(0, 0, 0, 0.01, 0.01, 0.01, 2);
  std::vector<double> x, y, z, r;
  std::vector<uint32_t> c;
  const auto lattice = registered<Lattice>();
  const domel::platform::ModelInstance good(lattice, mix, "here");
  good.insert(req, x, y, z, r, &c);
  ASSERT_EQ(c.size(), r.size());
  ASSERT_GT(r.size(), 0u);
  for (std::size_t k = 0; k < r.size(); ++k) EXPECT_EQ(r[k], c[k] == 0 ? 0.5e-3 : 1e-3);

  const auto none = registered<NoComponents>();
  const domel::platform::ModelInstance bad(none, mix, "here");
  std::string why;
  try {
    bad.insert(req, x, y, z, r, &c);
  } catch (const domel::platform::PluginError& e) {
    why = e.what();
  }
  EXPECT_NE(why.find("insertion model 'no_components'"), std::string::npos) << why;
  EXPECT_NE(why.find("did not say which component of the mixture each particle is"), std::string::npos) << why;
  bad.insert(req, x, y, z, r);  // without a mixture to map, the host does not ask
  EXPECT_EQ(r.size(), 10u);
}
