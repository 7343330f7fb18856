// SPDX-License-Identifier: MIT
// The multigrid pressure solve of the built-in fluid coupler: hypre's
// structured-grid conjugate gradient preconditioned by one V-cycle of PFMG
// (Ashby & Falgout 1996; hypre's Struct interface), on the 7-point system of
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
  /// The warm start of the next solve (the last correction on the whole
  /// grid, empty before the first solve), for checkpoints.
  std::vector<double> warm_start() const;
  void set_warm_start(const std::vector<double>& x);

 private:
  struct State;
  std::unique_ptr<State> s_;
  double tol_;
  int max_;
};

}  // namespace domel::plugins::fluid
