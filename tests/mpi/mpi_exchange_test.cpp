// SPDX-License-Identifier: MIT
// The decomposition and the particle exchange on several MPI ranks: every
// rank computes the same tree whatever particles it holds, migration keeps
// every particle exactly once on its owner, and with the ghosts each pair
// closer than the cut-off is complete on exactly one rank (the owner of its
// lower id), checked against all pairs of the gathered particles.
#include "distributed/communicator.hpp"
#include "distributed/decomposition.hpp"
#include "distributed/particle_exchange.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <set>
#include <unordered_set>

namespace dp = domel::platform;

namespace {

constexpr std::size_t kTotal = 6000;
constexpr double kCutoff = 0.006;

dp::Region extent() { return {{0, 0, 0}, {0.08, 0.06, 0.2}}; }

/// Particle g of the global set (the same on every rank): a column with a
/// denser bottom layer, radius 1 mm.
void particle(std::size_t g, double p[3]) {
  std::mt19937_64 rng(1000 + g);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  p[0] = 0.08 * u(rng);
  p[1] = 0.06 * u(rng);
  p[2] = g % 3 == 0 ? 0.03 * u(rng) : 0.2 * u(rng);
}

/// This rank's share of the global set: `blocks` gives rank r the g in
/// [r n / size, (r + 1) n / size), else every size-th.
dp::ParticleStore share(const dp::Communicator& comm, bool blocks) {
  dp::ParticleStore s;
  const auto size = static_cast<std::size_t>(comm.size()), rank = static_cast<std::size_t>(comm.rank());
  for (std::size_t g = 0; g < kTotal; ++g) {
    const bool mine = blocks ? (g * size / kTotal == rank) : (g % size == rank);
    if (!mine) continue;
    double p[3];
    particle(g, p);
    s.add(g, p[0], p[1], p[2], 0.001, 2500.0);
    s.vx.back() = static_cast<double>(g);  // a payload that must travel with the particle
  }
  return s;
}

std::vector<std::uint64_t> costs(const dp::ParticleStore& s) {
  std::vector<std::uint64_t> c(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) c[k] = s.z[k] < 0.03 ? 12 : 1;
  return c;
}

dp::Decomposition decompose(const dp::ParticleStore& s, const dp::Communicator& comm) {
  const auto c = costs(s);
  return dp::Decomposition::bisect(extent(), comm.size(), s.x.data(), s.y.data(), s.z.data(), c.data(), s.size(),
                                   comm);
}

std::vector<char> bytes_of(const std::vector<double>& v) {
  std::vector<char> b(v.size() * sizeof(double));
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

}  // namespace

TEST(Mpi, EveryRankComputesTheSameTreeWhateverItHolds) {
  const dp::Communicator comm = dp::Communicator::world();
  const dp::Decomposition a = decompose(share(comm, true), comm);
  const dp::Decomposition b = decompose(share(comm, false), comm);
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  std::vector<double> cuts;
  for (std::size_t i = 0; i < a.nodes().size(); ++i) {
    EXPECT_EQ(a.nodes()[i].cut, b.nodes()[i].cut);  // the same set spread otherwise: the same cuts, bit for bit
    cuts.push_back(a.nodes()[i].cut);
  }
  // and every rank has the same cuts as rank 0
  const auto all = comm.all_gather(bytes_of(cuts));
  for (const auto& other : all) EXPECT_EQ(other, all[0]);
}

TEST(Mpi, MigrationKeepsEveryParticleOnceOnItsOwner) {
  const dp::Communicator comm = dp::Communicator::world();
  dp::ParticleStore s = share(comm, false);
  const dp::Decomposition d = decompose(s, comm);
  const auto moved = dp::migrate(s, d, comm);
  std::vector<std::uint64_t> counts{s.size(), moved.sent, moved.received};
  comm.sum(counts);
  EXPECT_EQ(counts[0], kTotal);
  EXPECT_EQ(counts[1], counts[2]);  // what left arrived
  if (comm.size() > 1) EXPECT_GT(counts[1], 0u);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double p[3] = {s.x[k], s.y[k], s.z[k]};
    EXPECT_EQ(d.owner(p), comm.rank());
    EXPECT_EQ(s.vx[k], static_cast<double>(s.id[k]));  // the payload travelled with it
  }
  // each id exactly once over all ranks
  std::vector<std::uint64_t> seen(kTotal, 0);
  for (std::uint64_t id : s.id) ++seen[id];
  comm.sum(seen);
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](std::uint64_t c) { return c == 1; }));
  // a second migration moves nothing
  const auto again = dp::migrate(s, d, comm);
  EXPECT_EQ(again.sent, 0u);
}

TEST(Mpi, WithTheGhostsEachClosePairIsCompleteOnExactlyOneRank) {
  const dp::Communicator comm = dp::Communicator::world();
  dp::ParticleStore s = share(comm, true);
  const dp::Decomposition d = decompose(s, comm);
  dp::migrate(s, d, comm);
  dp::ParticleStore ghosts;
  dp::exchange_ghosts(s, ghosts, d, kCutoff, comm);
  // ghosts are other ranks' particles, each once
  std::unordered_set<std::uint64_t> owned(s.id.begin(), s.id.end()), here = owned;
  for (std::uint64_t id : ghosts.id) {
    EXPECT_EQ(owned.count(id), 0u);
    EXPECT_TRUE(here.insert(id).second) << "ghost " << id << " twice";
  }
  // the pairs this rank computes: the owner of the lower id computes a pair
  std::uint64_t computed = 0, missing = 0;
  std::vector<double> gx(kTotal), gy(kTotal), gz(kTotal);
  for (std::size_t g = 0; g < kTotal; ++g) {
    double p[3];
    particle(g, p);
    gx[g] = p[0]; gy[g] = p[1]; gz[g] = p[2];
  }
  std::uint64_t close_pairs = 0;
  for (std::size_t i = 0; i < kTotal; ++i)
    for (std::size_t j = i + 1; j < kTotal; ++j) {
      const double dx = gx[i] - gx[j], dy = gy[i] - gy[j], dz = gz[i] - gz[j];
      if (dx * dx + dy * dy + dz * dz >= kCutoff * kCutoff) continue;
      ++close_pairs;
      if (owned.count(i) == 0) continue;
      if (here.count(j)) ++computed;
      else ++missing;
    }
  EXPECT_EQ(missing, 0u) << "pairs whose partner is neither owned nor a ghost here";
  std::vector<std::uint64_t> total{computed};
  comm.sum(total);
  EXPECT_EQ(total[0], close_pairs);  // every close pair once over all ranks
  EXPECT_GT(close_pairs, 1000u);     // the check has something to check
}

int main(int argc, char** argv) {
  dp::MpiSession mpi(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  // one report: the other ranks print only failures
  if (dp::Communicator::world().rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
