// SPDX-License-Identifier: MIT
// The incompressible volume-averaged Navier-Stokes equations of the built-in
// fluid coupler, Anderson & Jackson's "model A" (set II of Zhou, Kuang, Chu &
// Yu 2010, J. Fluid Mech. 661:482; docs/fluid.md says why A and not B):
//
//   d(eps)/dt + div(eps u) = 0
//   rho_f eps (du/dt + (u . grad) u) = -eps grad p + mu div(eps grad u)
//                                      + rho_f eps g - K (u - u_s)
//
// on a uniform staggered grid (mac_grid.hpp); u is the interstitial velocity,
// eps the fluid volume fraction, K (u - u_s) the drag the particles exert per
// unit volume (K = sum of the particles' beta over the cell volume, u_s their
// mean velocity weighted by beta). The momentum equation is written in its
// advective form, which equals the conservative one where continuity holds.
// One step of length dt is an incremental pressure-correction projection
// (Chorin 1968; Spalding's partial elimination for the drag):
//
//   predictor   rho_f eps^{n+1} (u* - u^n)/dt = R^n - K (u* - u_s)
//               with R^n = -rho_f eps (u^n . grad) u^n   (first-order upwind,
//                          or van Leer's limited upwind-biased one: below)
//                          + mu eps lap u^n - eps grad p^n + rho_f eps g,
//               so u* = (rho_f eps u^n/dt + R^n + K u_s) / (rho_f eps/dt + K)
//               face by face: the drag is implicit, no limit from K;
//   correction  u^{n+1} = u* - A grad p',  A = eps dt / (rho_f eps + K dt),
//   pressure    div(eps A grad p') = div(eps u*) + (eps^{n+1} - eps^n)/dt,
//               a symmetric positive-definite 7-point system (solved by the
//               caller's PressureSolver), then p^{n+1} = p^n + p'.
//
// Advection: (u . grad) u_a at a face is sum_b u_b (phi_{+1/2} - phi_{-1/2}) / h_b,
// with phi the value of u_a halfway to the next face along b, taken from the
// upwind side: first-order upwind takes the upwind face's value; van Leer
// (1974, J. Comput. Phys. 14:361) adds the limited slope, phi_{+1/2} = u_0 +
// psi(r) (u_1 - u_0) / 2 with psi(r) = (r + |r|) / (1 + |r|), r = (u_0 -
// u_{-1}) / (u_1 - u_0): second order where the profile is smooth, first
// order at extrema, no new extrema (TVD). Its 5-point stencil takes the
// boundaries' ghost values two faces out (mirrored), and falls back to
// upwind across the flow within two faces of an obstacle (along it, the
// obstacle's own faces carry the wall's zero normal velocity).
// docs/validation/gas-solver.md checks both.
//
// Boundaries, per side of the box: no-slip wall (normal velocity 0, the
// tangential one mirrored about the wall's own tangential velocity, zero
// unless it moves: a lid), slip wall (normal velocity 0, no shear: a plane
// of symmetry), velocity inlet over the whole side or a patch of
// it (the rest of the side is wall; the velocity given is superficial, so
// eps u = U across the face even where particles sit on it), pressure outlet (p fixed half a cell
// outside the last cell centre, zero gradient of the velocity). Blocked cells
// (obstacles) are no-slip walls on every face: the tangential velocity inside
// an obstacle is the mirror of the flow's, as beyond a wall side of the box.
// A box with an outlet has its pressure level fixed there; a closed box
// (walls only: a cavity) pins the pressure correction of its first fluid
// cell, whose own continuity then follows from the others' (the box's net
// flux is zero). Inlets without an outlet are refused.
#pragma once

#include "plugins/fluid/mac_grid.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace domel::plugins::fluid {

enum class Side { x_min = 0, x_max, y_min, y_max, z_min, z_max };
constexpr const char* kSideNames[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};

struct Boundary {
  enum Type { wall, slip_wall, velocity_inlet, pressure_outlet } type = wall;
  std::array<double, 3> velocity{0, 0, 0};  ///< inlet velocity, or a no-slip wall's tangential one [m/s]
  bool patch = false;                       ///< inlet over a patch only
  /// inlet: the laminar profile of a developed flow, velocity x the product
  /// of 4 s (1 - s) over the side's (or patch's) tangential axes of more than
  /// one cell (s: 0 to 1 across it); `velocity` is then the centre's
  bool parabolic = false;
  std::array<double, 3> patch_lo{0, 0, 0}, patch_hi{0, 0, 0};
  double pressure = 0;                      ///< outlet pressure [Pa]
};

/// The advection scheme of the momentum equation (see the top of this file).
enum class Advection { upwind, van_leer };

/// The face's role: free (solved: interior between two fluid cells, or on an
/// outlet) or fixed (wall, inlet, a face of a blocked cell).
enum class FaceKind : std::uint8_t { interior, outlet, wall, inlet };

/// Solves A x = b for the pressure correction: A sparse SPD, given row by
/// row as (diag, neighbours). Returns iterations and relative residual.
struct PressureSystem {
  std::array<int, 3> n{0, 0, 0};                      ///< the grid's cells per axis
  std::vector<std::size_t> cell_of;                   ///< per unknown: its cell (i + nx (j + ny k))
  std::vector<double> diag;                           ///< per unknown
  std::vector<std::vector<std::pair<std::size_t, double>>> off;  ///< per unknown: (column, value), value < 0
  std::vector<double> rhs;
  /// Names the pattern (n, cell_of, off's columns): a new value whenever it
  /// is built, the same while only the values change, so that a solver may
  /// keep what it derived from the pattern (new_pattern_id())
  std::uint64_t pattern_id = 0;
  /// |rhs| below which the system counts as solved [1/s]: the round-off of
  /// a fluid at rest would otherwise be iterated on as if it were flow
  double reference_norm = 0;

  /// |rhs| (2-norm).
  double rhs_norm() const {
    double s = 0;
    for (double v : rhs) s += v * v;
    return std::sqrt(s);
  }
  /// Whether rhs is below `tol` x the reference: nothing to solve.
  bool trivial(double tol, double bnorm) const { return bnorm <= tol * reference_norm; }
  /// The relative tolerance a solver stops at: `tol`, but never below `tol`
  /// x the reference norm in absolute terms.
  double relative_tolerance(double tol, double bnorm) const {
    return bnorm > 0 ? tol * std::max(1.0, reference_norm / bnorm) : tol;
  }
};
/// A pattern id no other system in the process has had.
inline std::uint64_t new_pattern_id() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1);
}
struct SolveReport {
  int iterations = 0;
  double residual = 0;
};
using PressureSolver = std::function<SolveReport(const PressureSystem&, std::vector<double>& x)>;

class VansSolver {
 public:
  struct Settings {
    MacGrid grid;
    std::array<Boundary, 6> sides;
    double rho = 1.2;   ///< [kg/m^3]
    double mu = 1.8e-5; ///< [Pa s]
    std::array<double, 3> gravity{0, 0, 0};
    std::array<double, 3> initial_velocity{0, 0, 0};
    Advection advection = Advection::upwind;
  };

  VansSolver(Settings s, std::vector<std::uint8_t> blocked) : s_(std::move(s)), blocked_(std::move(blocked)) {
    const MacGrid& g = s_.grid;
    if (blocked_.empty()) blocked_.assign(g.cells(), 0);
    if (blocked_.size() != g.cells()) throw std::invalid_argument("blocked cells do not match the grid");
    bool outlet = false, inlet = false;
    for (int side = 0; side < 6; ++side) {
      const Boundary& b = s_.sides[side];
      outlet = outlet || b.type == Boundary::pressure_outlet;
      inlet = inlet || b.type == Boundary::velocity_inlet;
      if (b.type == Boundary::wall && b.velocity[side / 2] != 0)
        throw std::invalid_argument(std::string("the wall ") + kSideNames[side] + " moves across itself");
    }
    if (inlet && !outlet) throw std::invalid_argument("an inlet without a pressure outlet: the gas cannot leave");
    closed_ = !outlet;
    eps_.assign(g.cells(), 1.0);
    eps_old_ = eps_;
    p_.assign(g.cells(), 0.0);
    for (int a = 0; a < 3; ++a) {
      kind_[a].assign(g.faces(a), FaceKind::interior);
      u_[a].assign(g.faces(a), 0.0);
      K_[a].assign(g.faces(a), 0.0);
      Ku_[a].assign(g.faces(a), 0.0);
    }
    classify_faces();
    // unknowns: the fluid cells
    unknown_.assign(g.cells(), SIZE_MAX);
    for (std::size_t c = 0; c < g.cells(); ++c)
      if (!blocked_[c]) unknown_[c] = n_unknowns_++;
    build_stencils();
    // start: the initial velocity on the free faces, the inlet values on inlets
    for (int a = 0; a < 3; ++a)
      for (std::size_t f = 0; f < g.faces(a); ++f)
        u_[a][f] = kind_[a][f] == FaceKind::inlet ? inlet_value_[a][f]
                   : (kind_[a][f] == FaceKind::wall ? 0.0 : s_.initial_velocity[a]);
    set_gravity(s_.gravity);
  }

  /// The gravity of the fluid's momentum equation, and the pressure reset to
  /// hydrostatic from the first outlet (the coupler learns the scenario's
  /// gravity at its first exchange).
  void set_gravity(const std::array<double, 3>& gravity) {
    s_.gravity = gravity;
    const MacGrid& g = s_.grid;
    if (closed_) {  // hydrostatic about the box's centre
      for (int k = 0; k < g.n[2]; ++k)
        for (int j = 0; j < g.n[1]; ++j)
          for (int i = 0; i < g.n[0]; ++i) {
            const double x[3] = {g.centre(0, i), g.centre(1, j), g.centre(2, k)};
            double p = 0;
            for (int d = 0; d < 3; ++d) p += s_.rho * s_.gravity[d] * (x[d] - 0.5 * (g.lo[d] + g.hi(d)));
            p_[g.cell(i, j, k)] = p;
          }
      return;
    }
    for (int side = 0; side < 6; ++side)
      if (s_.sides[side].type == Boundary::pressure_outlet) {
        const int a = side / 2;
        double ref[3];
        for (int d = 0; d < 3; ++d) ref[d] = 0.5 * (g.lo[d] + g.hi(d));
        ref[a] = side % 2 ? g.hi(a) : g.lo[a];
        for (int k = 0; k < g.n[2]; ++k)
          for (int j = 0; j < g.n[1]; ++j)
            for (int i = 0; i < g.n[0]; ++i) {
              const double x[3] = {g.centre(0, i), g.centre(1, j), g.centre(2, k)};
              double p = s_.sides[side].pressure;
              for (int d = 0; d < 3; ++d) p += s_.rho * s_.gravity[d] * (x[d] - ref[d]);
              p_[g.cell(i, j, k)] = p;
            }
        return;
      }
  }

  const Settings& settings() const { return s_; }
  const MacGrid& grid() const { return s_.grid; }
  const std::vector<double>& eps() const { return eps_; }
  const std::vector<double>& pressure() const { return p_; }
  const std::vector<double>& u(int a) const { return u_[a]; }
  const std::vector<double>& K(int a) const { return K_[a]; }
  const std::vector<double>& Ku(int a) const { return Ku_[a]; }
  const std::vector<FaceKind>& kind(int a) const { return kind_[a]; }
  const std::vector<std::uint8_t>& blocked() const { return blocked_; }
  std::vector<double>& eps_mut() { return eps_; }
  std::vector<double>& K_mut(int a) { return K_[a]; }
  std::vector<double>& Ku_mut(int a) { return Ku_[a]; }
  std::vector<double>& u_mut(int a) { return u_[a]; }

  /// The state a checkpoint keeps (docs/checkpoint.md): the fields the next
  /// step starts from (void fraction now and before, pressure, face
  /// velocities), the last exchange's drag fields (the fields output shows
  /// them) and the gravity learnt at the first exchange. W and R are the
  /// SDK's StateWriter and StateReader.
  template <class W>
  void save(W& w) const {
    w.put(eps_);
    w.put(eps_old_);
    w.put(p_);
    for (int a = 0; a < 3; ++a) {
      w.put(u_[a]);
      w.put(K_[a]);
      w.put(Ku_[a]);
    }
    w.put(s_.gravity);
  }
  template <class R>
  void load(R& r) {
    const MacGrid& g = s_.grid;
    eps_ = r.template get_vector<double>(g.cells());
    eps_old_ = r.template get_vector<double>(g.cells());
    p_ = r.template get_vector<double>(g.cells());
    for (int a = 0; a < 3; ++a) {
      u_[a] = r.template get_vector<double>(g.faces(a));
      K_[a] = r.template get_vector<double>(g.faces(a));
      Ku_[a] = r.template get_vector<double>(g.faces(a));
    }
    s_.gravity = r.template get<std::array<double, 3>>();
  }

  /// Remember the current void fraction as eps^n before a new deposit.
  void keep_old_void_fraction() { eps_old_ = eps_; }

  /// Largest |u_a| over the faces and the moving walls, per axis.
  std::array<double, 3> max_speed() const {
    std::array<double, 3> m{0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      for (double v : u_[a]) m[a] = std::max(m[a], std::abs(v));
      for (const Boundary& b : s_.sides)
        if (b.type == Boundary::wall) m[a] = std::max(m[a], std::abs(b.velocity[a]));
    }
    return m;
  }

  /// One projection step of length dt. `frac` in (0, 1]: where the void
  /// fraction stands within the interval (eps^n + frac (eps^{n+1} - eps^n)),
  /// for sub-steps; eps_old_ is eps at the start of the interval.
  SolveReport step(double dt, double frac_from, double frac_to, const PressureSolver& solve) {
    const MacGrid& g = s_.grid;
    std::vector<double>& e0 = e0_;
    std::vector<double>& e1 = e1_;
    for (std::size_t c = 0; c < g.cells(); ++c) {
      e0[c] = eps_old_[c] + frac_from * (eps_[c] - eps_old_[c]);
      e1[c] = eps_old_[c] + frac_to * (eps_[c] - eps_old_[c]);
    }
    // the void fraction on every face at the interval's point this step ends at
    for (int a = 0; a < 3; ++a) {
      std::vector<double>& fe = fe1_[a];
      const auto& co = cells_of_[a];
      for (std::size_t f = 0; f < fe.size(); ++f) fe[f] = 0.5 * (e1[co[f][0]] + e1[co[f][1]]);
    }
    // an inlet prescribes the superficial velocity: eps u = U across the face
    // (the gas enters from below a bed as through a distributor)
    for (int a = 0; a < 3; ++a)
      for (const std::uint32_t f : inlet_faces_[a]) u_[a][f] = inlet_value_[a][f] / fe1_[a][f];
    // predictor, over the free faces
    auto half_slope = [](double d1, double d2) {  // the limited slope's half: van Leer's harmonic mean
      const double p = d1 * d2;
      return p > 0 ? p / (d1 + d2) : 0.0;
    };
    const bool van_leer = s_.advection == Advection::van_leer;
    const double ih[3] = {1.0 / g.h[0], 1.0 / g.h[1], 1.0 / g.h[2]};
    const double ih2[3] = {ih[0] * ih[0], ih[1] * ih[1], ih[2] * ih[2]};
    const double rho_dt = s_.rho / dt;
    for (int a = 0; a < 3; ++a) {
      const std::vector<double>& ua = u_[a];
      const std::vector<double>& fe = fe1_[a];
      us_[a] = ua;
      // one face's update: u_a's neighbours along b (near(b, side), far(b,
      // side) two faces out) and u_b's mean around the face (cross(b, m)),
      // read through the accessors of the face's kind of stencil
      auto update = [&](std::size_t f, bool outlet, unsigned far_ok, auto&& near, auto&& far, auto&& cross) {
        const double ef1 = fe[f];
        const double un = ua[f];
        // advection (upwind or van Leer) and diffusion of u_a
        double adv = 0, lap = 0;
        for (int b = 0, m = 0; b < 3; ++b) {
          double ub = un;
          if (b != a) ub = cross(b, m++);  // the mean of the b-faces around this one
          const double um = near(b, 0), up = near(b, 1);
          if (van_leer && (far_ok >> b & 1)) {
            const double u_mm = far(b, 0), u_pp = far(b, 1);
            const double hi_face = ub > 0 ? un + half_slope(un - um, up - un) : up - half_slope(u_pp - up, up - un);
            const double lo_face = ub > 0 ? um + half_slope(um - u_mm, un - um) : un - half_slope(up - un, un - um);
            adv += ub * (hi_face - lo_face) * ih[b];
          } else {
            adv += ub * (ub > 0 ? un - um : up - un) * ih[b];
          }
          lap += (up - 2 * un + um) * ih2[b];
        }
        const double gradp = outlet ? outlet_gradient(p_, a, f) : (p_[cells_of_[a][f][1]] - p_[cells_of_[a][f][0]]) * ih[a];
        const double R = -s_.rho * ef1 * adv + s_.mu * ef1 * lap - ef1 * gradp + s_.rho * ef1 * s_.gravity[a];
        // the drag implicit: u* (rho eps / dt + K) = rho eps u^n / dt + R + K u_s
        const double inv = 1.0 / (rho_dt * ef1 + K_[a][f]);
        us_[a][f] = (rho_dt * ef1 * un + R + Ku_[a][f]) * inv;
        A_[a][f] = ef1 * inv;  // eps dt / (rho eps + K dt)
      };
      for (const FaceStencil& st : stencil_[a])
        update(
            st.f, st.outlet, st.far_ok, [&](int b, int side) { return value(st.near[b][side], ua); },
            [&](int b, int side) { return value(st.far[b][side], ua); },
            [&](int b, int m) {
              double sum = 0;
              for (int q = 0; q < st.n_cross[m]; ++q) sum += u_[b][st.cross[m][q]];
              return sum * st.cross_weight[m];
            });
      // the faces whose neighbours are all inside the box and free: strides
      const PlainStrides& ps = plain_strides_[a];
      for (const PlainFace& pf : plain_[a]) {
        const std::size_t f = pf.f;
        update(
            f, false, 7u, [&](int b, int side) { return side ? ua[f + ps.along[b]] : ua[f - ps.along[b]]; },
            [&](int b, int side) { return side ? ua[f + 2 * ps.along[b]] : ua[f - 2 * ps.along[b]]; },
            [&](int b, int m) {  // the order FaceStencil::cross keeps: back along a, then along b
              const std::vector<double>& ub = u_[b];
              const std::size_t q = pf.cross[m], sb = ps.cross_b[m], sa = ps.cross_a[m];
              return (((ub[q] + ub[q + sb]) + ub[q + sa]) + ub[q + sa + sb]) * 0.25;
            });
      }
    }
    // pressure system: its pattern is the constructor's, its values this step's
    PressureSystem& sys = sys_;
    const double inv_dt = 1.0 / dt;
    for (std::size_t P = 0; P < n_unknowns_; ++P) {
      double div = 0, diag = 0;
      for (const CellFace& cf : cell_faces_[P]) {
        const int a = cf.axis;
        const double ef = fe1_[a][cf.f];
        const double flux = ef * us_[a][cf.f] * ih[a];
        div += cf.high ? flux : -flux;
        if (cf.kind == FaceKind::interior) {
          const double coef = ef * A_[a][cf.f] * ih2[a];
          diag += coef;
          if (cf.slot >= 0) sys.off[P][static_cast<std::size_t>(cf.slot)].second = -coef;
        } else if (cf.kind == FaceKind::outlet) {
          diag += 2.0 * ef * A_[a][cf.f] * ih2[a];  // p' = 0 half a cell beyond the last centre
        }
      }
      const std::size_t c = sys.cell_of[P];
      sys.diag[P] = diag;
      sys.rhs[P] = -(div + (e1[c] - e0[c]) * inv_dt);
    }
    if (closed_ && n_unknowns_ > 0) sys.rhs[0] = 0;  // p' = 0 in the first fluid cell (its row and column left out)
    {
      // the flow's own rate of strain (or 1 mm/s over a cell at rest), over
      // the whole system: the solve stops at the tolerance times this, so a
      // nearly divergence-free predictor is not iterated on to round-off
      const auto um = max_speed();
      double rate = 0, hmin = g.h[0];
      for (int a = 0; a < 3; ++a) {
        rate += um[a] / g.h[a];
        hmin = std::min(hmin, g.h[a]);
      }
      sys.reference_norm = std::sqrt(static_cast<double>(n_unknowns_)) * (rate + 1e-3 / hmin);
    }
    std::vector<double>& pc = pc_;
    std::fill(pc.begin(), pc.end(), 0.0);
    const SolveReport rep = solve(sys, pc);
    // correction, over the free faces: the interior ones, then the outlets
    for (int a = 0; a < 3; ++a) {
      for (const std::uint32_t f : interior_faces_[a]) {
        const std::size_t lo = cells_of_[a][f][0], hi = cells_of_[a][f][1];
        u_[a][f] = us_[a][f] - A_[a][f] * (pc[unknown_[hi]] - pc[unknown_[lo]]) / g.h[a];
      }
      for (const auto& [f, low] : outlet_faces_[a]) {  // p' = 0 beyond the outlet, half a cell from the cell's centre
        const std::size_t c = cells_of_[a][f][0];
        if (low)
          u_[a][f] = us_[a][f] - A_[a][f] * (pc[unknown_[c]] - 0.0) / (0.5 * g.h[a]);
        else
          u_[a][f] = us_[a][f] - A_[a][f] * (0.0 - pc[unknown_[c]]) / (0.5 * g.h[a]);
      }
    }
    for (std::size_t c = 0; c < g.cells(); ++c)
      if (!blocked_[c]) p_[c] += pc[unknown_[c]];
    return rep;
  }

  /// Gradient of the pressure on the face grid of axis a (for the particles'
  /// pressure-gradient force), into G: the face difference where the face is
  /// free, the nearest free face's along a where it is fixed (a wall has the
  /// gradient of the fluid beside it, e.g. the hydrostatic one), 0 where
  /// neither neighbour along a is free.
  void pressure_gradient(int a, std::vector<double>& G) const {
    const MacGrid& g = s_.grid;
    G.assign(g.faces(a), 0.0);
    for (const std::uint32_t f : interior_faces_[a]) G[f] = (p_[cells_of_[a][f][1]] - p_[cells_of_[a][f][0]]) / g.h[a];
    for (const auto& of : outlet_faces_[a]) G[of.first] = outlet_gradient(p_, a, of.first);
    for (const auto& [f, from] : gradient_copies_[a]) G[f] = G[from];
  }

  /// Cell-centred velocity (mean of the two faces along each axis).
  void cell_velocity(std::vector<double>& out) const {
    const MacGrid& g = s_.grid;
    out.assign(3 * g.cells(), 0.0);
    for (int k = 0; k < g.n[2]; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i) {
          const std::size_t c = g.cell(i, j, k);
          for (int a = 0; a < 3; ++a) {
            int hi[3] = {i, j, k};
            hi[a] += 1;
            out[3 * c + a] = 0.5 * (u_[a][g.face(a, i, j, k)] + u_[a][g.face(a, hi[0], hi[1], hi[2])]);
          }
        }
  }

  /// div(eps u) + d(eps)/dt of the last step's end state, per fluid cell
  /// (the residual continuity leaves after the projection), as the largest
  /// |value| times the cell's time scale dt: a dimensionless check.
  double continuity_residual(double dt) const {
    const MacGrid& g = s_.grid;
    double worst = 0;
    for (int k = 0; k < g.n[2]; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i) {
          const std::size_t c = g.cell(i, j, k);
          if (blocked_[c]) continue;
          double div = (eps_[c] - eps_old_[c]) / dt;
          for (int a = 0; a < 3; ++a)
            for (int s = 0; s < 2; ++s) {
              int fi[3] = {i, j, k};
              fi[a] += s;
              div += (s ? 1.0 : -1.0) * face_eps(eps_, a, fi[0], fi[1], fi[2]) * u_[a][g.face(a, fi[0], fi[1], fi[2])] / g.h[a];
            }
          worst = std::max(worst, std::abs(div) * dt);
        }
    return worst;
  }

  template <class F>
  void for_faces(int a, F&& fn) const {
    const MacGrid& g = s_.grid;
    for (int k = 0; k < g.fn(a, 2); ++k)
      for (int j = 0; j < g.fn(a, 1); ++j)
        for (int i = 0; i < g.fn(a, 0); ++i) fn(i, j, k, g.face(a, i, j, k));
  }

  /// The value of face f of axis a, which the step does not solve for (a
  /// wall's or an inlet's), at the end of the interval under way: 0 on a wall;
  /// on an inlet U / eps with the interval's end void fraction (the step sets
  /// eps u = U there).
  double fixed_value(int a, std::size_t f) const {
    if (kind_[a][f] != FaceKind::inlet) return 0.0;
    const MacGrid& g = s_.grid;
    const std::size_t n0 = static_cast<std::size_t>(g.fn(a, 0)), n1 = static_cast<std::size_t>(g.fn(a, 1));
    const int i = static_cast<int>(f % n0), j = static_cast<int>((f / n0) % n1), k = static_cast<int>(f / (n0 * n1));
    return inlet_value_[a][f] / face_eps(eps_, a, i, j, k);
  }

  /// The force of the box's no-slip side walls on the fluid [N]: for each
  /// face next to such a wall and tangential to it, the viscous term the
  /// step applies there towards the wall, mu eps (u_ghost - u) / h^2 over the
  /// face's control volume, with the wall's ghost u_ghost = 2 U_wall - u.
  std::array<double, 3> wall_shear() const {
    const MacGrid& g = s_.grid;
    std::array<double, 3> F{0, 0, 0};
    const double V = g.cell_volume();
    for (int a = 0; a < 3; ++a)
      for_faces(a, [&](int i, int j, int k, std::size_t f) {
        const FaceKind kd = kind_[a][f];
        if (kd != FaceKind::interior && kd != FaceKind::outlet) return;
        const int idx[3] = {i, j, k};
        for (int b = 0; b < 3; ++b) {
          if (b == a) continue;
          for (int side = 0; side < 2; ++side) {
            if (idx[b] != (side ? g.fn(a, b) - 1 : 0) || s_.sides[2 * b + side].type != Boundary::wall) continue;
            const double wall_u = s_.sides[2 * b + side].velocity[a];
            F[a] += s_.mu * face_eps(eps_, a, i, j, k) * 2.0 * (wall_u - u_[a][f]) / (g.h[b] * g.h[b]) * V;
          }
        }
      });
    return F;
  }

  /// Face (i, j, k) of axis a lies inside an obstacle: the cells on both of
  /// its sides are blocked (or one is blocked and the other beyond the box).
  /// Its u_a is not a flow value; a tangential neighbour mirrors it instead.
  bool solid_face(int a, int i, int j, int k) const {
    const MacGrid& g = s_.grid;
    const int idx[3] = {i, j, k};
    int l[3] = {i, j, k};
    l[a] -= 1;
    const bool hi_solid = idx[a] == g.n[a] || blocked_[g.cell(i, j, k)] != 0;
    const bool lo_solid = idx[a] == 0 || blocked_[g.cell(l[0], l[1], l[2])] != 0;
    const bool any_blocked = (idx[a] < g.n[a] && blocked_[g.cell(i, j, k)] != 0) ||
                             (idx[a] > 0 && blocked_[g.cell(l[0], l[1], l[2])] != 0);
    return hi_solid && lo_solid && any_blocked;
  }

  /// Void fraction on face (i, j, k) of axis a: the mean of the cells on its
  /// two sides, the inner cell's on the boundary.
  double face_eps(const std::vector<double>& e, int a, int i, int j, int k) const {
    const MacGrid& g = s_.grid;
    const int idx[3] = {i, j, k};
    int l[3] = {i, j, k};
    l[a] -= 1;
    if (idx[a] == 0) return e[g.cell(i, j, k)];
    if (idx[a] == g.n[a]) return e[g.cell(l[0], l[1], l[2])];
    return 0.5 * (e[g.cell(i, j, k)] + e[g.cell(l[0], l[1], l[2])]);
  }

 private:
  void classify_faces() {
    const MacGrid& g = s_.grid;
    for (int a = 0; a < 3; ++a) inlet_value_[a].assign(g.faces(a), 0.0);
    for (int a = 0; a < 3; ++a)
      for_faces(a, [&](int i, int j, int k, std::size_t f) {
        const int idx[3] = {i, j, k};
        if (idx[a] == 0 || idx[a] == g.n[a]) {
          const int side = 2 * a + (idx[a] == 0 ? 0 : 1);
          const Boundary& b = s_.sides[side];
          int in[3] = {i, j, k};
          if (idx[a] == g.n[a]) in[a] -= 1;
          const bool inner_blocked = blocked_[g.cell(in[0], in[1], in[2])] != 0;
          if (inner_blocked || b.type == Boundary::wall || b.type == Boundary::slip_wall) {
            kind_[a][f] = FaceKind::wall;
          } else if (b.type == Boundary::pressure_outlet) {
            kind_[a][f] = FaceKind::outlet;
          } else {
            bool inside = true;
            if (b.patch)
              for (int d = 0; d < 3; ++d) {
                if (d == a) continue;
                const double x = g.centre(d, idx[d]);
                inside = inside && x >= b.patch_lo[d] && x <= b.patch_hi[d];
              }
            kind_[a][f] = inside ? FaceKind::inlet : FaceKind::wall;
            if (inside) {
              double shape = 1;
              if (b.parabolic)
                for (int d = 0; d < 3; ++d) {
                  if (d == a || g.n[d] < 2) continue;
                  const double lo = b.patch ? b.patch_lo[d] : g.lo[d], hi = b.patch ? b.patch_hi[d] : g.hi(d);
                  const double sd = hi > lo ? (g.centre(d, idx[d]) - lo) / (hi - lo) : 0.5;
                  shape *= 4 * sd * (1 - sd);
                }
              inlet_value_[a][f] = b.velocity[a] * shape;
            }
          }
          return;
        }
        int l[3] = {i, j, k};
        l[a] -= 1;
        if (blocked_[g.cell(i, j, k)] || blocked_[g.cell(l[0], l[1], l[2])]) kind_[a][f] = FaceKind::wall;
      });
  }

  /// p gradient along a at a free face.
  double face_gradient(const std::vector<double>& p, int a, int i, int j, int k, FaceKind kd) const {
    const MacGrid& g = s_.grid;
    const int idx[3] = {i, j, k};
    int l[3] = {i, j, k};
    l[a] -= 1;
    if (kd == FaceKind::outlet) {
      const int side = 2 * a + (idx[a] == 0 ? 0 : 1);
      const double pb = s_.sides[side].pressure;
      if (idx[a] == 0) return (p[g.cell(i, j, k)] - pb) / (0.5 * g.h[a]);
      return (pb - p[g.cell(l[0], l[1], l[2])]) / (0.5 * g.h[a]);
    }
    return (p[g.cell(i, j, k)] - p[g.cell(l[0], l[1], l[2])]) / g.h[a];
  }

  /// u_a at a face near another, as (-)u_a[idx] + offsets_[offset]: a
  /// neighbour inside the box, or a boundary's ghost value (a wall's or an
  /// inlet's 2 U - u mirrored, a slip wall's u, an outlet's copy).
  struct Rule {
    std::uint32_t idx = 0;
    bool negate = false;
    std::uint8_t offset = 0;  ///< into offsets_, whose entry 0 is 0
  };
  double value(const Rule& r, const std::vector<double>& u) const {
    return (r.negate ? -u[r.idx] : u[r.idx]) + offsets_[r.offset];
  }

  /// What the predictor reads around a free face of axis a, built once.
  struct FaceStencil {
    std::uint32_t f = 0;
    Rule near[3][2];                    ///< u_a one face back and ahead along b
    Rule far[3][2];                     ///< two faces back and ahead (van Leer's stencil), where far_ok has bit b
    std::uint32_t cross[2][4] = {};     ///< the b-faces whose mean is u_b here, for the two b != a in order
    std::uint8_t n_cross[2] = {0, 0};
    double cross_weight[2] = {0, 0};    ///< 1 / n_cross (0 where none)
    std::uint8_t far_ok = 0;
    bool outlet = false;
  };
  /// A free face whose neighbours along every axis (two out, for van Leer)
  /// are faces of the box read as they are, and whose u_b means have four
  /// faces each: read by strides (PlainStrides) instead of rules.
  struct PlainFace {
    std::uint32_t f = 0;
    std::uint32_t cross[2] = {0, 0};  ///< per b != a in order: the first of the four b-faces (back along a)
  };
  /// Strides of axis a's plain faces: along[b] in the a-face grid; for the
  /// two b != a in order, the b-face grid's strides along b and along a.
  struct PlainStrides {
    std::size_t along[3] = {0, 0, 0};
    std::size_t cross_b[2] = {0, 0}, cross_a[2] = {0, 0};
  };
  /// One of a fluid cell's six faces, for the pressure system.
  struct CellFace {
    std::uint32_t f = 0;
    std::uint8_t axis = 0;
    bool high = false;                     ///< the face on the cell's high side along axis
    FaceKind kind = FaceKind::wall;
    std::int32_t slot = -1;                ///< its entry in the row's off-diagonals (interior faces; -1: none)
  };

  /// The offset's index in offsets_, appended if new.
  std::uint8_t offset_code(double v) {
    for (std::size_t q = 0; q < offsets_.size(); ++q)
      if (offsets_[q] == v) return static_cast<std::uint8_t>(q);
    offsets_.push_back(v);
    return static_cast<std::uint8_t>(offsets_.size() - 1);
  }

  /// The rule for u_a at the face one step along b (dir -1 or +1) from face
  /// (i, j, k) of axis a, with the boundary's ghost value beyond the box: a
  /// wall mirrors the tangential velocity about its own (no slip), an inlet
  /// about its velocity, a slip wall and an outlet copy it.
  Rule neighbour_rule(int a, int b, int dir, int i, int j, int k) {
    const MacGrid& g = s_.grid;
    int q[3] = {i, j, k};
    q[b] += dir;
    const auto here = static_cast<std::uint32_t>(g.face(a, i, j, k));
    if (q[b] >= 0 && q[b] < g.fn(a, b)) {
      // a tangential face inside an obstacle: mirrored, so the no-slip wall
      // lies on the obstacle's face, half a cell from either node
      if (b != a && solid_face(a, q[0], q[1], q[2])) return {here, true, 0};
      return {static_cast<std::uint32_t>(g.face(a, q[0], q[1], q[2])), false, 0};
    }
    if (b == a) return {here, false, 0};  // beyond the last normal face: zero gradient
    const Boundary& bd = s_.sides[2 * b + (dir > 0 ? 1 : 0)];
    switch (bd.type) {
      case Boundary::wall:
      case Boundary::velocity_inlet: return {here, true, offset_code(2 * bd.velocity[a])};
      default: return {here, false, 0};
    }
  }

  /// The rules for u_a two faces back (out[0]) and ahead (out[1]) along b
  /// from face (i, j, k) of axis a, for van Leer's stencil: beyond the box,
  /// along a the last face's (zero gradient), across it the mirror image of
  /// the face as far inside, by the side's kind as neighbour_rule() takes it.
  /// False when an obstacle lies within two faces (upwind there).
  bool far_rules(int a, int b, int i, int j, int k, Rule out[2]) {
    const MacGrid& g = s_.grid;
    const int idx[3] = {i, j, k}, n = g.fn(a, b);
    for (int s = 0; s < 2; ++s) {
      const int dir = s ? 1 : -1;
      int q[3] = {i, j, k};
      if (b != a) {  // an obstacle within two faces: upwind
        for (int step = 1; step <= 2; ++step) {
          q[b] = idx[b] + dir * step;
          if (q[b] >= 0 && q[b] < n && solid_face(a, q[0], q[1], q[2])) return false;
        }
      }
      q[b] = idx[b] + 2 * dir;
      if (q[b] >= 0 && q[b] < n) {
        out[s] = {static_cast<std::uint32_t>(g.face(a, q[0], q[1], q[2])), false, 0};
        continue;
      }
      const int inside = std::clamp(q[b], 0, n - 1);
      if (b == a) {
        q[b] = inside;
        out[s] = {static_cast<std::uint32_t>(g.face(a, q[0], q[1], q[2])), false, 0};
        continue;
      }
      // the mirror image (on an axis of one cell, the face itself)
      q[b] = std::clamp(q[b] < 0 ? -1 - q[b] : 2 * n - 1 - q[b], 0, n - 1);
      const Boundary& bd = s_.sides[2 * b + s];
      if (bd.type == Boundary::pressure_outlet) q[b] = inside;  // zero gradient
      const auto m = static_cast<std::uint32_t>(g.face(a, q[0], q[1], q[2]));
      if (bd.type == Boundary::wall || bd.type == Boundary::velocity_inlet)
        out[s] = {m, true, offset_code(2 * bd.velocity[a])};
      else
        out[s] = {m, false, 0};
    }
    return true;
  }

  /// Whether a free face's stencil is what plain_strides_ reads: every
  /// neighbour rule (and, with van Leer, every far rule) the face a stride
  /// away as it is, and four b-faces in each u_b mean at the strides.
  bool plain(int a, const FaceStencil& st) const {
    if (st.outlet) return false;
    const PlainStrides& ps = plain_strides_[a];
    const bool van_leer = s_.advection == Advection::van_leer;
    if (van_leer && st.far_ok != 7) return false;
    auto is = [](const Rule& r, std::size_t idx) { return !r.negate && r.offset == 0 && r.idx == idx; };
    for (int b = 0; b < 3; ++b) {
      const std::size_t s = ps.along[b];
      if (st.f < 2 * s || !is(st.near[b][0], st.f - s) || !is(st.near[b][1], st.f + s)) return false;
      if (van_leer && (!is(st.far[b][0], st.f - 2 * s) || !is(st.far[b][1], st.f + 2 * s))) return false;
    }
    for (int m = 0; m < 2; ++m) {
      const std::size_t q = st.cross[m][0], sb = ps.cross_b[m], sa = ps.cross_a[m];
      if (st.n_cross[m] != 4 || st.cross[m][1] != q + sb || st.cross[m][2] != q + sa || st.cross[m][3] != q + sa + sb)
        return false;
    }
    return true;
  }

  /// The stencils (FaceStencil per free face), the cells beside every face,
  /// the inlet faces, and the pressure system's pattern (CellFace per fluid
  /// cell; the off-diagonals in the order the faces are visited, none to or
  /// from a closed box's pinned first cell).
  void build_stencils() {
    const MacGrid& g = s_.grid;
    offsets_.assign(1, 0.0);
    for (int a = 0; a < 3; ++a) {
      cells_of_[a].resize(g.faces(a));
      inlet_faces_[a].clear();
      interior_faces_[a].clear();
      outlet_faces_[a].clear();
      stencil_[a].clear();
      plain_[a].clear();
      {
        PlainStrides& ps = plain_strides_[a];
        for (int b = 0; b < 3; ++b) ps.along[b] = g.face(a, b == 0, b == 1, b == 2);
        for (int b = 0, m = 0; b < 3; ++b) {
          if (b == a) continue;
          ps.cross_b[m] = g.face(b, b == 0, b == 1, b == 2);
          ps.cross_a[m] = g.face(b, a == 0, a == 1, a == 2);
          ++m;
        }
      }
      us_[a].assign(g.faces(a), 0.0);
      A_[a].assign(g.faces(a), 0.0);  // stays 0 on the fixed faces; the step writes the free ones
      fe1_[a].assign(g.faces(a), 0.0);
      for_faces(a, [&](int i, int j, int k, std::size_t f) {
        const int idx[3] = {i, j, k};
        int l[3] = {i, j, k};
        l[a] -= 1;
        const auto lo = static_cast<std::uint32_t>(idx[a] == 0 ? g.cell(i, j, k) : g.cell(l[0], l[1], l[2]));
        const auto hi = static_cast<std::uint32_t>(idx[a] == g.n[a] ? g.cell(l[0], l[1], l[2]) : g.cell(i, j, k));
        cells_of_[a][f] = {lo, hi};
        const FaceKind kd = kind_[a][f];
        if (kd == FaceKind::inlet) inlet_faces_[a].push_back(static_cast<std::uint32_t>(f));
        if (kd == FaceKind::interior) interior_faces_[a].push_back(static_cast<std::uint32_t>(f));
        if (kd == FaceKind::outlet) outlet_faces_[a].push_back({static_cast<std::uint32_t>(f), idx[a] == 0});
        if (kd != FaceKind::interior && kd != FaceKind::outlet) return;
        FaceStencil st;
        st.f = static_cast<std::uint32_t>(f);
        st.outlet = kd == FaceKind::outlet;
        for (int b = 0, m = 0; b < 3; ++b) {
          st.near[b][0] = neighbour_rule(a, b, -1, i, j, k);
          st.near[b][1] = neighbour_rule(a, b, +1, i, j, k);
          if (far_rules(a, b, i, j, k, st.far[b])) st.far_ok |= static_cast<std::uint8_t>(1u << b);
          if (b == a) continue;
          // u_b here: the mean of the (up to) four b-faces around the face
          for (int da = -1; da <= 0; ++da)
            for (int db = 0; db <= 1; ++db) {
              int q[3] = {i, j, k};
              q[a] += da;
              q[b] += db;
              if (q[a] < 0 || q[a] >= g.fn(b, a)) continue;
              st.cross[m][st.n_cross[m]++] = static_cast<std::uint32_t>(g.face(b, q[0], q[1], q[2]));
            }
          ++m;
        }
        for (int q = 0; q < 2; ++q) st.cross_weight[q] = st.n_cross[q] ? 1.0 / st.n_cross[q] : 0.0;
        if (plain(a, st)) {
          plain_[a].push_back({st.f, {st.cross[0][0], st.cross[1][0]}});
          return;
        }
        stencil_[a].push_back(st);
      });
      // a fixed face's pressure gradient: the free face's one step up along a, else one step down
      gradient_copies_[a].clear();
      for_faces(a, [&](int i, int j, int k, std::size_t f) {
        const auto free = [&](std::size_t q) { return kind_[a][q] == FaceKind::interior || kind_[a][q] == FaceKind::outlet; };
        if (free(f)) return;
        const int idx[3] = {i, j, k};
        for (int step : {+1, -1}) {
          int q[3] = {idx[0], idx[1], idx[2]};
          q[a] += step;
          if (q[a] < 0 || q[a] > g.n[a]) continue;
          const std::size_t fq = g.face(a, q[0], q[1], q[2]);
          if (free(fq)) {
            gradient_copies_[a].push_back({static_cast<std::uint32_t>(f), static_cast<std::uint32_t>(fq)});
            return;
          }
        }
      });
    }
    e0_.assign(g.cells(), 0.0);
    e1_.assign(g.cells(), 0.0);
    pc_.assign(n_unknowns_, 0.0);
    sys_ = PressureSystem{};
    sys_.pattern_id = new_pattern_id();
    sys_.n = g.n;
    sys_.cell_of.assign(n_unknowns_, 0);
    sys_.diag.assign(n_unknowns_, 0.0);
    sys_.off.assign(n_unknowns_, {});
    sys_.rhs.assign(n_unknowns_, 0.0);
    cell_faces_.assign(n_unknowns_, {});
    for (int k = 0; k < g.n[2]; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i) {
          const std::size_t c = g.cell(i, j, k);
          if (blocked_[c]) continue;
          const std::size_t P = unknown_[c];
          sys_.cell_of[P] = c;
          int slot = 0;
          for (int a = 0; a < 3; ++a)
            for (int s = 0; s < 2; ++s) {  // s = 0: the face on the low side, 1: the high side
              int fi[3] = {i, j, k};
              fi[a] += s;
              CellFace& cf = cell_faces_[P][2 * a + s];
              cf.f = static_cast<std::uint32_t>(g.face(a, fi[0], fi[1], fi[2]));
              cf.axis = static_cast<std::uint8_t>(a);
              cf.high = s == 1;
              cf.kind = kind_[a][cf.f];
              if (cf.kind != FaceKind::interior) continue;
              int ni[3] = {i, j, k};
              ni[a] += s ? 1 : -1;
              const std::size_t nb = unknown_[g.cell(ni[0], ni[1], ni[2])];
              if (closed_ && (P == 0 || nb == 0)) continue;  // the pinned cell's row and column
              cf.slot = slot++;
              sys_.off[P].push_back({nb, 0.0});
            }
        }
  }

  /// eps on face f of axis a: the mean of the cells on its two sides, the
  /// inner cell's on the box's boundary (face_eps()).
  double face_eps_of(const std::vector<double>& e, int a, std::size_t f) const {
    return 0.5 * (e[cells_of_[a][f][0]] + e[cells_of_[a][f][1]]);
  }

  /// The pressure gradient on outlet face f of axis a (face_gradient()).
  double outlet_gradient(const std::vector<double>& p, int a, std::size_t f) const {
    const MacGrid& g = s_.grid;
    const std::size_t n0 = static_cast<std::size_t>(g.fn(a, 0)), n1 = static_cast<std::size_t>(g.fn(a, 1));
    return face_gradient(p, a, static_cast<int>(f % n0), static_cast<int>((f / n0) % n1), static_cast<int>(f / (n0 * n1)),
                         FaceKind::outlet);
  }

  Settings s_;
  bool closed_ = false;  ///< no outlet: the pressure correction pinned in the first fluid cell
  std::vector<std::uint8_t> blocked_;
  std::vector<double> eps_, eps_old_, p_;
  std::array<std::vector<double>, 3> u_, K_, Ku_, inlet_value_;
  std::array<std::vector<FaceKind>, 3> kind_;
  std::vector<std::size_t> unknown_;
  std::size_t n_unknowns_ = 0;
  // built once by build_stencils()
  std::vector<double> offsets_{0.0};
  std::array<std::vector<FaceStencil>, 3> stencil_;
  std::array<std::vector<std::array<std::uint32_t, 2>>, 3> cells_of_;  ///< per face: the cells below and above along a
  std::array<std::vector<std::uint32_t>, 3> inlet_faces_, interior_faces_;
  std::array<std::vector<std::pair<std::uint32_t, bool>>, 3> outlet_faces_;  ///< with: on the box's low side
  std::vector<std::array<CellFace, 6>> cell_faces_;  ///< per unknown
  // the step's work arrays, kept between steps
  std::vector<double> e0_, e1_, pc_;
  std::array<std::vector<PlainFace>, 3> plain_;  ///< the free faces read by strides (the rest: stencil_)
  std::array<PlainStrides, 3> plain_strides_;
  std::array<std::vector<std::pair<std::uint32_t, std::uint32_t>>, 3> gradient_copies_;  ///< (fixed face, free face it copies)
  std::array<std::vector<double>, 3> us_, A_, fe1_;  ///< fe1_: eps on the faces where the step ends
  PressureSystem sys_;
};

}  // namespace domel::plugins::fluid
