// SPDX-License-Identifier: MIT
// PressurePfmg: the system of one fluid step handed to hypre's Struct PCG
// with a PFMG preconditioner (call sequence from the hypre reference
// manual, "Struct System Interface" and "Struct Solvers"). The grid, the
// stencil, the matrix and the vectors are made once per grid; each solve
// writes the step's values into them and is warm-started from the last
// correction. The preconditioner (PFMG's coarse operators, built from the
// matrix by PCG's set-up) is kept while it serves: the conjugate gradient
// always iterates on the current matrix, so an older preconditioner changes
// how many iterations the tolerance takes, never the tolerance reached.
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
  HYPRE_StructMatrix A = nullptr;
  HYPRE_StructVector b = nullptr, x = nullptr;
  HYPRE_StructSolver pcg = nullptr, pfmg = nullptr;  ///< the kept preconditioner (null: none)
  std::vector<double> values, rhs, sol;
  std::vector<double> setup_values;         ///< the matrix the preconditioner was built from
  int setup_iterations = 0;                 ///< the first solve's iterations after that set-up
  int last_iterations = 0;                  ///< the last solve's
  std::vector<char> fluid;                  ///< per cell: an unknown of the system
  std::uint64_t pattern_id = 0;             ///< the system's pattern id, as last seen (0: none)
  std::vector<std::uint8_t> entry;          ///< each one's stencil entry (1-6)
  bool restored = false;  ///< sol (and the set-up's matrix) came from a checkpoint: the first solve keeps them

  void drop_preconditioner() {
    if (pfmg) HYPRE_StructPFMGDestroy(pfmg);
    if (pcg) HYPRE_StructPCGDestroy(pcg);
    pfmg = pcg = nullptr;
  }
  void drop_grid() {
    drop_preconditioner();
    if (x) HYPRE_StructVectorDestroy(x);
    if (b) HYPRE_StructVectorDestroy(b);
    if (A) HYPRE_StructMatrixDestroy(A);
    if (stencil) HYPRE_StructStencilDestroy(stencil);
    if (grid) HYPRE_StructGridDestroy(grid);
    x = b = nullptr;
    A = nullptr;
    stencil = nullptr;
    grid = nullptr;
  }
  ~State() { drop_grid(); }
};

namespace {

/// A preconditioner built from an older matrix is rebuilt once a solve takes
/// more than this many iterations beyond the first solve after its set-up
/// (the set-up costs about two of PCG's iterations here: docs/performance.md,
/// "the fluid step's own cost, second round").
constexpr int kStaleIterations = 1;

}  // namespace

PressurePfmg::PressurePfmg(double tolerance, int max_iterations)
    : s_(std::make_unique<State>()), tol_(tolerance), max_(max_iterations) {
  runtime();
}

PressurePfmg::~PressurePfmg() = default;

PressurePfmg::Saved PressurePfmg::saved() const {
  // a restored solver that has not solved yet still holds the checkpoint's matrix
  return Saved{s_->sol, s_->pcg || s_->restored ? s_->setup_values : std::vector<double>{}, s_->setup_iterations,
               s_->last_iterations};
}

void PressurePfmg::restore(const Saved& saved) {
  s_->drop_preconditioner();  // one built before the restore belongs to another matrix
  s_->sol = saved.sol;
  s_->setup_values = saved.setup_values;
  s_->setup_iterations = saved.setup_iterations;
  s_->last_iterations = saved.last_iterations;
  s_->restored = true;
}

SolveReport PressurePfmg::operator()(const PressureSystem& sys, std::vector<double>& x) {
  State& s = *s_;
  const std::size_t cells = static_cast<std::size_t>(sys.n[0]) * sys.n[1] * sys.n[2];
  int lower[3] = {0, 0, 0}, upper[3] = {sys.n[0] - 1, sys.n[1] - 1, sys.n[2] - 1};
  const bool restoring = s.restored;  // until a solve has set up from the checkpoint's matrix
  if (s.grid == nullptr || s.n != sys.n) {
    s.drop_grid();
    HYPRE_StructGridCreate(MPI_COMM_SELF, 3, &s.grid);
    HYPRE_StructGridSetExtents(s.grid, lower, upper);
    HYPRE_StructGridAssemble(s.grid);
    int offsets[7][3] = {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
    HYPRE_StructStencilCreate(3, 7, &s.stencil);
    for (int e = 0; e < 7; ++e) HYPRE_StructStencilSetElement(s.stencil, e, offsets[e]);
    HYPRE_StructMatrixCreate(MPI_COMM_SELF, s.grid, s.stencil, &s.A);
    HYPRE_StructMatrixInitialize(s.A);
    HYPRE_StructVectorCreate(MPI_COMM_SELF, s.grid, &s.b);
    HYPRE_StructVectorInitialize(s.b);
    HYPRE_StructVectorCreate(MPI_COMM_SELF, s.grid, &s.x);
    HYPRE_StructVectorInitialize(s.x);
    s.n = sys.n;
    s.pattern_id = 0;  // the stencil entries belong to the old grid
    s.fluid.clear();
    if (!restoring || s.sol.size() != cells) s.sol.assign(cells, 0.0);
    if (!restoring || s.setup_values.size() != 7 * cells) s.setup_values.clear();
  }
  // the stencil entry of each off-diagonal, found again only when the
  // system's pattern changes (the coupler's stays the same from step to step:
  // its pattern id says so; a system without an id is taken as new each time)
  const bool same = sys.pattern_id != 0 && sys.pattern_id == s.pattern_id && s.fluid.size() == cells;
  const auto nx = static_cast<std::size_t>(sys.n[0]), nxy = nx * static_cast<std::size_t>(sys.n[1]);
  if (!same) {
    s.drop_preconditioner();  // built for other unknowns (a checkpoint's set-up matrix is kept for the first solve)
    if (!restoring) s.setup_values.clear();
    s.entry.clear();
    s.pattern_id = 0;  // named only once the pattern below is complete
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
        s.entry.push_back(static_cast<std::uint8_t>(e));
      }
    }
    s.pattern_id = sys.pattern_id;
  }
  // the 7-point rows on the whole grid: identity rows for blocked cells,
  // written with the pattern; a fluid row's entries are this system's
  if (!same) {
    s.values.assign(7 * cells, 0.0);
    s.rhs.assign(cells, 0.0);
    for (std::size_t c = 0; c < cells; ++c) s.values[7 * c] = 1.0;
  }
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
  int entries[7] = {0, 1, 2, 3, 4, 5, 6};
  auto set_matrix = [&](std::vector<double>& v) {
    HYPRE_StructMatrixSetBoxValues(s.A, lower, upper, 7, entries, v.data());
    HYPRE_StructMatrixAssemble(s.A);
  };
  HYPRE_StructVectorSetBoxValues(s.b, lower, upper, s.rhs.data());
  HYPRE_StructVectorAssemble(s.b);
  for (std::size_t c = 0; c < cells; ++c)
    if (!fluid[c]) s.sol[c] = 0.0;
  auto set_guess = [&] {
    HYPRE_StructVectorSetBoxValues(s.x, lower, upper, s.sol.data());
    HYPRE_StructVectorAssemble(s.x);
  };
  set_guess();
  // PCG's set-up builds PFMG's levels from the matrix it is given; PFMG's
  // finest level is that matrix itself, so the values written after it are
  // the ones the conjugate gradient and the finest smoothing use
  auto set_up = [&](std::vector<double>& from) {
    s.drop_preconditioner();
    set_matrix(from);
    HYPRE_StructPCGCreate(MPI_COMM_SELF, &s.pcg);
    HYPRE_StructPCGSetMaxIter(s.pcg, max_);
    HYPRE_StructPCGSetTwoNorm(s.pcg, 1);
    HYPRE_StructPFMGCreate(MPI_COMM_SELF, &s.pfmg);
    HYPRE_StructPFMGSetMaxIter(s.pfmg, 1);
    HYPRE_StructPFMGSetTol(s.pfmg, 0.0);
    HYPRE_StructPFMGSetZeroGuess(s.pfmg);
    HYPRE_StructPFMGSetRelaxType(s.pfmg, 1);  // weighted Jacobi: symmetric, as PCG needs
    HYPRE_StructPFMGSetNumPreRelax(s.pfmg, 1);
    HYPRE_StructPFMGSetNumPostRelax(s.pfmg, 1);
    HYPRE_StructPCGSetPrecond(s.pcg, HYPRE_StructPFMGSolve, HYPRE_StructPFMGSetup, s.pfmg);
    HYPRE_StructPCGSetup(s.pcg, s.A, s.b, s.x);
    if (&from != &s.setup_values) s.setup_values = from;
  };
  // the same decision a restarted run takes: the renewal rule first, then the
  // checkpointed run's preconditioner (to the bit), else the kept one
  bool fresh = false;
  s.restored = false;
  const bool stale = s.last_iterations > s.setup_iterations + kStaleIterations;
  if (stale || (!s.pcg && !(restoring && !s.setup_values.empty()))) {
    set_up(s.values);
    fresh = true;
  } else if (!s.pcg) {
    set_up(s.setup_values);
  }
  set_matrix(s.values);
  const double rtol = sys.relative_tolerance(tol_, bn);
  HYPRE_StructPCGSetTol(s.pcg, rtol);
  HYPRE_Int it = 0;
  double res = 0;
  HYPRE_StructPCGSolve(s.pcg, s.A, s.b, s.x);
  HYPRE_StructPCGGetNumIterations(s.pcg, &it);
  HYPRE_StructPCGGetFinalRelativeResidualNorm(s.pcg, &res);
  // hypre stops at |r|^2 < rtol^2 |b|^2 and reports the root: a converged
  // solve may read an ulp above rtol
  const bool converged = res <= rtol * (1 + 1e-12);
  HYPRE_Int counted = it;  // what the renewal rule reads: the iterations of the solve that ended it
  if (!fresh && !converged) {
    // an old preconditioner that no longer gets there within max_iterations:
    // build it anew and solve again from where the first try stopped
    HYPRE_StructVectorGetBoxValues(s.x, lower, upper, s.sol.data());
    set_up(s.values);
    fresh = true;
    set_guess();
    HYPRE_StructPCGSetTol(s.pcg, rtol);
    HYPRE_Int more = 0;
    HYPRE_StructPCGSolve(s.pcg, s.A, s.b, s.x);
    HYPRE_StructPCGGetNumIterations(s.pcg, &more);
    HYPRE_StructPCGGetFinalRelativeResidualNorm(s.pcg, &res);
    it += more;
    counted = more;
  }
  HYPRE_StructVectorGetBoxValues(s.x, lower, upper, s.sol.data());
  s.last_iterations = static_cast<int>(counted);
  if (fresh) s.setup_iterations = s.last_iterations;
  for (std::size_t r = 0; r < sys.diag.size(); ++r) x[r] = s.sol[sys.cell_of[r]];
  rep.iterations = static_cast<int>(it);
  rep.residual = res;
  return rep;
}

}  // namespace domel::plugins::fluid
