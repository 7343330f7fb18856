// SPDX-License-Identifier: MIT
// Fluid-particle drag laws for DEM-CFD coupling (docs/physics.md §7), their
// coarse-grain (parcel) scaling (physics.md §6.3) and the analytic reference
// results the validation tests compare against (terminal velocities, Ergun
// pressure drop, minimum fluidisation velocities).
//
// Header-only, standard library only (it is compiled into a plugin built
// against the SDK, so nothing from platform/ is included). Formulas are taken
// from the cited publications; no code of CFDEMcoupling, OpenFOAM or LIGGGHTS
// was used.
//
// Convention ("model A" of Anderson & Jackson, physics.md §7): beta() is the
// drag coefficient of ONE particle, in kg/s, such that the drag force on it is
//
//     F_d = beta * (u_f - v_p)
//
// with u_f the interstitial (not superficial) fluid velocity. F_d is the drag
// alone: no division by eps ("model B") and no buoyancy or pressure-gradient
// force, which the caller adds separately.
//
// Symbols: d particle diameter [m], eps fluid volume fraction (voidage) in
// (0, 1], phi = 1 - eps solid fraction, U = |u_f - v_p| slip speed [m/s]
// (the sign of the slip argument is ignored), rho_f fluid density [kg/m^3],
// mu dynamic viscosity [Pa s], Re = eps rho_f d U / mu.
//
// Every law is written so that it stays finite and continuous as U -> 0
// (no 1/Re appears anywhere); the limits are given next to each law.
//
// Errors: std::invalid_argument for d <= 0, mu <= 0, rho_f <= 0, eps outside
// (0, 1] and (beta_parcel with scaling) alpha <= 0, NaN included. Nothing
// else throws.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace domel::plugins::fluid {

enum class DragLaw { schiller_naumann, di_felice, gidaspow, beetstra };

// The configuration name of a law ("unknown" for a value outside the enum).
inline const char* name(DragLaw law) {
  switch (law) {
    case DragLaw::schiller_naumann:
      return "schiller_naumann";
    case DragLaw::di_felice:
      return "di_felice";
    case DragLaw::gidaspow:
      return "gidaspow";
    case DragLaw::beetstra:
      return "beetstra";
  }
  return "unknown";
}

// The law named `text` (exact, case-sensitive match of the names above), or
// nullopt.
inline std::optional<DragLaw> drag_law_from_name(const std::string& text) {
  for (DragLaw law : {DragLaw::schiller_naumann, DragLaw::di_felice, DragLaw::gidaspow, DragLaw::beetstra}) {
    if (text == name(law)) return law;
  }
  return std::nullopt;
}

namespace detail {

inline constexpr double kPi = 3.14159265358979323846;

inline void require_positive(double value, const char* what) {
  if (!(value > 0.0)) throw std::invalid_argument(std::string(what) + " must be positive");
}

inline void require_voidage(double eps) {
  if (!(eps > 0.0 && eps <= 1.0)) throw std::invalid_argument("voidage eps must lie in (0, 1]");
}

inline void check_fluid(double d, double rho_f, double mu) {
  require_positive(d, "particle diameter d");
  require_positive(rho_f, "fluid density rho_f");
  require_positive(mu, "fluid viscosity mu");
}

// eps rho_f d U / mu, arguments already checked, U >= 0.
inline double reynolds_unchecked(double eps, double rho_f, double d, double speed, double mu) {
  return eps * rho_f * d * speed / mu;
}

// Schiller & Naumann (1933) correction factor 1 + 0.15 Re^0.687 (Re < 1000).
inline double schiller_naumann_factor(double re) { return 1.0 + 0.15 * std::pow(re, 0.687); }

// The Schiller-Naumann switch: C_d = 24/Re (1 + 0.15 Re^0.687) below, 0.44 at
// and above (the source's curve jumps by about 0.4 % there).
inline constexpr double kNewtonRe = 1000.0;
inline constexpr double kNewtonCd = 0.44;

// Single-sphere Schiller-Naumann coefficient beta = (pi/8) C_d rho_f d^2 U with
// Re = rho_f d U / mu (eps = 1), written without 1/Re:
//   Re < 1000:  beta = 3 pi mu d (1 + 0.15 Re^0.687)      (-> 3 pi mu d, Stokes, as U -> 0)
//   Re >= 1000: beta = (pi/8) 0.44 rho_f d^2 U
inline double schiller_naumann_beta(double d, double speed, double rho_f, double mu) {
  const double re = reynolds_unchecked(1.0, rho_f, d, speed, mu);
  if (re < kNewtonRe) return 3.0 * kPi * mu * d * schiller_naumann_factor(re);
  return kPi / 8.0 * kNewtonCd * rho_f * d * d * speed;
}

}  // namespace detail

// Particle Reynolds number Re = eps rho_f d |slip| / mu with the interstitial
// slip. Schiller-Naumann is a single-sphere law: beta() evaluates its Re with
// eps = 1 itself, whatever eps the caller passes (the caller never needs to).
inline double reynolds(double eps, double rho_f, double d, double slip, double mu) {
  detail::require_voidage(eps);
  detail::check_fluid(d, rho_f, mu);
  return detail::reynolds_unchecked(eps, rho_f, d, std::fabs(slip), mu);
}

// Di Felice (1994) exponent chi(Re) = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2).
// chi -> 3.7 as Re -> 0 and as Re -> infinity; minimum 3.05 at Re = 10^1.5.
// Re = 0 returns the limit 3.7 (exp(-(log Re)^2) vanishes faster than any
// power of Re, so chi is continuous there).
inline double di_felice_chi(double re) {
  if (!(re > 0.0)) return 3.7;
  const double x = 1.5 - std::log10(re);
  return 3.7 - 0.65 * std::exp(-0.5 * x * x);
}

// Beetstra, van der Hoef & Kuipers (2007), AIChE J. 53:489, normalised drag
// F(eps, Re) = F_d / (3 pi mu d eps U):
//   F = 10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi))
//     + [0.413 Re / (24 eps^2)] [1/eps + 3 eps phi + 8.4 Re^-0.343] / [1 + 10^(3 phi) Re^-(1+4 phi)/2]
// The last term is evaluated as
//     0.413/(24 eps^2) [(1/eps + 3 eps phi) Re^(1+a) + 8.4 Re^(1+a-0.343)] / [Re^a + 10^(3 phi)],
// a = (1 + 4 phi)/2 (numerator and denominator multiplied by Re^a): every
// exponent is positive, so it is finite at Re = 0 (value 0) and does not
// overflow for tiny Re. As Re -> 0, F -> 10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi))
// (the Stokes-flow fit of van der Hoef, Beetstra & Kuipers 2005, J. Fluid
// Mech. 528:233), and that tends to 1 (isolated sphere, Stokes) as phi -> 0.
inline double beetstra_normalised_force(double eps, double re) {
  detail::require_voidage(eps);
  const double phi = 1.0 - eps;
  const double eps2 = eps * eps;
  const double stokes = 10.0 * phi / eps2 + eps2 * (1.0 + 1.5 * std::sqrt(phi));
  if (!(re > 0.0)) return stokes;
  const double a = 0.5 * (1.0 + 4.0 * phi);
  const double re_1a = std::pow(re, 1.0 + a);
  const double num = (1.0 / eps + 3.0 * eps * phi) * re_1a + 8.4 * std::pow(re, 1.0 + a - 0.343);
  const double den = std::pow(re, a) + std::pow(10.0, 3.0 * phi);
  return stokes + 0.413 / (24.0 * eps2) * num / den;
}

// Drag coefficient beta [kg/s] of one particle of diameter d: F_d = beta (u_f - v_p).
//
// schiller_naumann (Schiller & Naumann 1933; single sphere, eps ignored except
// for the range check, Re taken at eps = 1):
//   F = (pi/8) C_d rho_f d^2 U (u - v), C_d = 24/Re (1 + 0.15 Re^0.687) for Re < 1000, 0.44 above
//   beta = 3 pi mu d (1 + 0.15 Re^0.687)          Re < 1000
//   beta = (pi/8) 0.44 rho_f d^2 U                Re >= 1000
//   U -> 0: beta -> 3 pi mu d (Stokes).
//
// di_felice (Di Felice 1994, Int. J. Multiphase Flow 20:153):
//   F = (1/8) C_d rho_f pi d^2 U (u - v) eps^(2 - chi),  C_d = (0.63 + 4.8/sqrt(Re))^2,
//   chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2)
//   With U/Re = mu/(eps rho_f d):  C_d U = (0.63 sqrt(U) + 4.8 sqrt(mu/(eps rho_f d)))^2, so
//   beta = (pi/8) rho_f d^2 (0.63 sqrt(U) + 4.8 sqrt(mu/(eps rho_f d)))^2 eps^(2 - chi)
//   U -> 0: C_d U -> 23.04 mu/(eps rho_f d), chi -> 3.7, so
//           beta -> (23.04/8) pi mu d eps^-2.7 = 2.88 pi mu d eps^-2.7
//   (continuous; the departure from the limit grows like sqrt(U)).
//
// gidaspow (Gidaspow 1994: Ergun 1952 for eps <= 0.8, Wen & Yu 1966 above), per
// unit volume
//   eps <= 0.8: beta_E  = 150 phi^2 mu/(eps d^2) + 1.75 phi rho_f U / d
//   eps >  0.8: beta_WY = (3/4) C_d rho_f eps phi U / d eps^-2.65, Schiller-Naumann
//               C_d(Re) with Re = eps rho_f d U / mu (0.44 for Re >= 1000)
//   per particle beta = V_p beta_vol / phi, V_p = pi d^3/6. Simplified
//   analytically (phi cancels, so a lone particle at eps = 1 works):
//   eps <= 0.8: beta = V_p (150 phi mu/(eps d^2) + 1.75 rho_f U / d)
//               U -> 0: beta -> 25 pi phi mu d / eps
//   eps >  0.8: beta = 3 pi mu d (1 + 0.15 Re^0.687) eps^-2.65        Re < 1000
//               beta = (pi/8) 0.44 rho_f d^2 U eps^-1.65               Re >= 1000
//               U -> 0: beta -> 3 pi mu d eps^-2.65; at eps = 1 this is
//               exactly Schiller-Naumann.
//   The switch at eps = 0.8 is discontinuous, as in the source.
//
// beetstra (Beetstra, van der Hoef & Kuipers 2007, AIChE J. 53:489):
//   F = 3 pi mu d eps (u - v) F(eps, Re)  =>  beta = 3 pi mu d eps F(eps, Re),
//   F from beetstra_normalised_force().
//   U -> 0: beta -> 3 pi mu d eps (10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi)));
//           -> 3 pi mu d at eps = 1.
inline double beta(DragLaw law, double d, double eps, double slip, double rho_f, double mu) {
  detail::require_voidage(eps);
  detail::check_fluid(d, rho_f, mu);
  using detail::kPi;
  const double speed = std::fabs(slip);
  switch (law) {
    case DragLaw::schiller_naumann:
      return detail::schiller_naumann_beta(d, speed, rho_f, mu);
    case DragLaw::di_felice: {
      const double re = detail::reynolds_unchecked(eps, rho_f, d, speed, mu);
      const double root = 0.63 * std::sqrt(speed) + 4.8 * std::sqrt(mu / (eps * rho_f * d));
      return kPi / 8.0 * rho_f * d * d * root * root * std::pow(eps, 2.0 - di_felice_chi(re));
    }
    case DragLaw::gidaspow: {
      const double phi = 1.0 - eps;
      if (eps <= 0.8) {
        const double vp = kPi * d * d * d / 6.0;
        return vp * (150.0 * phi * mu / (eps * d * d) + 1.75 * rho_f * speed / d);
      }
      const double re = detail::reynolds_unchecked(eps, rho_f, d, speed, mu);
      if (re < detail::kNewtonRe) return 3.0 * kPi * mu * d * detail::schiller_naumann_factor(re) * std::pow(eps, -2.65);
      return kPi / 8.0 * detail::kNewtonCd * rho_f * d * d * speed * std::pow(eps, -1.65);
    }
    case DragLaw::beetstra: {
      const double re = detail::reynolds_unchecked(eps, rho_f, d, speed, mu);
      return 3.0 * kPi * mu * d * eps * beetstra_normalised_force(eps, re);
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// Coarse-grain (parcel) drag, Sakai & Koshizuka (2009) and physics.md §6.3: a
// parcel of diameter d_parcel = alpha d stands for alpha^3 original particles;
// with scaling its drag is alpha^3 times that of one original particle of
// diameter d_parcel/alpha at the same slip and voidage (Re uses the original
// diameter). Without scaling the parcel is treated as one large particle of
// diameter d_parcel (alpha unused). Consequence: with scaling a parcel has the
// original particle's terminal velocity; without it, in the Stokes regime, it
// falls alpha^2 times faster.
inline double beta_parcel(DragLaw law, double d_parcel, double alpha, bool scaling, double eps, double slip,
                          double rho_f, double mu) {
  if (!scaling) return beta(law, d_parcel, eps, slip, rho_f, mu);
  detail::require_positive(alpha, "coarse-graining ratio alpha");
  return alpha * alpha * alpha * beta(law, d_parcel / alpha, eps, slip, rho_f, mu);
}

// Whether (eps, Re) lies in the range the law's source fitted; `regime` names
// what is outside ("" when ok). Several findings are joined with "; ".
struct Validity {
  bool ok;
  std::string regime;
  double drag = 0;  ///< set by the caller: the drag force the law gives there [N]
};

// Ranges (Re = eps rho_f d U / mu as in beta(); for Schiller-Naumann the
// caller may pass either, the checks do not depend on Re there):
//  * schiller_naumann: a correlation for ONE sphere in an unbounded fluid, so
//    any eps < 0.9 is flagged (0.9 is a judgement call, not from the source:
//    at phi = 0.1 Beetstra's F is already about 2, i.e. the hindrance is no
//    longer small). Re >= 1000 with constant C_d = 0.44 (Newton regime) is
//    part of the law and is not flagged; above the drag crisis (Re ~ 2e5)
//    C_d drops, which no law here models, so Re > 2e5 is flagged.
//  * di_felice: Di Felice fitted data over roughly 1e-2 < Re < 1e4; the
//    voidage range of that data is usually quoted as about 0.4 <= eps < 1 (we
//    are not certain of the lower bound; eps < 0.4 is flagged as a caution).
//  * gidaspow: the Ergun branch (eps <= 0.8) is a packed-bed fit (Ergun's data
//    roughly 0.35 <= eps <= 0.8, the lower bound being approximate); eps < 0.3
//    is flagged as denser than any packed bed it was fitted to. Wen & Yu's
//    branch is Schiller-Naumann with the Richardson-Zaki-like eps^-2.65 and
//    is not flagged for eps > 0.8; Re >= 1000 is the Newton regime, not
//    flagged. The jump at eps = 0.8 is the law's, not a warning.
//  * beetstra: lattice-Boltzmann data for 0.1 <= phi <= 0.6 and Re up to 1000.
//    phi < 0.1 is flagged: the fit was not made there (its Re -> 0, phi -> 0
//    limit does give the isolated sphere, but the finite-Re isolated-sphere
//    behaviour was not part of the fit); phi > 0.6 and Re > 1000 are flagged.
// Re negative or NaN is reported as not ok.
inline Validity validity(DragLaw law, double eps, double re) {
  detail::require_voidage(eps);
  Validity out{true, {}};
  auto flag = [&out](const char* text) {
    out.ok = false;
    if (!out.regime.empty()) out.regime += "; ";
    out.regime += text;
  };
  if (!(re >= 0.0)) {
    flag("Reynolds number negative or not a number");
    return out;
  }
  switch (law) {
    case DragLaw::schiller_naumann:
      if (eps < 0.9) flag("dense suspension: Schiller-Naumann is a single-sphere law");
      if (re > 2e5) flag("Re > 2e5: beyond the drag crisis, constant C_d = 0.44 overestimates the drag");
      break;
    case DragLaw::di_felice:
      if (re <= 1e-2) flag("Re <= 1e-2: below the Reynolds range Di Felice fitted (1e-2 < Re < 1e4)");
      if (re >= 1e4) flag("Re >= 1e4: above the Reynolds range Di Felice fitted (1e-2 < Re < 1e4)");
      if (eps < 0.4) flag("eps < 0.4: denser than the data Di Felice fitted (about 0.4 <= eps < 1)");
      break;
    case DragLaw::gidaspow:
      if (eps < 0.3) flag("eps < 0.3: denser than the packed beds the Ergun branch was fitted to");
      break;
    case DragLaw::beetstra:
      // Compared through eps (eps > 0.9 is phi < 0.1): 1 - 0.9 rounds below 0.1.
      if (eps > 0.9) flag("dilute: phi < 0.1 is below the range Beetstra fitted (0.1 <= phi <= 0.6)");
      if (eps < 0.4) flag("phi > 0.6 is above the range Beetstra fitted (0.1 <= phi <= 0.6)");
      if (re > 1000.0) flag("Re > 1000 is above the Reynolds range Beetstra fitted (Re <= 1000)");
      break;
  }
  return out;
}

// ---------------------------------------------------------------------------
// Analytic references (used by the validation tests). Velocities are signed:
// positive along g, negative for a particle lighter than the fluid (it rises).

// Archimedes number Ar = rho_f (rho_p - rho_f) g d^3 / mu^2.
inline double archimedes(double d, double rho_p, double rho_f, double mu, double g) {
  detail::check_fluid(d, rho_f, mu);
  return rho_f * (rho_p - rho_f) * g * d * d * d / (mu * mu);
}

// Stokes terminal velocity (rho_p - rho_f) g d^2 / (18 mu).
inline double stokes_terminal_velocity(double d, double rho_p, double rho_f, double mu, double g) {
  detail::check_fluid(d, rho_f, mu);
  return (rho_p - rho_f) * g * d * d / (18.0 * mu);
}

// Terminal velocity of a single sphere under Schiller-Naumann drag: the force
// balance beta(v) v = (rho_p - rho_f) V_p g gives, with Re = rho_f d v / mu,
//   18 Re (1 + 0.15 Re^0.687) = Ar      (Re < 1000)
//   0.33 Re^2 = Ar, i.e. (3/4) 0.44 Re^2 = Ar   (Re >= 1000)
// The left side of the first is convex and increasing in Re; Newton from the
// Stokes value Re = Ar/18 (which lies above the root) decreases monotonically
// to it, stopped at a step below 1e-15 Re (quadratic convergence, so the
// result is accurate to about 1e-15 relative). The source's C_d jumps at
// Re = 1000, so for 18000 (1 + 0.15 1000^0.687) <= Ar < 330000 (a 0.4 %
// window) no exact balance exists: there the function returns the switch
// point Re = 1000 (the drag jumps across the weight there).
inline double schiller_naumann_terminal_velocity(double d, double rho_p, double rho_f, double mu, double g) {
  const double ar_signed = archimedes(d, rho_p, rho_f, mu, g);
  const double ar = std::fabs(ar_signed);
  if (ar == 0.0) return 0.0;
  double re;
  const double ar_below_switch = 18.0 * detail::kNewtonRe * detail::schiller_naumann_factor(detail::kNewtonRe);
  const double ar_above_switch = 0.75 * detail::kNewtonCd * detail::kNewtonRe * detail::kNewtonRe;
  if (ar >= ar_above_switch) {
    re = std::sqrt(ar / (0.75 * detail::kNewtonCd));
  } else if (ar >= ar_below_switch) {
    re = detail::kNewtonRe;
  } else {
    re = ar / 18.0;
    for (int i = 0; i < 200; ++i) {
      const double p = std::pow(re, 0.687);
      const double f = 18.0 * re * (1.0 + 0.15 * p) - ar;
      const double fp = 18.0 + 18.0 * 0.15 * 1.687 * p;
      const double step = f / fp;
      re -= step;
      if (!(std::fabs(step) > 1e-15 * re)) break;
    }
  }
  const double v = re * mu / (rho_f * d);
  return ar_signed < 0.0 ? -v : v;
}

// Ergun (1952) pressure gradient -dp/dx [Pa/m] through a fixed bed at
// superficial velocity U_s:
//   150 mu U_s (1-eps)^2 / (eps^3 d^2) + 1.75 rho_f U_s |U_s| (1-eps) / (eps^3 d)
// (signed with U_s).
inline double ergun_pressure_gradient(double superficial_velocity, double eps, double d, double rho_f, double mu) {
  detail::require_voidage(eps);
  detail::check_fluid(d, rho_f, mu);
  const double phi = 1.0 - eps;
  const double eps3 = eps * eps * eps;
  const double us = superficial_velocity;
  return 150.0 * mu * us * phi * phi / (eps3 * d * d) + 1.75 * rho_f * us * std::fabs(us) * phi / (eps3 * d);
}

// Wen & Yu (1966) minimum fluidisation velocity:
//   Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7,  U_mf = Re_mf mu / (rho_f d),
// evaluated as 0.0408 Ar / (sqrt(33.7^2 + 0.0408 Ar) + 33.7) to avoid the
// cancellation for small Ar. Needs rho_p > rho_f; otherwise returns NaN.
inline double wen_yu_minimum_fluidisation_velocity(double d, double rho_p, double rho_f, double mu, double g) {
  const double ar = archimedes(d, rho_p, rho_f, mu, g);
  if (!(ar > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double b = 0.0408 * ar;
  const double re = b / (std::sqrt(33.7 * 33.7 + b) + 33.7);
  return re * mu / (rho_f * d);
}

// Minimum fluidisation velocity from Ergun's equation at bed voidage eps_mf:
// the bed weight per unit volume (1-eps)(rho_p - rho_f) g equals the Ergun
// gradient, i.e. with Re = rho_f U d / mu
//   (1.75/eps^3) Re^2 + (150 (1-eps)/eps^3) Re = Ar,
// solved as Re = 2 Ar / (B + sqrt(B^2 + 4 A Ar)) (no cancellation).
// Needs rho_p > rho_f; otherwise returns NaN.
inline double ergun_minimum_fluidisation_velocity(double d, double rho_p, double rho_f, double mu, double g,
                                                  double eps_mf) {
  detail::require_voidage(eps_mf);
  const double ar = archimedes(d, rho_p, rho_f, mu, g);
  if (!(ar > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double eps3 = eps_mf * eps_mf * eps_mf;
  const double a = 1.75 / eps3;
  const double b = 150.0 * (1.0 - eps_mf) / eps3;
  const double re = 2.0 * ar / (b + std::sqrt(b * b + 4.0 * a * ar));
  return re * mu / (rho_f * d);
}

}  // namespace domel::plugins::fluid
