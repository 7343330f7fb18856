// SPDX-License-Identifier: MIT
// Recursive coordinate bisection on one rank: regions tile space, the cost
// is shared out evenly, the tree does not depend on the points' order, and
// parts_within() agrees with the regions' distances. The particle packing
// round-trips every array.
#include "distributed/decomposition.hpp"
#include "distributed/particle_exchange.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

namespace dp = domel::platform;

namespace {

struct Points {
  std::vector<double> x, y, z;
  std::vector<std::uint64_t> cost;
};

/// A settled-column-like cloud: uniform in a 0.1 x 0.05 x 0.4 box, with the
/// cost concentrated at the bottom (contacts pile up where particles rest).
Points column(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points p;
  for (std::size_t k = 0; k < n; ++k) {
    p.x.push_back(0.1 * u(rng));
    p.y.push_back(0.05 * u(rng));
    p.z.push_back(0.4 * u(rng));
    p.cost.push_back(p.z.back() < 0.1 ? 13 : 1);
  }
  return p;
}

dp::Region extent() { return {{0, 0, 0}, {0.1, 0.05, 0.4}}; }

dp::Decomposition bisect(const Points& p, int parts) {
  return dp::Decomposition::bisect(extent(), parts, p.x.data(), p.y.data(), p.z.data(), p.cost.data(), p.x.size(),
                                   dp::Communicator{});
}

}  // namespace

TEST(Decomposition, OnePartOwnsAllSpace) {
  const dp::Decomposition d;
  const double far[3] = {1e9, -1e9, 3};
  EXPECT_EQ(d.parts(), 1);
  EXPECT_EQ(d.owner(far), 0);
  std::vector<int> near;
  d.parts_within(far, 0.01, near);
  EXPECT_EQ(near, std::vector<int>{0});
}

TEST(Decomposition, EveryPointHasOneOwnerAndThePartsShareTheCostEvenly) {
  const Points p = column(20000, 1);
  const std::uint64_t total = std::accumulate(p.cost.begin(), p.cost.end(), std::uint64_t{0});
  for (int parts : {2, 3, 4, 5, 7, 8}) {
    const dp::Decomposition d = bisect(p, parts);
    ASSERT_EQ(d.parts(), parts);
    std::vector<std::uint64_t> cost(static_cast<std::size_t>(parts), 0);
    for (std::size_t k = 0; k < p.x.size(); ++k) {
      const double q[3] = {p.x[k], p.y[k], p.z[k]};
      const int o = d.owner(q);
      ASSERT_GE(o, 0);
      ASSERT_LT(o, parts);
      // the owner's region holds the point, no other region does
      int holding = 0;
      for (int r = 0; r < parts; ++r) holding += d.region(r).distance(q) == 0.0 ? 1 : 0;
      EXPECT_GE(holding, 1);
      EXPECT_EQ(d.region(o).distance(q), 0.0);
      cost[static_cast<std::size_t>(o)] += p.cost[k];
    }
    // Each cut reaches its share to within the cost of the points in one fine
    // bin (1/512^2 of the extent along the axis: a few points at most) and the
    // largest point cost; over log2(parts) levels that stays under 0.5 % here.
    const double share = static_cast<double>(total) / parts;
    for (int r = 0; r < parts; ++r)
      EXPECT_NEAR(static_cast<double>(cost[static_cast<std::size_t>(r)]), share, 0.005 * share)
          << parts << " parts, part " << r;
  }
}

TEST(Decomposition, TheTreeDoesNotDependOnThePointsOrder) {
  Points p = column(5000, 2);
  const dp::Decomposition a = bisect(p, 4);
  std::vector<std::size_t> order(p.x.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(7));
  Points q;
  for (std::size_t k : order) {
    q.x.push_back(p.x[k]);
    q.y.push_back(p.y[k]);
    q.z.push_back(p.z[k]);
    q.cost.push_back(p.cost[k]);
  }
  const dp::Decomposition b = bisect(q, 4);
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  for (std::size_t i = 0; i < a.nodes().size(); ++i) {
    EXPECT_EQ(a.nodes()[i].axis, b.nodes()[i].axis);
    EXPECT_EQ(a.nodes()[i].cut, b.nodes()[i].cut);  // bit for bit
  }
}

TEST(Decomposition, PartsWithinACutoffAreThoseWhoseRegionIsThatClose) {
  const Points p = column(3000, 3);
  const dp::Decomposition d = bisect(p, 6);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.05, 0.45);
  std::vector<int> near;
  for (int t = 0; t < 2000; ++t) {
    const double q[3] = {u(rng) * 0.25, u(rng) * 0.125, u(rng)};  // inside and outside the extent
    const double cutoff = 0.004;
    d.parts_within(q, cutoff, near);
    std::vector<int> brute;
    for (int r = 0; r < d.parts(); ++r)
      if (d.region(r).distance(q) <= cutoff) brute.push_back(r);
    EXPECT_EQ(near, brute);
    EXPECT_TRUE(std::binary_search(near.begin(), near.end(), d.owner(q)));
  }
}

TEST(Decomposition, NoCostSplitsByVolume) {
  Points p = column(100, 4);
  std::fill(p.cost.begin(), p.cost.end(), 0);
  const dp::Decomposition d = bisect(p, 2);
  EXPECT_EQ(d.nodes()[0].axis, 2);  // the longest
  EXPECT_DOUBLE_EQ(d.nodes()[0].cut, 0.2);
}

TEST(Decomposition, RefusesABadExtentOrNoParts) {
  const Points p = column(10, 5);
  EXPECT_THROW(bisect(p, 0), std::invalid_argument);
  dp::Region bad = extent();
  bad.hi[0] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(dp::Decomposition::bisect(bad, 2, p.x.data(), p.y.data(), p.z.data(), p.cost.data(), p.x.size(),
                                         dp::Communicator{}),
               std::invalid_argument);
}

TEST(ParticleExchange, PackingRoundTripsEveryArrayIncludingExternalForcesAndAux) {
  dp::ParticleStore s;
  s.enable_external_force();
  s.add_aux(2);
  for (int k = 0; k < 5; ++k) s.add(100 + k, 0.1 * k, 0.2 * k, 0.3 * k, 0.001 * (k + 1), 2500.0, k == 3,
                                    static_cast<std::uint8_t>(k % 2));
  for (std::size_t k = 0; k < s.size(); ++k) {
    s.vx[k] = 1.0 + k;
    s.wz[k] = -2.0 * k;
    s.contacts[k] = static_cast<std::uint32_t>(7 * k);
    s.ext_fy[k] = 0.5 * k;
    s.aux[1][k] = 3.0 * k;
  }
  const std::vector<char> bytes = dp::pack_particles(s, {4, 1});
  EXPECT_EQ(bytes.size(), 2 * dp::particle_bytes(s));
  dp::ParticleStore t;
  t.enable_external_force();
  t.add_aux(2);
  dp::unpack_particles(t, bytes);
  ASSERT_EQ(t.size(), 2u);
  const std::size_t from[2] = {4, 1};
  for (std::size_t k = 0; k < 2; ++k) {
    const std::size_t f = from[k];
    EXPECT_EQ(t.id[k], s.id[f]);
    EXPECT_EQ(t.x[k], s.x[f]);
    EXPECT_EQ(t.vx[k], s.vx[f]);
    EXPECT_EQ(t.wz[k], s.wz[f]);
    EXPECT_EQ(t.radius[k], s.radius[f]);
    EXPECT_EQ(t.inv_mass[k], s.inv_mass[f]);
    EXPECT_EQ(t.contacts[k], s.contacts[f]);
    EXPECT_EQ(t.flags[k], s.flags[f]);
    EXPECT_EQ(t.material[k], s.material[f]);
    EXPECT_EQ(t.ext_fy[k], s.ext_fy[f]);
    EXPECT_EQ(t.aux[1][k], s.aux[1][f]);
  }
  dp::ParticleStore plain;  // another layout: refused, named
  EXPECT_THROW(dp::unpack_particles(plain, std::vector<char>(dp::particle_bytes(s) + 8)), std::runtime_error);
}

TEST(ParticleExchange, OneRankKeepsItsParticlesAndHasNoGhosts) {
  dp::ParticleStore s;
  for (int k = 0; k < 4; ++k) s.add(k, 0.01 * k, 0, 0, 0.001, 2500.0);
  const dp::Communicator one;
  const dp::Decomposition d;
  const auto m = dp::migrate(s, d, one);
  EXPECT_EQ(m.sent, 0u);
  EXPECT_EQ(s.size(), 4u);
  dp::GhostExchange gx;
  const auto g = gx.build(s, s.size(), d, 0.01, one);
  EXPECT_EQ(g.received, 0u);
  EXPECT_EQ(s.size(), 4u);  // no ghosts after the owned
}

TEST(ParticleExchange, OneRankWithAPeriodicAxisHoldsImagesOfItsOwnParticlesNearTheFaces) {
  dp::ParticleStore s;
  s.add(1, 0.001, 0.05, 0.05, 0.001, 2500.0);  // near the face x = 0
  s.add(2, 0.050, 0.05, 0.05, 0.001, 2500.0);  // in the middle
  dp::PeriodicBox box;
  box.axis[0] = true;
  box.hi[0] = box.hi[1] = box.hi[2] = 0.1;
  dp::GhostExchange gx;
  gx.build(s, 2, dp::Decomposition{}, 0.01, dp::Communicator{}, box);
  ASSERT_EQ(s.size(), 3u);  // particle 1's image one period along +x, after the two owned
  EXPECT_EQ(s.id[2], 1u);
  EXPECT_DOUBLE_EQ(s.x[2], 0.101);
  gx.build(s, 2, dp::Decomposition{}, 0.01, dp::Communicator{}, box);
  EXPECT_EQ(s.size(), 3u);  // a rebuild replaces the ghosts
  box.hi[0] = 0.015;  // shorter than twice the cut-off: images would not be unique
  EXPECT_THROW(gx.build(s, 2, dp::Decomposition{}, 0.01, dp::Communicator{}, box), std::invalid_argument);
}

TEST(ParticleExchange, OneRankClaimsIdsInSequence) {
  std::uint64_t next = 7;
  EXPECT_EQ(dp::claim_ids(3, next, dp::Communicator{}), 7u);
  EXPECT_EQ(next, 10u);
  EXPECT_EQ(dp::claim_ids(0, next, dp::Communicator{}), 10u);
  EXPECT_EQ(next, 10u);
}
