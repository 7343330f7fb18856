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
#include <array>
#include <cmath>
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

/// The particles of this rank after migration, then their ghosts.
struct Distributed {
  Distributed(bool blocks, const dp::PeriodicBox& box = {})
      : comm(dp::Communicator::world()), s(share(comm, blocks)), d(decompose(s, comm)) {
    dp::migrate(s, d, comm);
    owned = s.size();
    gx.build(s, owned, d, kCutoff, comm, box);
  }
  dp::Communicator comm;
  dp::ParticleStore s;  ///< [0, owned) owned, then ghosts
  dp::Decomposition d;
  std::size_t owned = 0;
  dp::GhostExchange gx;
};

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
  Distributed run(true);
  const dp::Communicator& comm = run.comm;
  const dp::ParticleStore& s = run.s;
  const auto first_ghost = s.id.begin() + static_cast<std::ptrdiff_t>(run.owned);
  EXPECT_EQ(run.gx.owned(), run.owned);
  // ghosts are other ranks' particles, each once
  std::unordered_set<std::uint64_t> owned(s.id.begin(), first_ghost), here = owned;
  for (auto g = first_ghost; g != s.id.end(); ++g) {
    EXPECT_EQ(owned.count(*g), 0u);
    EXPECT_TRUE(here.insert(*g).second) << "ghost " << *g << " twice";
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

TEST(Mpi, IdsClaimedByEveryRankAreUniqueAndContiguous) {
  const dp::Communicator comm = dp::Communicator::world();
  std::uint64_t next = 100;
  std::vector<std::uint64_t> mine;
  for (int round = 0; round < 3; ++round) {
    const std::uint64_t n = static_cast<std::uint64_t>((comm.rank() + round) % 3);  // some ranks claim none
    const std::uint64_t first = dp::claim_ids(n, next, comm);
    for (std::uint64_t k = 0; k < n; ++k) mine.push_back(first + k);
  }
  std::vector<std::uint64_t> seen(static_cast<std::size_t>(next - 100), 0), after{next};
  for (std::uint64_t id : mine) ++seen[static_cast<std::size_t>(id - 100)];
  comm.sum(seen);
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](std::uint64_t c) { return c == 1; }));  // no gap, no twin
  comm.sum(after);
  EXPECT_EQ(after[0], next * static_cast<std::uint64_t>(comm.size()));  // the same next_id everywhere
}

namespace {
/// A test load between particles at separation d closer than rc: a spring on the
/// gap along the line of centres, and a torque on each that depends on the
/// pair (so that torques travel home too). Returns false beyond rc.
bool load(const double d[3], double rc, double f[3], double t[3]) {
  const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (r >= rc) return false;
  for (int k = 0; k < 3; ++k) {
    f[k] = 1e3 * (rc - r) * d[k] / r;
    t[k] = 1e-2 * (rc - r) * (k + 1);
  }
  return true;
}
/// Particle g after a small move (at most 1e-4 m along each axis).
void moved(std::size_t g, double p[3]) {
  particle(g, p);
  p[0] += 1e-4 * std::sin(1.0 * g);
  p[1] += 1e-4 * std::cos(2.0 * g);
  p[2] -= 1e-4 * std::sin(3.0 * g);
}
}  // namespace

namespace {
/// Build the ghosts (through the faces of `box` where periodic), move the
/// owners, update the ghosts, compute pair loads on owned + ghosts, send the
/// ghosts' home, and compare with the same loads on one process (nearest
/// images through periodic faces).
void ghosts_follow_and_forces_go_home(const dp::PeriodicBox& box) {
  Distributed run(false, box);
  const dp::Communicator& comm = run.comm;
  dp::ParticleStore& s = run.s;
  const std::size_t no = run.owned, nall = s.size();
  const dp::GhostExchange& gx = run.gx;
  // the owners move (less than the list's skin would allow) and the ghosts follow
  for (std::size_t k = 0; k < no; ++k) {
    double p[3];
    moved(s.id[k], p);
    s.x[k] = p[0]; s.y[k] = p[1]; s.z[k] = p[2];
    s.wz[k] = static_cast<double>(s.id[k]);
  }
  gx.update(s, comm);
  for (std::size_t k = no; k < nall; ++k) {
    double p[3];
    moved(s.id[k], p);
    // the owner's position, or an image of it a whole period away
    double L[3], inv_L[3];
    box.periods(L, inv_L);
    for (int a = 0; a < 3; ++a) {
      const double at = a == 0 ? s.x[k] : a == 1 ? s.y[k] : s.z[k];
      EXPECT_NEAR(dp::min_image(at - p[a], L[a], inv_L[a]), 0.0, 1e-15);
      if (!box.axis[a]) EXPECT_EQ(at, p[a]);
    }
    EXPECT_EQ(s.wz[k], static_cast<double>(s.id[k]));
  }
  // pair loads on owned + ghosts: the rank owning the lower id computes the
  // pair; each moved by at most sqrt(3) 1e-4, so pairs within this range were
  // within the ghost cut-off when the ghosts were built
  const double rc = kCutoff - 2.0 * std::sqrt(3.0) * 1e-4;
  for (auto* a : {&s.fx, &s.fy, &s.fz, &s.tx, &s.ty, &s.tz}) std::fill(a->begin(), a->end(), 0.0);
  auto add = [&](std::size_t k, const double f[3], const double t[3], double sign) {
    s.fx[k] += sign * f[0]; s.fy[k] += sign * f[1]; s.fz[k] += sign * f[2];
    s.tx[k] += t[0]; s.ty[k] += t[1]; s.tz[k] += t[2];
  };
  for (std::size_t a = 0; a < no; ++a)
    for (std::size_t b = 0; b < nall; ++b) {
      if (s.id[a] >= s.id[b]) continue;  // the lower id is owned here: this rank computes the pair
      double f[3], t[3];
      const double sep[3] = {s.x[a] - s.x[b], s.y[a] - s.y[b], s.z[a] - s.z[b]};  // images carry their shift
      if (!load(sep, rc, f, t)) continue;
      add(a, f, t, 1.0);
      add(b, f, t, -1.0);
    }
  gx.reverse(s, comm);
  // one process, same loads
  std::vector<double> fx(kTotal, 0.0), tz(kTotal, 0.0);
  std::vector<std::array<double, 3>> pos(kTotal);
  double period[3], inv[3];
  box.periods(period, inv);
  std::uint64_t through = 0;
  for (std::size_t g = 0; g < kTotal; ++g) moved(g, pos[g].data());
  for (std::size_t i = 0; i < kTotal; ++i)
    for (std::size_t j = i + 1; j < kTotal; ++j) {
      double f[3], t[3], sep[3];
      bool face = false;
      for (int a = 0; a < 3; ++a) {
        sep[a] = dp::min_image(pos[i][a] - pos[j][a], period[a], inv[a]);
        face = face || sep[a] != pos[i][a] - pos[j][a];
      }
      if (!load(sep, rc, f, t)) continue;
      through += face ? 1 : 0;
      fx[i] += f[0]; fx[j] -= f[0];
      tz[i] += t[2]; tz[j] += t[2];
    }
  std::size_t loaded = 0;
  for (std::size_t k = 0; k < no; ++k) {
    const std::uint64_t g = s.id[k];
    // the same terms summed in another order: equal to round-off (1e-12 of the largest term)
    EXPECT_NEAR(s.fx[k], fx[g], 1e-12 * 1e3 * kCutoff * 10) << "particle " << g;
    EXPECT_NEAR(s.tz[k], tz[g], 1e-12 * 1e-2 * kCutoff * 3 * 10) << "particle " << g;
    loaded += tz[g] != 0.0 ? 1 : 0;
  }
  std::vector<std::uint64_t> n{loaded};
  comm.sum(n);
  EXPECT_GT(n[0], kTotal / 4);  // most particles carry a load: the check has something to check
  if (box.any()) EXPECT_GT(through, 100u);  // and many of them through a periodic face
}

}  // namespace

TEST(Mpi, GhostsFollowTheirOwnersAndTheirForcesGoHome) { ghosts_follow_and_forces_go_home({}); }

TEST(Mpi, ThroughPeriodicFacesGhostsAreImagesAndForcesEqualTheNearestImages) {
  dp::PeriodicBox box;
  box.axis[0] = box.axis[1] = true;
  box.hi[0] = 0.08;
  box.hi[1] = 0.06;
  box.hi[2] = 0.2;
  ghosts_follow_and_forces_go_home(box);
}
