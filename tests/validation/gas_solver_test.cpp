// SPDX-License-Identifier: MIT
// The fluid coupler's gas solver (plugins/fluid/vans_solver.hpp) on single-
// phase flows with published answers (eps = 1, no particles), issue 45 item
// 1; docs/validation/gas-solver.md has the figures and the grid study.
//
//  - Lid-driven cavity, Re = 100 and 400, 64 x 64 cells: the centre-line
//    velocities against Ghia, Ghia & Shin (1982, J. Comput. Phys. 48:387,
//    Tables I and II, a 129 x 129 multigrid solution), within 2 % of the lid
//    speed (the bound) with van Leer's scheme. Ghia's v at x = 0.9063
//    for Re = 400 (-0.23827) is compared apart, not bounded: it lies 0.09 U
//    above the straight line through its neighbours (-0.44993 at 0.8594,
//    -0.22847 at 0.9453), a kink no other point of the table has, and is
//    widely taken for a misprint; the test prints the solution's value there.
//  - Square cylinder in a channel, blockage 1/8, parabolic inflow, Re = U_max
//    D / nu = 20: the recirculation length behind it against Breuer, Bernsdorf,
//    Zeiser & Durst (2000, Int. J. Heat Fluid Flow 21:186), L_r / D = -0.065 +
//    0.0554 Re (their fit over 5 < Re < 60 of two methods' results), within
//    10 % (the bound).
//  - Plane Poiseuille flow between no-slip walls, driven by two pressure
//    outlets: the developed profile u = G y (H - y) / (2 mu), and its error's
//    order under grid refinement (4, 8, 16 cells across).
// The solver marches in time to the steady state in explicit steps within
// the limits of advection and diffusion; the state is steady when the
// quantity compared changes by less than a stated amount over a window of
// the flow's time scale (DOMEL_GAS_STRICT set: a hundred times less; the
// figures of both in the page).
// Cost (optimised build): cavity Re 100 about 10 s, Re 400 about 15 s,
// cylinder about 15 s, channel under 1 s.
#include "plugins/fluid/pressure_cg.hpp"
#include "plugins/fluid/vans_solver.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

using domel::plugins::fluid::Advection;
using domel::plugins::fluid::Boundary;
using domel::plugins::fluid::PressureCg;
using domel::plugins::fluid::VansSolver;

Boundary wall(double ux = 0, double uy = 0) {
  Boundary b;
  b.velocity = {ux, uy, 0};
  return b;
}
Boundary slip() {
  Boundary b;
  b.type = Boundary::slip_wall;
  return b;
}
Boundary outlet(double p) {
  Boundary b;
  b.type = Boundary::pressure_outlet;
  b.pressure = p;
  return b;
}

/// A 2-D grid: nx x ny cells of side h, one cell of depth h, slip walls in z.
VansSolver::Settings plane(int nx, int ny, double h, double rho, double mu, Advection scheme) {
  VansSolver::Settings s;
  s.grid.lo = {0, 0, 0};
  s.grid.n = {nx, ny, 1};
  s.grid.h = {h, h, h};
  s.rho = rho;
  s.mu = mu;
  s.advection = scheme;
  s.sides[4] = slip();
  s.sides[5] = slip();
  return s;
}

/// March until what `monitor` returns (the quantities a test compares)
/// changes by less than `tol` over a window of `window_time`, or until
/// t_max. Returns the time reached.
template <class Monitor>
double steady(VansSolver& f, double dt, double t_max, double window_time, double tol, Monitor monitor) {
  PressureCg cg(1e-8, 5000);  // the coupler's default tolerance
  auto solve = [&](const domel::plugins::fluid::PressureSystem& sys, std::vector<double>& x) { return cg(sys, x); };
  const int window = std::max(1, static_cast<int>(std::lround(window_time / dt)));
  double t = 0;
  std::vector<double> before = monitor();
  while (t < t_max) {
    for (int n = 0; n < window; ++n) {
      f.step(dt, 1.0, 1.0, solve);
      t += dt;
    }
    const std::vector<double> now = monitor();
    double change = 0;
    for (std::size_t k = 0; k < now.size(); ++k) change = std::max(change, std::abs(now[k] - before[k]));
    for (int a = 0; a < 2; ++a)
      for (double u : f.u(a)) change = std::isfinite(u) ? change : NAN;
    if (!std::isfinite(change)) {
      ADD_FAILURE() << "the flow blew up before t = " << t;
      break;
    }
    if (change < tol) break;
    before = now;
  }
  return t;
}

/// Linear interpolation of samples (x_k, y_k), x increasing.
double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  std::size_t k = 1;
  while (k + 1 < x.size() && x[k] < at) ++k;
  const double w = (at - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] + w * (y[k] - y[k - 1]);
}

struct Ghia {
  std::vector<double> y, u, x, v;
};

// Tables I and II of Ghia, Ghia & Shin (1982), without the end points (the
// walls' own values).
Ghia ghia(int re) {
  Ghia g;
  g.y = {0.0547, 0.0625, 0.0703, 0.1016, 0.1719, 0.2813, 0.4531, 0.5, 0.6172, 0.7344, 0.8516, 0.9531, 0.9609, 0.9688, 0.9766};
  g.x = {0.0625, 0.0703, 0.0781, 0.0938, 0.1563, 0.2266, 0.2344, 0.5, 0.8047, 0.8594, 0.9063, 0.9453, 0.9531, 0.9609, 0.9688};
  if (re == 100) {
    g.u = {-0.03717, -0.04192, -0.04775, -0.06434, -0.10150, -0.15662, -0.21090, -0.20581, -0.13641, 0.00332, 0.23151,
           0.68717, 0.73722, 0.78871, 0.84123};
    g.v = {0.09233, 0.10091, 0.10890, 0.12317, 0.16077, 0.17507, 0.17527, 0.05454, -0.24533, -0.22445, -0.16914,
           -0.10313, -0.08864, -0.07391, -0.05906};
  } else {
    g.u = {-0.08186, -0.09266, -0.10338, -0.14612, -0.24299, -0.32726, -0.17119, -0.11477, 0.02135, 0.16256, 0.29093,
           0.55892, 0.61756, 0.68439, 0.75837};
    g.v = {0.18360, 0.19713, 0.20920, 0.22965, 0.28124, 0.30203, 0.30174, 0.05186, -0.38598, -0.44993, NAN /*misprint*/,
           -0.22847, -0.19254, -0.15663, -0.12146};
  }
  return g;
}

struct CavityResult {
  double worst_u, worst_v, t;
  double u_mid;  ///< u on the vertical centre line at Ghia's y = 0.4531 (the grid study's quantity)
  double v_kink; ///< v on the horizontal centre line at x = 0.9063 (Ghia's doubtful Re 400 point)
};

/// The cavity of side 1 with lid speed 1 (rho = 1, mu = 1 / Re) on n x n cells.
CavityResult cavity(int re, int n, Advection scheme) {
  const double h = 1.0 / n;
  VansSolver::Settings s = plane(n, n, h, 1.0, 1.0 / re, scheme);
  s.sides[3] = wall(1.0, 0.0);  // the lid, y = 1, moving along +x
  VansSolver f(s, {});
  // u on the vertical centre line x = 0.5 (the faces i = n/2), at the cell
  // centres' heights, with the walls' values at y = 0 and 1; v likewise on
  // the horizontal one
  std::vector<double> ys{0.0}, us, xs{0.0}, vs;
  for (int j = 0; j < n; ++j) ys.push_back((j + 0.5) * h);
  ys.push_back(1.0);
  for (int i = 0; i < n; ++i) xs.push_back((i + 0.5) * h);
  xs.push_back(1.0);
  auto profiles = [&] {
    us = {0.0}, vs = {0.0};
    for (int j = 0; j < n; ++j) us.push_back(f.u(0)[f.grid().face(0, n / 2, j, 0)]);
    for (int i = 0; i < n; ++i) vs.push_back(f.u(1)[f.grid().face(1, i, n / 2, 0)]);
    us.push_back(1.0), vs.push_back(0.0);
    std::vector<double> both = us;
    both.insert(both.end(), vs.begin(), vs.end());
    return both;
  };
  // steady: the profiles change by less than 1e-5 of the lid speed over one
  // time unit L / U (the strict form, 1e-7, in docs/validation/gas-solver.md)
  const double dt = std::min(0.4 * h, 0.2 * h * h * re);
  const double t = steady(f, dt, 200.0, 1.0, std::getenv("DOMEL_GAS_STRICT") ? 1e-7 : 1e-5, profiles);
  profiles();
  const Ghia g = ghia(re);
  CavityResult r{0, 0, t, interpolate(ys, us, 0.4531), interpolate(xs, vs, 0.9063)};
  for (std::size_t k = 0; k < g.y.size(); ++k) {
    const double du = interpolate(ys, us, g.y[k]) - g.u[k];
    r.worst_u = std::max(r.worst_u, std::abs(du));
  }
  for (std::size_t k = 0; k < g.x.size(); ++k) {
    if (std::isnan(g.v[k])) continue;
    const double dv = interpolate(xs, vs, g.x[k]) - g.v[k];
    r.worst_v = std::max(r.worst_v, std::abs(dv));
  }
  std::printf("[cavity Re %d, %d x %d, %s] steady at t = %.1f; largest |u - Ghia| %.4f, |v - Ghia| %.4f (lid speed 1)",
              re, n, n, scheme == Advection::van_leer ? "van Leer" : "upwind  ", t, r.worst_u, r.worst_v);
  if (re == 400) std::printf("; v(0.9063) = %.4f (Ghia's doubtful -0.23827)", r.v_kink);
  std::printf("\n");
  return r;
}

}  // namespace

TEST(GasSolver, LidDrivenCavityAtRe100MatchesGhiaWithin2PercentOfTheLidSpeed) {
  const CavityResult vl = cavity(100, 64, Advection::van_leer);
  EXPECT_LT(vl.worst_u, 0.02);
  EXPECT_LT(vl.worst_v, 0.02);
}

TEST(GasSolver, LidDrivenCavityAtRe400MatchesGhiaWithin2PercentOfTheLidSpeed) {
  const CavityResult vl = cavity(400, 64, Advection::van_leer);
  EXPECT_LT(vl.worst_u, 0.02);
  EXPECT_LT(vl.worst_v, 0.02);
}

// Full size (scripts/validate, about 2 minutes): both schemes on 16, 32 and
// 64 cells at Re 100 and 400. Printed: u at (0.5, 0.4531) on the three grids
// with its Richardson order log2((f16 - f32) / (f32 - f64)), and the largest
// difference from Ghia on each grid with the order of its fall. Checked:
// upwind differs from Ghia more than van Leer on every grid; at Re 400, where
// both differ far more than Ghia's own error (a 129 x 129 second-order
// solution), van Leer's difference falls from 32 to 64 cells with an order
// above 1.5 (a second-order scheme, first order at the limiter's extrema and
// beside the walls) and upwind's with one below 1.2 (first order).
TEST(GasSolverFullSize, CavityGridStudyOfBothSchemes) {
  for (int re : {100, 400}) {
    double worst[2][3];
    for (Advection scheme : {Advection::upwind, Advection::van_leer}) {
      const int m = scheme == Advection::van_leer ? 1 : 0;
      double f[3];
      for (int g = 0; g < 3; ++g) {
        const CavityResult r = cavity(re, 16 << g, scheme);
        f[g] = r.u_mid;
        worst[m][g] = std::max(r.worst_u, r.worst_v);
      }
      std::printf("[cavity Re %d %s] u(0.5, 0.4531) on 16, 32, 64 cells: %.5f %.5f %.5f, Richardson order %.2f; "
                  "largest difference from Ghia %.4f %.4f %.4f, orders of its fall %.2f %.2f\n",
                  re, m ? "van Leer" : "upwind  ", f[0], f[1], f[2], std::log2((f[0] - f[1]) / (f[1] - f[2])),
                  worst[m][0], worst[m][1], worst[m][2], std::log2(worst[m][0] / worst[m][1]),
                  std::log2(worst[m][1] / worst[m][2]));
    }
    for (int g = 0; g < 3; ++g) EXPECT_GT(worst[0][g], worst[1][g]) << "Re " << re << ", " << (16 << g) << " cells";
    if (re == 400) {
      EXPECT_GT(std::log2(worst[1][1] / worst[1][2]), 1.5);
      EXPECT_LT(std::log2(worst[0][1] / worst[0][2]), 1.2);
    }
  }
}

namespace {

/// The square cylinder of Breuer et al. (2000) at D = cells_per_d cells:
/// channel H = 8 D, the cylinder's centre 8 D behind the inlet (theirs 12.5 D)
/// and 22 D ahead of the outlet (theirs 37.5 D); parabolic inflow of centre
/// speed 1; rho = 1, mu = D / Re. Returns L_r / D, the length of the
/// recirculation behind the cylinder on the centre line.
double recirculation(int re, int cells_per_d, Advection scheme) {
  const int nd = cells_per_d, nx = 30 * nd, ny = 8 * nd;
  const double d = 1.0, h = d / nd;
  VansSolver::Settings s = plane(nx, ny, h, 1.0, d / re, scheme);
  Boundary in;
  in.type = Boundary::velocity_inlet;
  in.velocity = {1.0, 0, 0};
  in.parabolic = true;
  s.sides[0] = in;
  s.sides[1] = outlet(0.0);
  // the cylinder: cells [8 D - D/2, 8 D + D/2) along x, the middle D along y
  std::vector<std::uint8_t> blocked(s.grid.cells(), 0);
  const int i0 = 8 * nd - nd / 2, j0 = 4 * nd - nd / 2;
  for (int j = j0; j < j0 + nd; ++j)
    for (int i = i0; i < i0 + nd; ++i) blocked[s.grid.cell(i, j, 0)] = 1;
  VansSolver f(s, blocked);
  // explicit limits with the speeds beside the cylinder (|u| + |v| up to
  // about 1.6 of the centre speed): dt (sum_a |u_a| / h + 4 nu / h^2) <= 0.9,
  // and the Courant number at most 0.5 (van Leer's TVD bound)
  const double dt = std::min(0.5 * h / 1.6, 0.9 / (1.6 / h + 4.0 * d / re / (h * h)));
  // u on the centre line y = 4 D (between rows ny/2 - 1 and ny/2), from the
  // rear face x = i0 + nd (a face of the u grid) downstream: where it turns positive
  const int rear = i0 + nd;
  auto u_at = [&](int i) {
    return 0.5 * (f.u(0)[f.grid().face(0, i, ny / 2 - 1, 0)] + f.u(0)[f.grid().face(0, i, ny / 2, 0)]);
  };
  auto length = [&] {
    for (int i = rear + 1; i < nx; ++i)
      if (u_at(i) > 0) {
        const double u0 = u_at(i - 1), u1 = u_at(i);
        return std::vector<double>{((i - 1 - rear) + u0 / (u0 - u1)) * h};
      }
    return std::vector<double>{0.0};
  };
  // steady: L_r changes by less than 1e-4 D over 2 D / U (strict: 1e-6 D)
  const double t = steady(f, dt, 150.0, 2.0 * d, std::getenv("DOMEL_GAS_STRICT") ? 1e-6 : 1e-4, length);
  const double lr = length()[0];
  std::printf("[square cylinder Re %d, D = %d cells, %s] steady at t = %.1f D/U; L_r / D = %.3f (Breuer et al. %.3f)\n",
              re, nd, scheme == Advection::van_leer ? "van Leer" : "upwind  ", t, lr / d, -0.065 + 0.0554 * re);
  return lr / d;
}

}  // namespace

TEST(GasSolver, RecirculationBehindASquareCylinderAtRe20MatchesBreuerWithin10Percent) {
  const double expected = -0.065 + 0.0554 * 20;
  EXPECT_NEAR(recirculation(20, 8, Advection::van_leer), expected, 0.1 * expected);
}

namespace {

/// Plane Poiseuille flow on ny cells across H = 1 (4 along x, L = 1), driven
/// by a pressure drop dp between two outlets (rho = 1, mu = 1): the largest
/// error of the face velocities against G y (H - y) / (2 mu), relative to the
/// centre speed G H^2 / (8 mu).
double poiseuille_error(int ny, Advection scheme) {
  const double h = 1.0 / ny, mu = 1.0, dp = 8.0;
  VansSolver::Settings s = plane(4, ny, h, 1.0, mu, scheme);
  s.grid.h[0] = 0.25;
  s.sides[0] = outlet(dp);
  s.sides[1] = outlet(0.0);
  VansSolver f(s, {});
  const double g = dp / 1.0, u_max = g / (8 * mu);
  auto faces = [&] { return f.u(0); };  // steady: no face changes by 1e-12 of u_max over H^2 / nu
  steady(f, 0.2 * h * h / mu, 20.0, 1.0 / mu, 1e-12 * u_max, faces);
  double worst = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i <= 4; ++i) {
      const double y = (j + 0.5) * h;
      worst = std::max(worst, std::abs(f.u(0)[f.grid().face(0, i, j, 0)] - g * y * (1 - y) / (2 * mu)));
    }
  return worst / u_max;
}

}  // namespace

TEST(GasSolver, ADevelopedChannelFlowIsPoiseuillesProfileWithSecondOrderError) {
  // The staggered grid's error is O(h^2) (the wall's mirrored ghost lies
  // half a cell out); the measured order between 8 and 16 cells must be
  // within 0.2 of 2, and the 16-cell profile within 0.5 % of the centre speed.
  double previous = 0;
  for (int ny : {4, 8, 16}) {
    const double e = poiseuille_error(ny, Advection::van_leer);
    std::printf("[channel, %2d cells across] largest error %.3e of the centre speed%s", ny, e, previous > 0 ? "" : "\n");
    if (previous > 0) std::printf("; order %.2f\n", std::log2(previous / e));
    if (ny == 16) {
      EXPECT_LT(e, 5e-3);
      EXPECT_NEAR(std::log2(previous / e), 2.0, 0.2);
    }
    previous = e;
  }
}

// Full size (scripts/validate, about 12 minutes): the square cylinder at Re 20
// and 40, van Leer on D = 6, 8 and 12 cells and upwind on 8; van Leer within
// 10 % of Breuer et al.'s fit on 8 and 12 cells (the bound), the
// rest reported.
TEST(GasSolverFullSize, RecirculationBehindASquareCylinderAtRe20And40WithBothSchemes) {
  for (int re : {20, 40}) {
    const double expected = -0.065 + 0.0554 * re;
    for (int cells : {6, 8, 12}) {
      const double lr = recirculation(re, cells, Advection::van_leer);
      if (cells >= 8) EXPECT_NEAR(lr, expected, 0.1 * expected) << "Re " << re << ", D = " << cells << " cells";
    }
    recirculation(re, 8, Advection::upwind);
  }
}
