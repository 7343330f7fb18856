// SPDX-License-Identifier: MIT
// A subdomain spread over the ranks (distributed/subdomain_ranks.hpp) steps
// as the same subdomain on one process does: every rank builds the same
// scenario, keeps every size-th particle, and after the run each particle it
// owns is compared, by id, with the one-process run of the same scenario.
// The two runs add the same contact forces in another order, so they differ
// by round-off, which the collisions amplify; the tolerance is set from
// that (see kChaos below). A contact history lost or reset when a particle
// moves to another rank (or a pair computed twice, or a ghost force not sent
// home) changes a force by its whole tangential part at once, which is
// orders of magnitude above it.
#include "core/archive.hpp"
#include "distributed/communicator.hpp"
#include "distributed/subdomain_ranks.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>
#include <unordered_map>

namespace dp = domel::platform;
namespace dt = domel::test;
using nlohmann::json;

namespace {

constexpr double kD = 0.002;

/// Dense frictional gas in a box periodic along x, y and z: a 10^3 lattice
/// at 1.2 d (solid fraction 0.30), e = 0.5, mu = 0.5, Hertz-Mindlin.
json gas() {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5);
  const double L = 12 * kD;
  json insert = {{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.2}, {"jitter", 0.05}};
  insert["region"] = {{"box", {{"min", {0, 0, 0}}, {"max", {L, L, L}}}}};
  doc["subdomains"][0]["insert"] = json::array({insert});
  doc["subdomains"][0]["periodic"] = {{"x", {0, L}}, {"y", {0, L}}, {"z", {0, L}}};
  return doc;
}

/// The lattice column of the fixture, settling between the walls of a box.
json column() { return dt::lattice_column(kD); }

/// Random velocities (0.5 m/s scale) and spins, from the id: the same on every rank.
void stir(dp::ParticleStore& s) {
  for (std::size_t k = 0; k < s.size(); ++k) {
    std::mt19937_64 rng(s.id[k]);
    std::normal_distribution<double> g(0.0, 0.3);
    s.vx[k] = g(rng); s.vy[k] = g(rng); s.vz[k] = g(rng);
    s.wx[k] = g(rng) / kD; s.wy[k] = g(rng) / kD; s.wz[k] = g(rng) / kD;
  }
}

struct Run {
  std::unique_ptr<dp::Simulation> sim;
  dp::SubdomainRanks* ranks = nullptr;
  dp::Subdomain& sd() { return *sim->subdomains[0]; }
};

/// The scenario set up on this process alone, or spread over the ranks of
/// `comm` (each rank starts with every size-th particle).
Run prepared(const json& doc, bool stirred, const dp::Communicator* comm, double nudge = 0.0, int threads = 1) {
  Run r{dt::build(doc)};
  dp::Subdomain& sd = r.sd();
  dp::ParticleStore& s = sd.store();
  if (stirred) stir(s);
  for (std::size_t k = 0; k < s.size(); ++k) s.x[k] *= 1.0 + nudge;
  sd.set_threads(threads);
  sd.set_skin(0.3 * kD);
  if (comm) {
    std::vector<std::uint8_t> other(s.size());
    for (std::size_t k = 0; k < s.size(); ++k)
      other[k] = !dp::starts_on_rank(s.id[k], comm->rank(), comm->size());
    s.remove_marked(other);
    r.ranks = &dp::distribute(sd, *comm);
  }
  sd.setup();
  return r;
}

struct Difference {
  double x = 0, v = 0, w = 0;  ///< largest over the particles [m, m/s, rad/s]
  std::uint64_t compared = 0;
};

/// This rank's owned particles against the reference, by id (positions by
/// the nearest image along periodic axes).
Difference compare(Run& run, Run& ref) {
  dp::Subdomain& sd = run.sd();
  const dp::ParticleStore& s = sd.store();
  const dp::ParticleStore& r = ref.sd().store();
  std::unordered_map<std::uint64_t, std::size_t> at;
  for (std::size_t k = 0; k < r.size(); ++k) at.emplace(r.id[k], k);
  double L[3], inv[3];
  sd.periodic().periods(L, inv);
  Difference d;
  for (std::size_t k = 0; k < sd.owned(); ++k) {
    const std::size_t q = at.at(s.id[k]);
    const double dx[3] = {s.x[k] - r.x[q], s.y[k] - r.y[q], s.z[k] - r.z[q]};
    for (int a = 0; a < 3; ++a) d.x = std::max(d.x, std::abs(dp::min_image(dx[a], L[a], inv[a])));
    d.v = std::max({d.v, std::abs(s.vx[k] - r.vx[q]), std::abs(s.vy[k] - r.vy[q]), std::abs(s.vz[k] - r.vz[q])});
    d.w = std::max({d.w, std::abs(s.wx[k] - r.wx[q]), std::abs(s.wy[k] - r.wy[q]), std::abs(s.wz[k] - r.wz[q])});
    ++d.compared;
  }
  return d;
}

/// How far round-off alone moves these runs: the largest differences of the
/// one-process run against itself with every x coordinate moved by a few
/// units in the last place (kNudge, relative), over the same steps, times
/// kChaos. The distributed run rounds differently at every step (the forces
/// summed in another order, the images' positions rounded where the
/// periodic run rounds their separations) and must stay within that band:
/// both start at round-off and the collisions amplify them alike, but not
/// at the same moments, hence the factor.
constexpr double kNudge = 1e-15;
constexpr double kChaos = 100.0;

void spread_runs_as_one_process(const json& doc, bool stirred, int steps, int threads = 1) {
  const dp::Communicator comm = dp::Communicator::world();
  Run ref = prepared(doc, stirred, nullptr);
  Run ref2 = prepared(doc, stirred, nullptr, kNudge);
  Run run = prepared(doc, stirred, &comm, 0.0, threads);
  for (int k = 0; k < steps; ++k) {
    ref.sd().step();
    ref2.sd().step();
    run.sd().step();
  }
  const Difference roundoff = compare(ref2, ref);
  const Difference d = compare(run, ref);
  // each particle's contact count as one process counts it: the contacts a
  // rank computed with ghosts are counted at their owners too
  run.sd().collect_contact_counts();
  {
    const dp::ParticleStore& s = run.sd().store();
    const dp::ParticleStore& r = ref.sd().store();
    std::unordered_map<std::uint64_t, std::uint32_t> contacts;
    for (std::size_t k = 0; k < r.size(); ++k) contacts.emplace(r.id[k], r.contacts[k]);
    std::size_t differ = 0, in_contact = 0;
    for (std::size_t k = 0; k < run.sd().owned(); ++k) {
      differ += s.contacts[k] != contacts.at(s.id[k]) ? 1 : 0;
      in_contact += s.contacts[k] > 0 ? 1 : 0;
    }
    EXPECT_EQ(differ, 0u) << "rank " << comm.rank() << ": particles whose contact count differs from one process";
    std::vector<std::uint64_t> n{in_contact};
    comm.sum(n);
    EXPECT_GT(n[0], 100u);  // the check has something to check
  }
  // each particle once over the ranks
  std::vector<std::uint64_t> n{d.compared};
  comm.sum(n);
  EXPECT_EQ(n[0], ref.sd().store().size());
  // the band: round-off's own spread, times kChaos
  const double bx = kChaos * roundoff.x, bv = kChaos * roundoff.v, bw = kChaos * roundoff.w;
  EXPECT_LT(d.x, bx) << "rank " << comm.rank() << ": positions differ by " << d.x << " m (round-off: " << roundoff.x
                     << " m)";
  EXPECT_LT(d.v, bv) << "rank " << comm.rank() << ": velocities differ by " << d.v << " m/s (round-off: "
                     << roundoff.v << " m/s)";
  EXPECT_LT(d.w, bw) << "rank " << comm.rank() << ": angular velocities differ by " << d.w << " rad/s (round-off: "
                     << roundoff.w << " rad/s)";
  // the check has something to check: particles and contact histories crossed ranks
  const dp::RankTraffic& t = run.ranks->traffic();
  std::vector<std::uint64_t> moved{t.migrated, t.histories_sent, t.ghosts, ref.sd().neighbor_builds()};
  comm.sum(moved);
  if (comm.rank() == 0)
    std::printf("[ ranks %d x %d threads ] %llu particles and %llu contact histories migrated, %llu ghosts at %llu builds; "
                "largest difference %.3g m, %.3g m/s (round-off alone: %.3g m, %.3g m/s)\n",
                comm.size(), threads, static_cast<unsigned long long>(moved[0]), static_cast<unsigned long long>(moved[1]),
                static_cast<unsigned long long>(moved[2]),
                static_cast<unsigned long long>(moved[3] / static_cast<std::uint64_t>(comm.size())), d.x, d.v,
                roundoff.x, roundoff.v);
  if (comm.size() > 1) {
    EXPECT_GT(moved[0], 0u);
    EXPECT_GT(moved[1], 0u);
  }
  if (comm.size() > 1 || run.sd().periodic().any()) EXPECT_GT(moved[2], 0u);  // ghosts (on one rank: periodic images)
}

}  // namespace

TEST(MpiSubdomain, AFrictionalGasInAPeriodicBoxMovesAsOnOneProcess) { spread_runs_as_one_process(gas(), true, 1500); }

TEST(MpiSubdomain, AColumnSettlingBetweenWallsMovesAsOnOneProcess) {
  spread_runs_as_one_process(column(), false, 1500);
}

TEST(MpiSubdomain, WithTwoThreadsPerRankTheGasMovesAsOnOneProcess) {
  spread_runs_as_one_process(gas(), true, 1500, 2);
}

namespace {

/// Two equal spheres (d = 2.8 mm, Hertz, e = 0.5, the S1 material) approach
/// along x at -+v/2 and collide head-on: the rebound ratio |v2 - v1| / v,
/// on this process alone or spread over the ranks of `comm` (every rank
/// the same answer). dt is the one-process run's contact time / 200, as in
/// tests/physics/restitution_test.cpp.
double head_on_restitution(const dp::Communicator* comm, double& dt_used, std::size_t* owned = nullptr) {
  constexpr double d = 0.0028, v = 1.0;
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-7, 0.5, 0.5);
  auto sim = dt::build(doc);
  dp::Subdomain& sd = *sim->subdomains[0];
  dp::ParticleStore& s = sd.store();
  s.add(1, -0.5 * d * 1.001, 0, 0, 0.5 * d, 2500);
  s.add(2, 0.5 * d * 1.001, 0, 0, 0.5 * d, 2500);
  s.vx[0] = 0.5 * v;
  s.vx[1] = -0.5 * v;
  if (dt_used <= 0) dt_used = sd.estimate_time_step(v).contact_time / 200;
  sd.set_time_step(dt_used);
  sd.set_skin(0.1 * d);
  if (comm) {
    std::vector<std::uint8_t> other(s.size());
    for (std::size_t k = 0; k < s.size(); ++k)
      other[k] = !dp::starts_on_rank(s.id[k], comm->rank(), comm->size());
    s.remove_marked(other);
    dp::distribute(sd, *comm);
  }
  sd.setup();
  if (owned) *owned = sd.owned();
  bool touched = false;
  for (int k = 0; k < 100000; ++k) {
    sd.step();
    std::vector<std::uint64_t> contacts{sd.stats().contacts};
    if (comm) comm->sum(contacts);
    if (contacts[0] > 0) touched = true;
    if (touched && contacts[0] == 0) break;
  }
  EXPECT_TRUE(touched);
  double vx[2] = {-1e300, -1e300};  // by id, from its owner
  const dp::ParticleStore& after = sd.store();
  for (std::size_t k = 0; k < sd.owned(); ++k) vx[after.id[k] - 1] = after.vx[k];
  if (comm)
    for (double& x : vx) x = comm->max(x);
  return std::fabs(vx[1] - vx[0]) / v;
}

}  // namespace

TEST(MpiSubdomain, AHeadOnCollisionAcrossARankBorderReboundsWithTheRestitution) {
  // The pair is computed by the owner of id 1 with id 2 as its ghost, and
  // id 2's force goes home in the reverse exchange. The ratio must be the
  // one-process run's to round-off (1e-12 relative: a handful of sums in
  // another order) and the scenario's e = 0.5 within 1 % (the one-process
  // test's tolerance, docs/physics.md §9).
  const dp::Communicator comm = dp::Communicator::world();
  double dt_used = 0;
  const double one = head_on_restitution(nullptr, dt_used);
  std::size_t owned = 0;
  const double spread = head_on_restitution(&comm, dt_used, &owned);
  if (comm.size() == 2) EXPECT_EQ(owned, 1u) << "the bisection puts one sphere on each rank";
  EXPECT_NEAR(spread, one, 1e-12 * one);
  EXPECT_NEAR(spread, 0.5, 0.005);
  if (comm.rank() == 0) std::printf("restitution on %d rank(s): %.15g (one process %.15g)\n", comm.size(), spread, one);
}

namespace {

/// The value the owners of particle `id` hold in the test's field after
/// `step` steps: distinct per particle and per step.
double tag_value(std::uint64_t id, std::uint64_t step) {
  return 1.0 + 0.5 * static_cast<double>(id) + 1000.0 * static_cast<double>(step);
}

/// The gas of gas(), stirred, with one field added by a test in one place
/// (ParticleStore::add_field: carried, and refreshed in the ghosts every
/// step), spread over the ranks of `comm`. The field is set from the id.
Run gas_with_a_tag(const dp::Communicator& comm, std::size_t& tag) {
  Run r{dt::build(gas())};
  dp::Subdomain& sd = r.sd();
  dp::ParticleStore& s = sd.store();
  tag = s.add_field("test_tag", dp::ParticleStore::kCarried | dp::ParticleStore::kGhostUpdate);
  stir(s);
  for (std::size_t k = 0; k < s.size(); ++k) s.aux[tag][k] = tag_value(s.id[k], 0);
  sd.set_skin(0.3 * kD);
  std::vector<std::uint8_t> other(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) other[k] = !dp::starts_on_rank(s.id[k], comm.rank(), comm.size());
  s.remove_marked(other);
  r.ranks = &dp::distribute(sd, comm);
  return r;
}

/// Particles of this rank whose field is not tag_value(id, step): owned and
/// ghosts (a ghost holds its owner's value).
std::pair<std::size_t, std::size_t> wrong_tags(dp::Subdomain& sd, std::size_t tag, std::uint64_t step) {
  const dp::ParticleStore& s = sd.store();
  std::size_t owned = 0, ghosts = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.aux[tag][k] != tag_value(s.id[k], step)) ++(k < sd.owned() ? owned : ghosts);
  return {owned, ghosts};
}

}  // namespace

// Issue 40: a per-particle field is declared once, with its sync policy, and
// the ranks carry it as they carry the built-in fields. 400 steps of the
// gas (under a second on 3 ranks): particles migrate at the builds, the ghosts
// are rebuilt and refreshed between builds, and a checkpoint taken half way
// restores the field on every rank, owners and ghosts, after which the run
// goes on exactly as the uninterrupted one.
TEST(MpiSubdomain, AFieldAddedInOnePlaceMigratesReachesTheGhostsAndSurvivesARestart) {
  const dp::Communicator comm = dp::Communicator::world();
  std::size_t tag = 0;
  auto run = gas_with_a_tag(comm, tag);
  dp::Subdomain& sd = run.sd();
  sd.setup();
  constexpr std::uint64_t kSteps = 200;
  std::string saved;
  for (std::uint64_t step = 1; step <= 2 * kSteps; ++step) {
    // the owners change their value before the step; after it, owners and
    // ghosts hold the new one (a ghost built at a list build, or refreshed)
    dp::ParticleStore& s = sd.store();
    for (std::size_t k = 0; k < sd.owned(); ++k) s.aux[tag][k] = tag_value(s.id[k], step);
    sd.step();
    const auto [owned, ghosts] = wrong_tags(sd, tag, step);
    ASSERT_EQ(owned, 0u) << "rank " << comm.rank() << ", step " << step << ": owned particles lost their field";
    ASSERT_EQ(ghosts, 0u) << "rank " << comm.rank() << ", step " << step << ": ghosts do not hold their owners' field";
    if (step == kSteps) {
      dp::ArchiveWriter w;
      sd.save(w, "");
      saved = w.serialize("{}");
    }
  }
  // the check has something to check: particles migrated, ghosts were built
  const dp::RankTraffic& t = run.ranks->traffic();
  std::vector<std::uint64_t> moved{t.migrated, t.ghosts, t.updates};
  comm.sum(moved);
  if (comm.size() > 1) EXPECT_GT(moved[0], 0u);  // on one rank nothing migrates
  EXPECT_GT(moved[1], 0u);  // on one rank too: the periodic images
  EXPECT_GT(moved[2], 0u);

  // the restart: a fresh subdomain with the same field, restored from the
  // checkpoint of step kSteps, holds the field as the run did then, and the
  // second half gives the same particles and fields bit for bit
  std::size_t tag2 = 0;
  auto again = gas_with_a_tag(comm, tag2);
  dp::Subdomain& sd2 = again.sd();
  ASSERT_TRUE(sd2.restore(dp::ArchiveReader(saved, "checkpoint part"), ""));
  {
    const auto [owned, ghosts] = wrong_tags(sd2, tag2, kSteps);
    EXPECT_EQ(owned, 0u) << "rank " << comm.rank() << ": the restored owners lost their field";
    EXPECT_EQ(ghosts, 0u) << "rank " << comm.rank() << ": the restored ghosts lost their owners' field";
  }
  for (std::uint64_t step = kSteps + 1; step <= 2 * kSteps; ++step) {
    dp::ParticleStore& s = sd2.store();
    for (std::size_t k = 0; k < sd2.owned(); ++k) s.aux[tag2][k] = tag_value(s.id[k], step);
    sd2.step();
  }
  const dp::ParticleStore& a = sd.store();
  const dp::ParticleStore& b = sd2.store();
  ASSERT_EQ(sd.owned(), sd2.owned());
  std::size_t differ = 0;
  for (std::size_t k = 0; k < sd.owned(); ++k)
    differ += a.id[k] != b.id[k] || a.x[k] != b.x[k] || a.vx[k] != b.vx[k] || a.aux[tag][k] != b.aux[tag2][k];
  EXPECT_EQ(differ, 0u) << "rank " << comm.rank() << ": the restarted run differs from the uninterrupted one";
}

// Issue 40: particles_to_edit() drops the ghosts once; a second edit in the
// same macro step (a coupling's inflow, then a deletion region) keeps what
// the first one added. The gas after one step (ghosts on every rank, the
// periodic images on one rank too): a particle added on rank 0 survives two
// further edits, and after its removal the run steps on with every other
// particle. Well under a second on 1-4 ranks.
TEST(MpiSubdomain, ASecondEditBetweenStepsKeepsWhatTheFirstAdded) {
  const dp::Communicator comm = dp::Communicator::world();
  auto run = prepared(gas(), true, &comm);
  dp::Subdomain& sd = run.sd();
  sd.step();
  ASSERT_GT(sd.size(), sd.owned()) << "rank " << comm.rank() << ": the check needs ghosts";
  std::vector<std::uint64_t> before{sd.owned()};
  comm.sum(before);
  constexpr std::uint64_t kNewId = 1u << 30;
  {
    dp::ParticleStore& s = sd.particles_to_edit();
    if (comm.rank() == 0) {
      dp::ParticleStore one = s.empty_like();
      one.append(s, std::vector<std::uint32_t>{0});
      one.id[0] = kNewId;
      s.append(one);
    }
  }
  auto holds_new = [&] {
    const dp::ParticleStore& s = sd.particles_to_edit();
    return std::count(s.id.begin(), s.id.end(), kNewId);
  };
  EXPECT_EQ(holds_new(), comm.rank() == 0 ? 1 : 0) << "rank " << comm.rank() << ": the second edit lost the particle";
  EXPECT_EQ(holds_new(), comm.rank() == 0 ? 1 : 0) << "rank " << comm.rank() << ": the third edit lost the particle";
  {
    dp::ParticleStore& s = sd.particles_to_edit();
    std::vector<std::uint8_t> drop(s.size(), 0);
    for (std::size_t k = 0; k < s.size(); ++k) drop[k] = s.id[k] == kNewId;
    s.remove_marked(drop);
  }
  sd.step();
  std::vector<std::uint64_t> after{sd.owned()};
  comm.sum(after);
  EXPECT_EQ(after[0], before[0]);
  EXPECT_GT(sd.size(), sd.owned()) << "rank " << comm.rank() << ": the step rebuilt no ghosts";
}
