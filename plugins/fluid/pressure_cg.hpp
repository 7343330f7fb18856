// SPDX-License-Identifier: MIT
// The built-in pressure solve: Eigen's conjugate gradient with an incomplete
// Cholesky preconditioner on the SPD 7-point system of vans_solver.hpp,
// warm-started from the previous correction; the preconditioner is kept
// while the system's matrix stays the same (a gas step without particles, or
// with the same drag and void fraction). Adequate for the grids of the
// validation cases (up to ~10^5 cells); its cost per cell grows with the grid
// (docs/fluid.md, "Pressure solve"), which a multigrid back end removes.
#pragma once

#include "plugins/fluid/vans_solver.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <algorithm>
#include <vector>

namespace domel::plugins::fluid {

class PressureCg {
 public:
  PressureCg(double tolerance, int max_iterations) : tol_(tolerance), max_(max_iterations) {}
  // the solver keeps a reference to A_ once it has factored it: not copied or moved
  PressureCg(const PressureCg&) = delete;
  PressureCg& operator=(const PressureCg&) = delete;

  SolveReport operator()(const PressureSystem& sys, std::vector<double>& x) {
    const Eigen::Index n = static_cast<Eigen::Index>(sys.diag.size());
    Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(sys.rhs.data(), n);
    if (last_.size() != n) last_ = Eigen::VectorXd::Zero(n);
    const bool same = A_.rows() == n && sys.diag == diag_ && sys.off == off_;
    if (!same) {
      std::vector<Eigen::Triplet<double>> t;
      t.reserve(sys.diag.size() * 7);
      for (std::size_t r = 0; r < sys.diag.size(); ++r) {
        t.emplace_back(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(r), sys.diag[r]);
        for (const auto& [c, v] : sys.off[r])
          t.emplace_back(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c), v);
      }
      A_.resize(n, n);
      A_.setFromTriplets(t.begin(), t.end());
      diag_ = sys.diag;
      off_ = sys.off;
      factored_ = false;
    }
    auto& cg = cg_;
    // relative to |b|, but never below tol x the system's reference norm
    const double bn = sys.rhs_norm();
    cg.setTolerance(sys.relative_tolerance(tol_, bn));
    cg.setMaxIterations(max_);
    Eigen::VectorXd sol = Eigen::VectorXd::Zero(n);
    const bool trivial = sys.trivial(tol_, bn);
    if (!trivial) {
      if (!factored_) cg.compute(A_);
      factored_ = true;
      sol = cg.solveWithGuess(b, last_);
    }
    last_ = sol;
    x.assign(sol.data(), sol.data() + n);
    SolveReport rep;
    rep.iterations = trivial ? 0 : static_cast<int>(cg.iterations());
    rep.residual = trivial ? 0.0 : cg.error();
    return rep;
  }

  /// The warm start of the next solve (the last correction), for checkpoints.
  std::vector<double> warm_start() const { return std::vector<double>(last_.data(), last_.data() + last_.size()); }
  void set_warm_start(const std::vector<double>& x) {
    last_ = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
  }

 private:
  double tol_;
  int max_;
  Eigen::VectorXd last_;
  Eigen::SparseMatrix<double> A_;  ///< the matrix factored, kept while diag_ and off_ hold
  std::vector<double> diag_;
  std::vector<std::vector<std::pair<std::size_t, double>>> off_;
  bool factored_ = false;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>>
      cg_;
};

}  // namespace domel::plugins::fluid
