// SPDX-License-Identifier: MIT
// Guards the Verlet list (platform/core/neighbor_list.cpp): it finds exactly
// the pairs within r_i + r_j + skin (checked against brute force on a
// polydisperse random cloud), orients every pair id_i < id_j, rebuilds when
// a particle moved more than half the skin, and carries contact history by
// pair ids across rebuilds and re-ordering of the store.
#include "core/neighbor_list.hpp"
#include "core/error.hpp"
#include "core/thread_pool.hpp"
#include "geometry/wall_neighbors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

using namespace domel::platform;

namespace {

ParticleStore cloud(std::size_t n, unsigned seed) {
  ParticleStore s;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, 0.05), rad(0.001, 0.003);
  for (std::size_t k = 0; k < n; ++k) s.add(100 + k, pos(rng), pos(rng), pos(rng), rad(rng), 2500);
  return s;
}

std::set<std::pair<std::uint64_t, std::uint64_t>> brute(const ParticleStore& s, double skin) {
  std::set<std::pair<std::uint64_t, std::uint64_t>> out;
  for (std::size_t a = 0; a < s.size(); ++a)
    for (std::size_t b = a + 1; b < s.size(); ++b) {
      const double dx = s.x[a] - s.x[b], dy = s.y[a] - s.y[b], dz = s.z[a] - s.z[b];
      const double cut = s.radius[a] + s.radius[b] + skin;
      if (dx * dx + dy * dy + dz * dz < cut * cut) out.insert(std::minmax(s.id[a], s.id[b]));
    }
  return out;
}

/// Mark every `every`-th pair of the list live, with a history row that
/// encodes its ids (tag, tag + 1, tag + 2); returns the tags by id pair.
std::map<std::pair<std::uint64_t, std::uint64_t>, double> mark_live(NeighborList& nl, const ParticleStore& s,
                                                                    std::size_t every) {
  std::map<std::pair<std::uint64_t, std::uint64_t>, double> expected;
  for (std::size_t k = 0; k < nl.size(); k += every) {
    const double tag = static_cast<double>(s.id[nl.i[k]] * 100000 + s.id[nl.j[k]]);
    nl.touching[k] = 1;
    for (int c = 0; c < 3; ++c) nl.history[k * 3 + c] = tag + c;
    expected[{s.id[nl.i[k]], s.id[nl.j[k]]}] = tag;
  }
  return expected;
}

}  // namespace

TEST(NeighborList, FindsExactlyThePairsWithinCutoffOrientedByIds) {
  const ParticleStore s = cloud(800, 7);
  NeighborList nl;
  nl.configure(0.0008, 3);
  nl.build(s);
  std::set<std::pair<std::uint64_t, std::uint64_t>> found;
  for (std::size_t k = 0; k < nl.size(); ++k) {
    EXPECT_LT(s.id[nl.i[k]], s.id[nl.j[k]]);
    EXPECT_TRUE(found.insert({s.id[nl.i[k]], s.id[nl.j[k]]}).second) << "pair listed twice";
  }
  EXPECT_EQ(found, brute(s, 0.0008));
  EXPECT_GT(found.size(), 100u);
}

TEST(NeighborList, FarOutliersLoseNoPairs) {
  // A few particles thrown 100 m away (silo_ci once shot some out) make the
  // build span its grid over the bulk and clamp the outliers into the edge
  // cells (so it does not go quadratic): the list must still be exact, and
  // the outliers that sit next to each other must still find each other.
  ParticleStore s = cloud(3000, 11);
  s.add(1, 100.0, 100.0, 100.0, 0.002, 2500);
  s.add(2, 100.0, 100.0, 100.003, 0.002, 2500);
  s.add(3, -50.0, 0.0, 0.0, 0.002, 2500);
  NeighborList nl;
  nl.configure(0.0008, 3);
  nl.build(s);
  std::set<std::pair<std::uint64_t, std::uint64_t>> found;
  for (std::size_t k = 0; k < nl.size(); ++k) found.insert({s.id[nl.i[k]], s.id[nl.j[k]]});
  EXPECT_EQ(found, brute(s, 0.0008));
  EXPECT_TRUE(found.count({1, 2}));
}

TEST(NeighborList, ThreadedBuildGivesTheOneThreadList) {
  // The scan runs per particle range and the ranges are joined in order, so
  // the list, its tiers and the carried history must equal the serial build's.
  const ParticleStore s = cloud(6000, 5);
  NeighborList serial, threaded;
  serial.configure(0.0008, 3);
  threaded.configure(0.0008, 3);
  ThreadPool pool(2);
  serial.build(s);
  threaded.build(s, &pool);
  ASSERT_GT(serial.size(), 1000u);
  EXPECT_EQ(serial.i, threaded.i);
  EXPECT_EQ(serial.j, threaded.j);
  EXPECT_EQ(serial.near_size(), threaded.near_size());
  // history carried over by ids in a second build
  for (std::size_t k = 0; k < serial.size(); k += 7) {
    serial.touching[k] = threaded.touching[k] = 1;
    for (int h = 0; h < 3; ++h) serial.history[3 * k + h] = threaded.history[3 * k + h] = 1.0 + k + h;
  }
  serial.build(s);
  threaded.build(s, &pool);
  EXPECT_EQ(serial.history, threaded.history);
  EXPECT_EQ(serial.touching, threaded.touching);
}

TEST(NeighborList, CellsAreNeverNarrowerThanTheCutoff) {
  // regression: with floor(span/cutoff) + 1 cells per axis a cell was narrower
  // than the cutoff and this touching pair (2, 3), 0.9 apart, was missed
  ParticleStore s;
  for (double x : {0.0, 0.7, 1.6, 2.3}) s.add(static_cast<std::uint64_t>(s.size() + 1), x, 0, 0, 0.5, 1);
  NeighborList nl;
  nl.configure(0.1, 0);
  nl.build(s);
  std::set<std::pair<std::uint64_t, std::uint64_t>> found;
  for (std::size_t k = 0; k < nl.size(); ++k) found.insert({s.id[nl.i[k]], s.id[nl.j[k]]});
  EXPECT_EQ(found, brute(s, 0.1));
  // and on many random clouds of every density
  for (unsigned seed = 0; seed < 200; ++seed) {
    std::mt19937_64 rng(seed);
    const std::size_t n = 5 + seed % 60;
    std::uniform_real_distribution<double> pos(0.0, 0.002 + 0.0002 * (seed % 50)), rad(0.0005, 0.0015);
    ParticleStore c;
    for (std::size_t k = 0; k < n; ++k) c.add(k + 1, pos(rng), pos(rng), pos(rng), rad(rng), 1);
    NeighborList l;
    l.configure(0.0002, 0);
    l.build(c);
    std::set<std::pair<std::uint64_t, std::uint64_t>> got;
    for (std::size_t k = 0; k < l.size(); ++k) got.insert({c.id[l.i[k]], c.id[l.j[k]]});
    ASSERT_EQ(got, brute(c, 0.0002)) << "seed " << seed;
  }
}

TEST(NeighborList, RebuildsOnlyAfterHalfSkinDisplacement) {
  ParticleStore s = cloud(50, 3);
  NeighborList nl;
  nl.configure(0.001, 0);
  nl.build(s);
  EXPECT_FALSE(nl.needs_rebuild(s));
  s.x[10] += 0.00049;
  EXPECT_FALSE(nl.needs_rebuild(s));
  s.x[10] += 0.00002;  // now 0.51 mm > skin/2
  EXPECT_TRUE(nl.needs_rebuild(s));
}

// Growing radii close gaps as displacements do: the displacement that forces a rebuild is half the skin less the
// growth since the build, and growth alone past half the skin forces one. The case: two spheres the skin plus a
// little apart, so unlisted; one grows and the other moves towards it, each within half the skin, together past it.
TEST(NeighborList, GrowthSinceTheBuildCountsAgainstTheSkin) {
  ParticleStore s;
  const double r = 0.001, skin = 0.0004;
  s.add(1, 0, 0, 0, r, 2500);
  s.add(2, 2 * r + skin * 1.01, 0, 0, r, 2500);
  NeighborList nl;
  nl.configure(skin, 0);
  nl.build(s);
  EXPECT_EQ(nl.size(), 0u);
  s.radius[0] += 0.3 * skin;  // the grown particle reaches 0.3 skin further
  nl.add_growth(0.3 * skin);
  s.x[1] -= 0.3 * skin;  // and the other moved 0.3 skin towards it: 0.6 skin closed, contact possible soon
  EXPECT_TRUE(nl.needs_rebuild(s)) << "0.3 skin of growth leaves 0.2 skin of displacement";
  s.x[1] += 0.15 * skin;  // back to 0.15 skin moved: within the 0.2 left
  EXPECT_FALSE(nl.needs_rebuild(s));
  nl.add_growth(0.25 * skin);  // 0.55 skin grown: more than half the skin by growth alone
  s.x[1] += 0.15 * skin;       // even at rest
  EXPECT_TRUE(nl.needs_rebuild(s));
  EXPECT_LT(nl.far_tier_displacement2(), 0.0);
  nl.build(s);  // a build starts the count again
  EXPECT_EQ(nl.grown(), 0.0);
  EXPECT_FALSE(nl.needs_rebuild(s));
  EXPECT_EQ(nl.rebuild_displacement2(), 0.25 * skin * skin);
}

TEST(NeighborList, HistorySurvivesRebuildAndReordering) {
  ParticleStore s = cloud(400, 11);
  NeighborList nl;
  nl.configure(0.0008, 3);
  nl.build(s);
  const auto expected = mark_live(nl, s, 2);  // every other pair
  // reverse the store order, as a space-filling-curve sort would shuffle it
  std::vector<std::uint32_t> order(s.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>(order.size() - 1 - k);
  s.permute(order);
  ASSERT_TRUE(nl.needs_rebuild(s));
  nl.build(s);
  std::size_t carried = 0;
  for (std::size_t k = 0; k < nl.size(); ++k) {
    const auto key = std::make_pair(s.id[nl.i[k]], s.id[nl.j[k]]);
    auto it = expected.find(key);
    if (it == expected.end()) {
      EXPECT_EQ(nl.touching[k], 0);
      EXPECT_EQ(nl.history[k * 3], 0.0);
      continue;
    }
    ++carried;
    EXPECT_EQ(nl.touching[k], 1);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(nl.history[k * 3 + c], it->second + c);
  }
  EXPECT_EQ(carried, expected.size());
}

TEST(NeighborList, HistoryOfRemovedParticlesIsDroppedAndTheRestCarried) {
  // Every pair live, a history row that encodes its ids; then every 7th
  // particle removed and the rest shuffled: the build moves the surviving
  // rows to their new entries in place (chains of swaps), drops the rows of
  // pairs with a removed particle, and zeroes every new entry. Threaded and
  // serial builds must agree.
  for (int threads : {1, 2}) {
    ParticleStore s = cloud(5000, 21);  // >= 4096: the threaded scan and carry run
    NeighborList nl;
    nl.configure(0.0008, 3);
    ThreadPool pool(threads);
    nl.build(s, &pool);
    const auto expected = mark_live(nl, s, 1);
    std::vector<std::uint8_t> remove(s.size(), 0);
    for (std::size_t k = 0; k < s.size(); k += 7) remove[k] = 1;
    s.remove_marked(remove);
    // a shuffle: k -> 7919 k mod n is a permutation (7919 is prime and does not divide n)
    std::vector<std::uint32_t> order(s.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>((k * 7919) % order.size());
    ASSERT_EQ(std::set<std::uint32_t>(order.begin(), order.end()).size(), order.size());
    s.permute(order);
    nl.build(s, &pool);
    std::size_t carried = 0;
    for (std::size_t k = 0; k < nl.size(); ++k) {
      auto it = expected.find({s.id[nl.i[k]], s.id[nl.j[k]]});
      ASSERT_TRUE(it != expected.end()) << "a pair that was not in the list before";  // nothing moved
      ++carried;
      ASSERT_EQ(nl.touching[k], 1);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(nl.history[k * 3 + c], it->second + c) << threads << " threads, entry " << k;
    }
    std::size_t surviving = 0;
    std::set<std::uint64_t> alive(s.id.begin(), s.id.end());
    for (const auto& [key, tag] : expected) surviving += alive.count(key.first) && alive.count(key.second) ? 1 : 0;
    EXPECT_EQ(carried, surviving) << threads << " threads";
    EXPECT_LT(surviving, expected.size());  // some rows were dropped
  }
}

TEST(NeighborList, HistoryIsCarriedByRowWhenTheLayoutIsUnchanged) {
  // Without an insertion, removal or re-ordering since the last build (most
  // builds), the carry-over finds each live pair in its row of the new list
  // instead of through the id table. Particles move (some pairs leave the
  // cut-off, others enter, some change tier); each live pair still in the
  // list must get its own row back, every other entry zero, serial or
  // threaded.
  for (int threads : {1, 2}) {
    ParticleStore s = cloud(5000, 31);  // >= 4096: the threaded scan and carry run
    NeighborList nl;
    nl.configure(0.0008, 3);
    ThreadPool pool(threads);
    nl.build(s, &pool);
    const auto expected = mark_live(nl, s, 3);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> step(-0.0006, 0.0006);
    for (std::size_t k = 0; k < s.size(); ++k) {
      s.x[k] += step(rng);
      s.y[k] += step(rng);
      s.z[k] += step(rng);
    }
    ASSERT_FALSE(nl.layout_stale(s));
    nl.build(s, &pool);
    const auto now = brute(s, 0.0008);
    ASSERT_EQ(nl.size(), now.size());
    std::size_t carried = 0;
    for (std::size_t k = 0; k < nl.size(); ++k) {
      auto it = expected.find({s.id[nl.i[k]], s.id[nl.j[k]]});
      if (it == expected.end()) {
        ASSERT_EQ(nl.touching[k], 0) << threads << " threads, entry " << k;
        for (int c = 0; c < 3; ++c) ASSERT_EQ(nl.history[k * 3 + c], 0.0);
        continue;
      }
      ++carried;
      ASSERT_EQ(nl.touching[k], 1) << threads << " threads, entry " << k;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(nl.history[k * 3 + c], it->second + c) << threads << " threads, entry " << k;
    }
    std::size_t still = 0;
    for (const auto& [key, tag] : expected) still += now.count(key);
    EXPECT_EQ(carried, still) << threads << " threads";
    EXPECT_LT(still, expected.size());  // some live pairs left the list
    EXPECT_GT(still, expected.size() / 2);
  }
}

TEST(WallNeighbors, HistoryFollowsParticleIdsAcrossReordering) {
  ParticleStore s = cloud(200, 5);
  WallPrimitive floor;
  floor.p[2] = 0.01;  // plane z = 0.01, normal +z
  WallNeighbors wl;
  wl.build(s, floor, 0.002, 3);
  ASSERT_FALSE(wl.particle.empty());
  for (std::size_t k = 0; k < wl.particle.size(); ++k) {
    wl.touching[k] = 1;
    wl.history[k * 3] = static_cast<double>(s.id[wl.particle[k]]);
  }
  std::vector<std::uint32_t> order(s.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>((k * 37) % order.size());
  s.permute(order);
  wl.build(s, floor, 0.002, 3);
  for (std::size_t k = 0; k < wl.particle.size(); ++k) {
    EXPECT_EQ(wl.touching[k], 1);
    EXPECT_EQ(wl.history[k * 3], static_cast<double>(s.id[wl.particle[k]]));
  }
}

TEST(WallNeighbors, FixedParticlesAreNotWallCandidates) {
  // A fixed particle never moves, so walls leave it out (as two fixed
  // particles never interact): a fixed floor laid across a container's wall
  // would otherwise count as deep "contacts" with it.
  ParticleStore s;
  s.add(1, 0.0, 0.0, 0.0101, 0.001, 2500);        // free, 0.1 mm above touching the plane
  s.add(2, 0.01, 0.0, 0.0101, 0.001, 2500, true);  // fixed, the same height
  s.add(3, 0.02, 0.0, 0.0, 0.001, 2500, true);     // fixed, 10 diameters "into" the plane
  WallPrimitive floor;
  floor.p[2] = 0.01;  // plane z = 0.01, normal +z
  WallNeighbors wl;
  wl.build(s, floor, 0.002, 3);
  ASSERT_EQ(wl.particle.size(), 1u);
  EXPECT_EQ(s.id[wl.particle[0]], 1u);
}

TEST(Suggest, DidYouMeanOrFullList) {
  EXPECT_EQ(suggest("hertzz", {"hertz", "linear"}), "did you mean 'hertz'?");
  EXPECT_EQ(suggest("spring", {"linear", "hertz"}), "valid: hertz, linear");
  EXPECT_EQ(suggest("x", {}), "");
}

// Periodic boundaries: the list holds exactly the pairs within the cut-off
// of their nearest image (brute force over the 27 images, on a periodic
// cloud in x and z, 2 cells and more per axis), on 1 and 2 threads alike;
// wrapping a particle by one period keeps its pairs and their history.
TEST(NeighborList, PeriodicAxesFindPairsThroughTheFacesAndKeepTheirHistory) {
  for (double L : {0.05, 0.009}) {  // 0.009: two cells along each periodic axis
    ParticleStore s;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> pos(0.0, L), rad(0.001, 0.0015);
    const std::size_t n = L > 0.02 ? 5000 : 60;
    for (std::size_t k = 0; k < n; ++k) s.add(100 + k, pos(rng), pos(rng) * 4, pos(rng), rad(rng), 2500);
    PeriodicBox box;
    box.axis[0] = box.axis[2] = true;
    box.hi[0] = box.hi[2] = L;
    const double skin = 0.0005;
    std::set<std::pair<std::uint64_t, std::uint64_t>> expected;
    for (std::size_t a = 0; a < s.size(); ++a)
      for (std::size_t b = a + 1; b < s.size(); ++b) {
        double dx = s.x[a] - s.x[b], dz = s.z[a] - s.z[b];
        dx -= L * std::nearbyint(dx / L);
        dz -= L * std::nearbyint(dz / L);
        const double dy = s.y[a] - s.y[b];
        const double cut = s.radius[a] + s.radius[b] + skin;
        if (dx * dx + dy * dy + dz * dz < cut * cut) expected.insert(std::minmax(s.id[a], s.id[b]));
      }
    ThreadPool pool(2);
    for (ThreadPool* p : {static_cast<ThreadPool*>(nullptr), &pool}) {
      NeighborList nl;
      nl.configure(skin, 3);
      nl.set_periodic(box);
      nl.build(s, p);
      std::set<std::pair<std::uint64_t, std::uint64_t>> got;
      for (std::size_t k = 0; k < nl.size(); ++k) got.insert({s.id[nl.i[k]], s.id[nl.j[k]]});
      EXPECT_EQ(got.size(), nl.size()) << "a pair listed twice, L = " << L;
      EXPECT_EQ(got, expected) << "L = " << L;
      // history survives a particle leaving through a face and re-entering
      const auto tags = mark_live(nl, s, 3);
      ParticleStore moved = s;
      for (std::size_t k = 0; k < moved.size(); k += 2) moved.x[k] += L;  // one period out
      EXPECT_GT(box.wrap(moved), 0u);
      for (std::size_t k = 0; k < moved.size(); ++k) {
        EXPECT_GE(moved.x[k], 0.0);
        EXPECT_LT(moved.x[k], L);
      }
      nl.build(moved, p);
      std::size_t kept = 0;
      for (std::size_t k = 0; k < nl.size(); ++k) {
        const auto it = tags.find({moved.id[nl.i[k]], moved.id[nl.j[k]]});
        if (it == tags.end()) continue;
        ASSERT_TRUE(nl.touching[k]);
        EXPECT_EQ(nl.history[k * 3], it->second);
        ++kept;
      }
      EXPECT_EQ(kept, tags.size());
    }
  }
  // a box shorter than twice the cut-off is refused
  ParticleStore s;
  s.add(1, 0.001, 0, 0, 0.001, 2500);
  PeriodicBox box;
  box.axis[0] = true;
  box.hi[0] = 0.005;
  NeighborList nl;
  nl.configure(0.001, 3);
  nl.set_periodic(box);
  EXPECT_THROW(nl.build(s), RuntimeError);
}

TEST(NeighborList, LiveHistoriesAdoptedByAnotherListAreCarriedByIds) {
  // What a particle takes to another rank: the live rows, by ids, adopted
  // by another list whose store holds the particles in another order (the
  // receiving rank's); its next build finds each row's pair.
  ParticleStore s = cloud(400, 13);
  NeighborList nl;
  nl.configure(0.0008, 3);
  nl.build(s);
  const auto expected = mark_live(nl, s, 3);
  const PairHistories h = nl.live_histories();
  ASSERT_EQ(h.size(), expected.size());
  EXPECT_EQ(h.stride, 3u);
  std::vector<std::uint32_t> order(s.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>((k * 101) % order.size());
  s.permute(order);
  NeighborList other;
  other.configure(0.0008, 3);
  other.adopt_histories(h);
  other.build(s);
  std::size_t carried = 0;
  for (std::size_t k = 0; k < other.size(); ++k) {
    const auto it = expected.find({s.id[other.i[k]], s.id[other.j[k]]});
    if (it == expected.end()) {
      EXPECT_EQ(other.touching[k], 0);
      continue;
    }
    ++carried;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(other.history[k * 3 + c], it->second + c);
  }
  EXPECT_EQ(carried, expected.size());
  PairHistories wrong = h;
  wrong.values.pop_back();
  EXPECT_THROW(other.adopt_histories(wrong), std::invalid_argument);
}

TEST(NeighborList, WithGhostsAPairIsListedOnlyWhereItsLowerIdIsOwned) {
  // particles [0, owned) owned, the rest ghosts: the list holds exactly the
  // brute-force pairs whose lower id is an owned particle
  const ParticleStore s = cloud(600, 17);
  const std::size_t owned = 350;
  NeighborList nl;
  nl.configure(0.0008, 3);
  nl.build(s, nullptr, owned);
  std::set<std::uint64_t> owned_ids(s.id.begin(), s.id.begin() + static_cast<std::ptrdiff_t>(owned));
  std::set<std::pair<std::uint64_t, std::uint64_t>> want, got;
  for (const auto& p : brute(s, 0.0008))
    if (owned_ids.count(p.first)) want.insert(p);
  for (std::size_t k = 0; k < nl.size(); ++k) got.insert({s.id[nl.i[k]], s.id[nl.j[k]]});
  EXPECT_EQ(got, want);
  EXPECT_EQ(got.size(), nl.size());
  EXPECT_GT(want.size(), 100u);
}

TEST(WallNeighbors, LiveHistoriesAdoptedByAnotherListAreCarriedByIds) {
  ParticleStore s = cloud(200, 5);
  WallPrimitive floor;
  floor.p[2] = 0.01;
  WallNeighbors wl;
  wl.build(s, floor, 0.002, 3);
  ASSERT_FALSE(wl.particle.empty());
  for (std::size_t k = 0; k < wl.particle.size(); k += 2) {
    wl.touching[k] = 1;
    wl.history[k * 3] = static_cast<double>(s.id[wl.particle[k]]);
  }
  WallNeighbors other;
  other.adopt_histories(wl.live_histories(3));
  other.build(s, floor, 0.002, 3);
  std::size_t live = 0;
  for (std::size_t k = 0; k < other.particle.size(); ++k) {
    EXPECT_EQ(other.touching[k], k % 2 == 0 ? 1 : 0);
    EXPECT_EQ(other.history[k * 3], k % 2 == 0 ? static_cast<double>(s.id[other.particle[k]]) : 0.0);
    live += other.touching[k];
  }
  EXPECT_GT(live, 0u);
  // only particles [0, count) are candidates
  WallNeighbors part;
  part.build(s, floor, 0.002, 3, true, 50);
  for (std::uint32_t k : part.particle) EXPECT_LT(k, 50u);
}

TEST(ParticleStore, AppendKeepsEveryArrayOfBothStoresInOrder) {
  // what a restart on another rank count does with the parts it keeps
  // (Subdomain::restore_shared_out): every per-particle array, the external
  // forces and aux arrays included, of a then b
  auto make = [](std::uint64_t first, int n) {
    ParticleStore s;
    s.enable_external_force();
    s.add_aux(1);
    for (int k = 0; k < n; ++k) {
      s.add(first + static_cast<std::uint64_t>(k), 0.1 * k, 0.2 * k, 0.3 * k, 0.001, 2500.0);
      s.fx.back() = static_cast<double>(first) + k;
      s.ext_fz.back() = -1.0 * (static_cast<double>(first) + k);
      s.aux[0].back() = 7.0 * (static_cast<double>(first) + k);
    }
    return s;
  };
  ParticleStore a = make(10, 3);
  const ParticleStore b = make(20, 2);
  a.append(b);
  ASSERT_EQ(a.size(), 5u);
  const std::vector<std::uint64_t> ids = {10, 11, 12, 20, 21};
  for (std::size_t k = 0; k < ids.size(); ++k) {
    EXPECT_EQ(a.id[k], ids[k]);
    EXPECT_EQ(a.fx[k], static_cast<double>(ids[k]));
    EXPECT_EQ(a.ext_fz[k], -static_cast<double>(ids[k]));
    EXPECT_EQ(a.aux[0][k], 7.0 * static_cast<double>(ids[k]));
  }
  EXPECT_EQ(a.z[4], b.z[1]);
  ParticleStore plain;
  EXPECT_THROW(plain.append(b), std::invalid_argument);
}
