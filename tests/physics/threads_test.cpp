// Guards the thread-parallel force loop (run --threads N): for a fixed
// thread count a run is bit-identical run to run (static partition of the
// pair list, per-thread force arrays summed in thread order), and 1, 2 and 3
// threads agree to round-off on a short settle: they differ only in the
// order of floating-point sums, so positions agree to ~1e-12 d after 1500
// steps (15 ms; measured: 0 for 2 threads, 5e-15 d for 3; the bound allows for the growth of round-off in
// a many-body collision sequence). Deferred steps (the run loop's) equal complete ones bit for bit.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace dt = domel::test;
using nlohmann::json;

namespace {

json column() { return dt::lattice_column(0.0028); }

std::unique_ptr<domel::platform::Simulation> settle(int threads, int steps, bool deferred = false) {
  auto sim = dt::build(column());
  auto& sd = *sim->subdomains[0];
  sd.set_threads(threads);
  sd.set_skin(0.5 * 0.0028);
  sd.setup();
  for (int k = 0; k < steps; ++k) {
    if (deferred) sd.step_deferred();
    else sd.step();
  }
  return sim;
}

}  // namespace

TEST(Threads, BitIdenticalRunToRunForAFixedThreadCount) {
  for (int threads : {1, 2}) {
    auto a = settle(threads, 1500), b = settle(threads, 1500);
    const auto& p = a->subdomains[0]->store();
    const auto& q = b->subdomains[0]->store();
    ASSERT_EQ(p.size(), 2000u);
    for (std::size_t k = 0; k < p.size(); ++k) {
      ASSERT_EQ(p.x[k], q.x[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.z[k], q.z[k]);
      ASSERT_EQ(p.wx[k], q.wx[k]);
    }
  }
}

TEST(Threads, OneTwoAndThreeThreadsAgreeToRoundOff) {
  auto one = settle(1, 1500);
  const auto& p = one->subdomains[0]->store();
  EXPECT_GT(one->subdomains[0]->stats().contacts, 100u);  // the column is in contact: forces matter
  for (int threads : {2, 3}) {
    auto many = settle(threads, 1500);
    const auto& q = many->subdomains[0]->store();
    double worst = 0;
    for (std::size_t k = 0; k < p.size(); ++k)
      worst = std::max({worst, std::fabs(p.x[k] - q.x[k]), std::fabs(p.y[k] - q.y[k]), std::fabs(p.z[k] - q.z[k])});
    std::printf("%d threads: largest position difference to 1 thread = %.3g d\n", threads, worst / 0.0028);
    EXPECT_LT(worst, 1e-12 * 0.0028 * 1e3);
    EXPECT_EQ(one->subdomains[0]->stats().contacts, many->subdomains[0]->stats().contacts);
  }
}

TEST(Threads, DeferredStepsEqualCompleteSteps) {
  // step_deferred() leaves the second half kick (and with threads the force
  // sums and wall contacts) to the next step's first sweep; the arithmetic
  // is the same, so after store() the state must equal that of step()
  // exactly, for any thread count.
  for (int threads : {1, 2, 3}) {
    auto a = settle(threads, 700), b = settle(threads, 700, true);
    const auto& p = a->subdomains[0]->store();
    const auto& q = b->subdomains[0]->store();  // finishes the pending step
    ASSERT_EQ(p.size(), q.size());
    for (std::size_t k = 0; k < p.size(); ++k) {
      ASSERT_EQ(p.x[k], q.x[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.vz[k], q.vz[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.wy[k], q.wy[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.fz[k], q.fz[k]) << threads << " threads, particle " << k;
      ASSERT_EQ(p.tx[k], q.tx[k]) << threads << " threads, particle " << k;
    }
    const auto sa = a->subdomains[0]->stats(), sb = b->subdomains[0]->stats();
    EXPECT_GT(sa.wall_contacts, 0u);  // the walls' deferred part is exercised
    EXPECT_EQ(sa.wall_contacts, sb.wall_contacts);
    EXPECT_EQ(sa.contacts, sb.contacts);
    EXPECT_EQ(sa.max_overlap_ratio, sb.max_overlap_ratio);
  }
}

TEST(Threads, PerParticleContactsCountTheTouchingPairsAndWalls) {
  // store().contacts (the VTK coordination number) is counted from the
  // lists' contact flags when the store is read, not in the step loop. It
  // must equal a brute-force count over all pairs (centre distance below
  // r_i + r_j, the screen's own test) and the box's five planes (gap below
  // r), after deferred steps (whose wall contacts are finished by store()).
  const double a = 1.02 * 0.0028;
  for (int threads : {1, 2}) {
    auto sim = settle(threads, 700, true);
    const auto& sd = *sim->subdomains[0];
    const auto& s = sd.store();
    std::vector<std::uint32_t> want(s.size(), 0);
    std::size_t pairs = 0, walls = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      for (std::size_t j = i + 1; j < s.size(); ++j) {
        const double dx = s.x[i] - s.x[j], dy = s.y[i] - s.y[j], dz = s.z[i] - s.z[j];
        const double rsum = s.radius[i] + s.radius[j];
        if (dx * dx + dy * dy + dz * dz < rsum * rsum) {
          ++want[i];
          ++want[j];
          ++pairs;
        }
      }
      for (double gap : {s.x[i], 10 * a - s.x[i], s.y[i], 10 * a - s.y[i], s.z[i]})
        if (gap < s.radius[i]) {
          ++want[i];
          ++walls;
        }
    }
    const auto st = sd.stats();
    EXPECT_EQ(st.contacts, pairs) << threads << " threads";
    EXPECT_EQ(st.wall_contacts, walls) << threads << " threads";
    std::printf("%d threads: %zu pair and %zu wall contacts\n", threads, pairs, walls);
    EXPECT_GT(pairs, 100u);  // the bottom of the column is in contact
    EXPECT_GT(walls, 0u);
    ASSERT_EQ(s.contacts.size(), s.size());
    for (std::size_t k = 0; k < s.size(); ++k) ASSERT_EQ(s.contacts[k], want[k]) << threads << " threads, particle " << k;
  }
}
