// SPDX-License-Identifier: MIT
// The hypre back end of the fluid coupler's pressure solve keeps its PFMG
// preconditioner from solve to solve and builds it anew only when the
// iterations rise (plugins/fluid/pressure_pfmg.cpp). A checkpoint carries
// the matrix it was built from, so a solver restored from the state saved
// after any solve goes on with the same preconditioner decisions and the
// same corrections, to the bit, as the one that never stopped: after a
// renewal, before one, and when the first solve after the restore has
// nothing to solve. Built where hypre is (DOMEL_TEST_PFMG); cost well under
// a second.
#include "plugins/fluid/vans_solver.hpp"

#ifdef DOMEL_TEST_PFMG
#include "plugins/fluid/pressure_pfmg.hpp"
#endif

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace fl = domel::plugins::fluid;

namespace {

constexpr int kN = 10;

/// A 7-point SPD system on kN^3 cells whose face coefficients change from
/// step to step (as eps and the drag's K change a coupler's), strongly in
/// one region from step 12 on (a bed forming), so that a kept
/// preconditioner goes stale; step 20's right-hand side is zero.
fl::PressureSystem system_at(int step, std::uint64_t pattern_id) {
  fl::PressureSystem sys;
  sys.n = {kN, kN, kN};
  sys.pattern_id = pattern_id;
  const std::size_t cells = static_cast<std::size_t>(kN) * kN * kN;
  sys.cell_of.resize(cells);
  sys.diag.assign(cells, 0.0);
  sys.off.assign(cells, {});
  sys.rhs.assign(cells, 0.0);
  auto cell = [](int i, int j, int k) { return static_cast<std::size_t>(i + kN * (j + kN * k)); };
  auto coef = [&](std::size_t a, std::size_t b) {
    const double x = 0.37 * static_cast<double>(a + b) + 0.11 * step;
    const bool bed = step >= 12 && std::min(a, b) < cells / 3;
    return (1.0 + 0.3 * std::sin(x)) * (bed ? 1.0 + 0.8 * (step - 11) : 1.0);
  };
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const std::size_t c = cell(i, j, k);
        sys.cell_of[c] = c;
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        double d = 0;
        for (const auto& q : nb) {
          if (q[0] < 0 || q[0] >= kN || q[1] < 0 || q[1] >= kN || q[2] < 0 || q[2] >= kN) continue;
          const std::size_t o = cell(q[0], q[1], q[2]);
          const double w = coef(std::min(c, o), std::max(c, o));
          sys.off[c].push_back({o, -w});
          d += w;
        }
        if (k == kN - 1) d += 2.0;  // an outlet above: p' = 0 half a cell out
        sys.diag[c] = d;
        sys.rhs[c] = step == 20 ? 0.0 : std::sin(0.7 * static_cast<double>(c) + step) * std::exp(-0.05 * step);
      }
  sys.reference_norm = 1.0;
  return sys;
}

}  // namespace

TEST(PressurePfmg, ARestoredSolverGoesOnAsTheOneThatNeverStoppedToTheBit) {
#ifndef DOMEL_TEST_PFMG
  GTEST_SKIP() << "built without hypre";
#else
  constexpr int kSteps = 30;
  const std::uint64_t id = fl::new_pattern_id();
  fl::PressurePfmg whole(1e-8, 2000);
  std::vector<std::vector<double>> x(kSteps);
  std::vector<fl::PressurePfmg::Saved> saved(kSteps);
  int renewals = 0;
  for (int s = 0; s < kSteps; ++s) {
    const fl::PressureSystem sys = system_at(s, id);
    whole(sys, x[s]);
    saved[s] = whole.saved();
    if (s > 0 && saved[s].setup_values != saved[s - 1].setup_values) ++renewals;
  }
  std::printf("[pfmg] %d renewals of the preconditioner after the first set-up in %d solves\n", renewals, kSteps);
  EXPECT_GE(renewals, 2);  // the bed makes the kept one stale more than once
  for (int from = 0; from + 1 < kSteps; ++from) {
    fl::PressurePfmg restored(1e-8, 2000);
    restored.restore(saved[from]);
    for (int s = from + 1; s < kSteps; ++s) {
      std::vector<double> y;
      restored(system_at(s, id), y);
      ASSERT_EQ(y.size(), x[s].size());
      ASSERT_EQ(0, std::memcmp(y.data(), x[s].data(), y.size() * sizeof(double)))
          << "restored after solve " << from << ", solve " << s << " differs";
      // its own saved state is the uninterrupted solver's (a checkpoint of the restart)
      const fl::PressurePfmg::Saved again = restored.saved();
      ASSERT_EQ(again.setup_values, saved[s].setup_values) << "after solve " << s << ", restored after " << from;
      ASSERT_EQ(again.setup_iterations, saved[s].setup_iterations);
      ASSERT_EQ(again.last_iterations, saved[s].last_iterations);
    }
  }
#endif
}
