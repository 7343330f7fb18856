// SPDX-License-Identifier: MIT
// PressurePfmg: the system of one fluid step handed to hypre's Struct PCG
// with a PFMG preconditioner (call sequence from the hypre reference
// manual, "Struct System Interface" and "Struct Solvers"). The grid and the
// stencil are made once; the matrix, which changes with eps and K at every
// step, is set up anew each solve, warm-started from the last correction.
#include "plugins/fluid/pressure_pfmg.hpp"

#include <HYPRE_struct_ls.h>
#include <HYPRE_utilities.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace domel::plugins::fluid {

namespace {

/// MPI (one process, MPI_COMM_SELF) and hypre, initialised once per process
/// when a solver is first made, finalised when the library is unloaded or
/// the process ends; MPI is left alone if the host initialised it.
struct Runtime {
  bool owns_mpi = false;
  Runtime() {
    int ready = 0;
    MPI_Initialized(&ready);
    if (!ready) {
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
      owns_mpi = true;
    }
    HYPRE_Init();
  }
  ~Runtime() {
    HYPRE_Finalize();
    int done = 0;
    MPI_Finalized(&done);
    if (owns_mpi && !done) MPI_Finalize();
  }
};

Runtime& runtime() {
  static Runtime r;
  return r;
}

}  // namespace

struct PressurePfmg::State {
  std::array<int, 3> n{0, 0, 0};
  HYPRE_StructGrid grid = nullptr;
  HYPRE_StructStencil stencil = nullptr;
  std::vector<double> values, rhs, sol;
  std::vector<char> fluid;                  ///< per cell: an unknown of the system
  std::vector<std::size_t> pattern;         ///< the off-diagonals' columns, row after row, as last seen
  std::vector<std::size_t> cell_of;         ///< the unknowns' cells, as last seen
  std::vector<std::uint8_t> entry;          ///< each one's stencil entry (1-6)
  bool restored = false;  ///< sol came from a checkpoint: the first solve keeps it
  ~State() {
    if (stencil) HYPRE_StructStencilDestroy(stencil);
    if (grid) HYPRE_StructGridDestroy(grid);
  }
};

PressurePfmg::PressurePfmg(double tolerance, int max_iterations)
    : s_(std::make_unique<State>()), tol_(tolerance), max_(max_iterations) {
  runtime();
}

PressurePfmg::~PressurePfmg() = default;

std::vector<double> PressurePfmg::warm_start() const { return s_->sol; }

void PressurePfmg::set_warm_start(const std::vector<double>& x) {
  s_->sol = x;
  s_->restored = s_->grid == nullptr;
}

SolveReport PressurePfmg::operator()(const PressureSystem& sys, std::vector<double>& x) {
  State& s = *s_;
  const std::size_t cells = static_cast<std::size_t>(sys.n[0]) * sys.n[1] * sys.n[2];
  int lower[3] = {0, 0, 0}, upper[3] = {sys.n[0] - 1, sys.n[1] - 1, sys.n[2] - 1};
  if (s.grid == nullptr || s.n != sys.n) {
    if (s.stencil) HYPRE_StructStencilDestroy(s.stencil);
    if (s.grid) HYPRE_StructGridDestroy(s.grid);
    HYPRE_StructGridCreate(MPI_COMM_SELF, 3, &s.grid);
    HYPRE_StructGridSetExtents(s.grid, lower, upper);
    HYPRE_StructGridAssemble(s.grid);
    int offsets[7][3] = {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
    HYPRE_StructStencilCreate(3, 7, &s.stencil);
    for (int e = 0; e < 7; ++e) HYPRE_StructStencilSetElement(s.stencil, e, offsets[e]);
    s.n = sys.n;
    s.pattern.clear();  // the stencil entries belong to the old grid
    s.fluid.clear();
    if (!s.restored || s.sol.size() != cells) s.sol.assign(cells, 0.0);
    s.restored = false;
  }
  // the stencil entry of each off-diagonal, found again only when the
  // system's pattern changes (the coupler's stays the same from step to step)
  bool same = true;
  {
    std::size_t q = 0;
    for (std::size_t r = 0; r < sys.diag.size() && same; ++r)
      for (const auto& [col, v] : sys.off[r]) {
        if (q >= s.pattern.size() || s.pattern[q] != col) {
          same = false;
          break;
        }
        ++q;
      }
    same = same && q == s.pattern.size() && s.fluid.size() == cells && s.cell_of == sys.cell_of;
  }
  const auto nx = static_cast<std::size_t>(sys.n[0]), nxy = nx * static_cast<std::size_t>(sys.n[1]);
  if (!same) {
    s.pattern.clear();
    s.entry.clear();
    s.cell_of = sys.cell_of;
    s.fluid.assign(cells, 0);
    for (std::size_t r = 0; r < sys.diag.size(); ++r) {
      const std::size_t c = sys.cell_of[r];
      s.fluid[c] = 1;
      const long ci = static_cast<long>(c % nx), cj = static_cast<long>((c / nx) % sys.n[1]),
                 ck = static_cast<long>(c / nxy);
      for (const auto& [col, v] : sys.off[r]) {
        const std::size_t d = sys.cell_of[col];
        const long di = static_cast<long>(d % nx) - ci, dj = static_cast<long>((d / nx) % sys.n[1]) - cj,
                   dk = static_cast<long>(d / nxy) - ck;
        int e = 0;
        if (di == -1 && dj == 0 && dk == 0) e = 1;
        else if (di == 1 && dj == 0 && dk == 0) e = 2;
        else if (di == 0 && dj == -1 && dk == 0) e = 3;
        else if (di == 0 && dj == 1 && dk == 0) e = 4;
        else if (di == 0 && dj == 0 && dk == -1) e = 5;
        else if (di == 0 && dj == 0 && dk == 1) e = 6;
        else throw std::logic_error("pressure system: a coupling that is not a grid neighbour");
        s.pattern.push_back(col);
        s.entry.push_back(static_cast<std::uint8_t>(e));
      }
    }
  }
  // the 7-point rows on the whole grid: identity rows for blocked cells
  s.values.assign(7 * cells, 0.0);
  s.rhs.assign(cells, 0.0);
  for (std::size_t c = 0; c < cells; ++c) s.values[7 * c] = 1.0;
  const std::vector<char>& fluid = s.fluid;
  for (std::size_t r = 0, q = 0; r < sys.diag.size(); ++r) {
    const std::size_t c = sys.cell_of[r];
    s.values[7 * c] = sys.diag[r];
    s.rhs[c] = sys.rhs[r];
    for (const auto& [col, v] : sys.off[r]) s.values[7 * c + s.entry[q++]] = v;
  }
  const double bn = sys.rhs_norm();
  x.assign(sys.diag.size(), 0.0);
  SolveReport rep;
  if (sys.trivial(tol_, bn)) return rep;  // nothing to correct
  HYPRE_StructMatrix A;
  HYPRE_StructVector b, xv;
  HYPRE_StructMatrixCreate(MPI_COMM_SELF, s.grid, s.stencil, &A);
  HYPRE_StructMatrixInitialize(A);
  int entries[7] = {0, 1, 2, 3, 4, 5, 6};
  HYPRE_StructMatrixSetBoxValues(A, lower, upper, 7, entries, s.values.data());
  HYPRE_StructMatrixAssemble(A);
  HYPRE_StructVectorCreate(MPI_COMM_SELF, s.grid, &b);
  HYPRE_StructVectorInitialize(b);
  HYPRE_StructVectorSetBoxValues(b, lower, upper, s.rhs.data());
  HYPRE_StructVectorAssemble(b);
  HYPRE_StructVectorCreate(MPI_COMM_SELF, s.grid, &xv);
  HYPRE_StructVectorInitialize(xv);
  for (std::size_t c = 0; c < cells; ++c)
    if (!fluid[c]) s.sol[c] = 0.0;
  HYPRE_StructVectorSetBoxValues(xv, lower, upper, s.sol.data());
  HYPRE_StructVectorAssemble(xv);
  HYPRE_StructSolver pcg, pfmg;
  HYPRE_StructPCGCreate(MPI_COMM_SELF, &pcg);
  HYPRE_StructPCGSetTol(pcg, sys.relative_tolerance(tol_, bn));
  HYPRE_StructPCGSetMaxIter(pcg, max_);
  HYPRE_StructPCGSetTwoNorm(pcg, 1);
  HYPRE_StructPFMGCreate(MPI_COMM_SELF, &pfmg);
  HYPRE_StructPFMGSetMaxIter(pfmg, 1);
  HYPRE_StructPFMGSetTol(pfmg, 0.0);
  HYPRE_StructPFMGSetZeroGuess(pfmg);
  HYPRE_StructPFMGSetRelaxType(pfmg, 1);  // weighted Jacobi: symmetric, as PCG needs
  HYPRE_StructPFMGSetNumPreRelax(pfmg, 1);
  HYPRE_StructPFMGSetNumPostRelax(pfmg, 1);
  HYPRE_StructPCGSetPrecond(pcg, HYPRE_StructPFMGSolve, HYPRE_StructPFMGSetup, pfmg);
  HYPRE_StructPCGSetup(pcg, A, b, xv);
  HYPRE_StructPCGSolve(pcg, A, b, xv);
  HYPRE_Int it = 0;
  double res = 0;
  HYPRE_StructPCGGetNumIterations(pcg, &it);
  HYPRE_StructPCGGetFinalRelativeResidualNorm(pcg, &res);
  HYPRE_StructVectorGetBoxValues(xv, lower, upper, s.sol.data());
  HYPRE_StructPFMGDestroy(pfmg);
  HYPRE_StructPCGDestroy(pcg);
  HYPRE_StructVectorDestroy(xv);
  HYPRE_StructVectorDestroy(b);
  HYPRE_StructMatrixDestroy(A);
  for (std::size_t r = 0; r < sys.diag.size(); ++r) x[r] = s.sol[sys.cell_of[r]];
  rep.iterations = static_cast<int>(it);
  rep.residual = res;
  return rep;
}

}  // namespace domel::plugins::fluid
