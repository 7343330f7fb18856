// SPDX-License-Identifier: MIT
// The particle store's one list of fields (ParticleStore::for_each_field,
// issue 40): a field added in one place (add_field) with its sync policy is
// packed for a migration or a ghost build only when its policy says so,
// saved in checkpoints only with kCheckpoint, and keeps its name; and the
// one-process ranks (loop/ranks.hpp) hand out the level's own store and
// leave every sum bit for bit as it was. The 3-rank test of the same field
// is tests/mpi/mpi_subdomain_test.cpp. Well under a second.
#include "core/archive.hpp"
#include "core/particle_store.hpp"
#include "distributed/particle_exchange.hpp"
#include "loop/ranks.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace dp = domel::platform;
namespace dt = domel::test;
using Store = dp::ParticleStore;

namespace {

/// Three particles with a carried field `carried` (k + 1) and a field
/// `local` (10 k) that neither travels nor is saved.
Store three(std::size_t& carried, std::size_t& local) {
  Store s;
  carried = s.add_field("carried", Store::kCarried);
  local = s.add_field("local", 0u);
  for (std::uint64_t k = 0; k < 3; ++k) {
    s.add(k + 1, 0.01 * static_cast<double>(k), 0, 0, 0.001, 2500);
    s.aux[carried][k] = static_cast<double>(k) + 1.0;
    s.aux[local][k] = 10.0 * static_cast<double>(k);
  }
  return s;
}

}  // namespace

TEST(ParticleFields, AnAddedFieldTravelsOnlyWhereItsPolicySays) {
  std::size_t carried = 0, local = 0;
  const Store s = three(carried, local);
  // a migration's bytes: every built-in field and `carried`, not `local`
  Store bare;
  bare.add(1, 0, 0, 0, 0.001, 2500);
  EXPECT_EQ(dp::particle_bytes(s), dp::particle_bytes(bare) + sizeof(double));
  Store to = s.empty_like();
  dp::unpack_particles(to, dp::pack_particles(s, {2, 0}));
  ASSERT_EQ(to.size(), 2u);
  EXPECT_EQ(to.aux_names(), s.aux_names());
  EXPECT_EQ(to.id[0], 3u);
  EXPECT_EQ(to.aux[carried][0], 3.0);  // travelled with its particle
  EXPECT_EQ(to.aux[carried][1], 1.0);
  EXPECT_EQ(to.aux[local][0], 0.0);  // not sent: zero, as for a new particle
  // the ghosts' refresh and the reverse exchange: the built-in motion (9
  // doubles) and loads (6), and no added field
  EXPECT_EQ(dp::particle_bytes(s, Store::kGhostUpdate), 9 * sizeof(double));
  EXPECT_EQ(dp::particle_bytes(s, Store::kReverse), 6 * sizeof(double));
}

TEST(ParticleFields, ACheckpointHoldsTheFieldsWithKCheckpointByName) {
  std::size_t carried = 0, local = 0;
  Store s = three(carried, local);
  dp::ArchiveWriter w;
  s.save(w, "p/");
  const std::string bytes = w.serialize("{}");
  const dp::ArchiveReader r(bytes, "fields.ckpt");
  EXPECT_TRUE(r.has("p/carried"));
  EXPECT_FALSE(r.has("p/local"));
  std::size_t c2 = 0, l2 = 0;
  Store back = three(c2, l2);
  back.aux[c2].assign(3, -1.0);
  back.load(r, "p/");
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(back.aux[c2][k], s.aux[carried][k]);
    EXPECT_EQ(back.aux[l2][k], 0.0);  // not saved: restarts at zero
  }
}

TEST(ParticleFields, ANameIsTakenOnce) {
  Store s;
  s.add_field("tag", Store::kCarried);
  EXPECT_THROW(s.add_field("tag", Store::kCarried), std::invalid_argument);
  EXPECT_THROW(s.add_field("radius", Store::kCarried), std::invalid_argument);
  EXPECT_THROW(s.add_field("aux_count", Store::kCarried), std::invalid_argument);
}

TEST(SingleProcess, AGatherIsTheLevelsOwnStoreAndSumsLeaveEveryBit) {
  auto sim = dt::build(dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5));
  dp::Subdomain& sd = dt::one_sphere(*sim, {0, 0, 0.01}, 0.001, 2500);
  dp::RunRanks& ranks = dp::one_process();
  dp::GatheredParticles whole = ranks.gather(sd, true);
  EXPECT_EQ(&*whole, &sd.store());  // no copy: an edit of the whole set is the level's
  EXPECT_EQ(ranks.where_in_gathered(sd, *whole, "test"), std::vector<std::size_t>{0});
  const auto [begin, end] = ranks.keep_added(sd, *whole, 0);
  EXPECT_EQ(begin, 0u);
  EXPECT_EQ(end, 1u);
  std::vector<double> sums{-0.0, 1.5}, maxima{-2.0};
  ranks.reduce_in_rank_order(sums, maxima);
  EXPECT_TRUE(std::signbit(sums[0]));  // -0.0 stays -0.0 (0.0 + x would not)
  EXPECT_EQ(sums[1], 1.5);
  EXPECT_EQ(maxima[0], -2.0);
  EXPECT_TRUE(std::signbit(ranks.sum_in_rank_order({-0.0})[0]));
  EXPECT_EQ(ranks.sum_count(7), 7u);
  EXPECT_EQ(ranks.max(-3.0), -3.0);
  EXPECT_TRUE(ranks.traffic(sd).is_null());
}
