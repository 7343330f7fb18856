// SPDX-License-Identifier: MIT
// The multigrid pressure solve of the built-in fluid coupler: hypre's
// structured-grid conjugate gradient preconditioned by one V-cycle of PFMG
// (Ashby & Falgout 1996; hypre's Struct interface), the V-cycle's levels kept
// from step to step while the iterations stay near those of a fresh set-up,
// on the 7-point system of
// vans_solver.hpp laid out on the whole cell grid (a blocked cell is an
// identity row). Its cost per cell stays about constant as the grid grows,
// where the incomplete-Cholesky conjugate gradient's grows with the grid's
// width (docs/performance.md, "Fluid step"). Built when CMake finds Debian's
// libhypre-dev (DOMEL_HAVE_HYPRE); hypre needs MPI initialised, which the
// first solver does (MPI_COMM_SELF, one process) and finalises at unload.
#pragma once

#include "plugins/fluid/vans_solver.hpp"

#include <memory>
#include <vector>

namespace domel::plugins::fluid {

class PressurePfmg {
 public:
  PressurePfmg(double tolerance, int max_iterations);
  ~PressurePfmg();
  SolveReport operator()(const PressureSystem& sys, std::vector<double>& x);
  /// What the next solve starts from, for checkpoints: the warm start (the
  /// last correction on the whole grid, empty before the first solve), the
  /// matrix the kept preconditioner was set up from (empty: none kept) and
  /// the iteration counts its renewal is decided by.
  struct Saved {
    std::vector<double> sol, setup_values;
    int setup_iterations = 0, last_iterations = 0;
  };
  Saved saved() const;
  /// Before the first solve: the next solves go on as the saved solver's would.
  void restore(const Saved& saved);

 private:
  struct State;
  std::unique_ptr<State> s_;
  double tol_;
  int max_;
};

}  // namespace domel::plugins::fluid
