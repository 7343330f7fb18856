// SPDX-License-Identifier: MIT
// Unit tests of the fluid drag laws (plugins/fluid/drag_laws.hpp): the four
// per-particle drag coefficients of docs/physics.md §7 (Schiller-Naumann, Di
// Felice, Gidaspow, Beetstra) checked against their published formulas written
// out literally here, their limits at zero slip, the coarse-grain scaling of
// §6.3, the validity ranges, and the analytic references (terminal velocities,
// Ergun pressure gradient, minimum fluidisation velocities) against numbers
// worked out by hand for glass beads (2500 kg/m^3) in air (1.2 kg/m^3,
// 1.8e-5 Pa s, g = 9.81 m/s^2).
//
// Tolerances, used throughout and justified where they are defined:
//  kRoundoff  1e-12  the same quantity computed along two algebraically
//                    equal paths (a few tens of roundings of 1.1e-16 each,
//                    pow() included, which glibc rounds to within 1 ulp);
//  printed(x, digits)  half a unit in the last digit printed in the brief /
//                    textbook value, i.e. what "to the printed digits" means.
#include "plugins/fluid/drag_laws.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using domel::plugins::fluid::beta;
using domel::plugins::fluid::beta_parcel;
using domel::plugins::fluid::DragLaw;

constexpr double kPi = 3.14159265358979323846;

// Air and glass.
constexpr double kRhoF = 1.2;
constexpr double kMu = 1.8e-5;
constexpr double kRhoP = 2500.0;
constexpr double kG = 9.81;

// Two algebraically identical evaluations of a formula of at most a few tens
// of floating-point operations agree to a few tens of ulps (1 ulp = 2.2e-16
// relative); 1e-12 leaves a factor of ~100 margin and is still far below any
// modelling difference the tests look for.
constexpr double kRoundoff = 1e-12;

const std::vector<DragLaw> kLaws = {DragLaw::schiller_naumann, DragLaw::di_felice, DragLaw::gidaspow,
                                    DragLaw::beetstra};

::testing::AssertionResult close(double got, double want, double rel) {
  if (got == want || std::fabs(got - want) <= rel * std::fabs(want)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << got << ", want " << want << " (relative difference "
                                       << (got - want) / want << ", allowed " << rel << ")";
}

// `got` rounds to the printed value `want` whose last printed digit has the
// place value `unit`: |got - want| <= unit / 2.
::testing::AssertionResult printed(double got, double want, double unit) {
  if (std::fabs(got - want) <= 0.5 * unit) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << got << ", printed value " << want << " +- " << 0.5 * unit;
}

double sphere_volume(double d) { return kPi * d * d * d / 6.0; }

// Buoyant weight (rho_p - rho_f) V g of a glass sphere in air.
double buoyant_weight(double d) { return (kRhoP - kRhoF) * sphere_volume(d) * kG; }

// Schiller-Naumann C_d as printed (Schiller & Naumann 1933; physics.md §7.4).
double literal_sn_cd(double re) { return re < 1000.0 ? 24.0 / re * (1.0 + 0.15 * std::pow(re, 0.687)) : 0.44; }

// Di Felice's chi as printed (Di Felice 1994; physics.md §7.1).
double literal_chi(double re) {
  return 3.7 - 0.65 * std::exp(-(1.5 - std::log10(re)) * (1.5 - std::log10(re)) / 2.0);
}

// Beetstra's normalised force as printed (Beetstra et al. 2007; physics.md §7.3).
double literal_beetstra_f(double eps, double re) {
  const double phi = 1.0 - eps;
  return 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * std::sqrt(phi)) +
         (0.413 * re / (24.0 * eps * eps)) * (1.0 / eps + 3.0 * eps * phi + 8.4 * std::pow(re, -0.343)) /
             (1.0 + std::pow(10.0, 3.0 * phi) * std::pow(re, -(1.0 + 4.0 * phi) / 2.0));
}

// Slip speed giving the Reynolds number `re` at voidage eps (d = 1 mm, air).
double slip_for(double re, double eps, double d) { return re * kMu / (eps * kRhoF * d); }

TEST(DragLaws, NamesRoundTrip) {
  using domel::plugins::fluid::drag_law_from_name;
  using domel::plugins::fluid::name;
  EXPECT_STREQ(name(DragLaw::schiller_naumann), "schiller_naumann");
  EXPECT_STREQ(name(DragLaw::di_felice), "di_felice");
  EXPECT_STREQ(name(DragLaw::gidaspow), "gidaspow");
  EXPECT_STREQ(name(DragLaw::beetstra), "beetstra");
  for (DragLaw law : kLaws) {
    const auto back = drag_law_from_name(name(law));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, law);
  }
  EXPECT_FALSE(drag_law_from_name("Gidaspow").has_value());  // case-sensitive
  EXPECT_FALSE(drag_law_from_name("").has_value());
  EXPECT_FALSE(drag_law_from_name("wen_yu").has_value());
}

TEST(DragLaws, RejectsInvalidArguments) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (DragLaw law : kLaws) {
    EXPECT_THROW(beta(law, 0.0, 0.5, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, -1e-3, 0.5, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, nan, 0.5, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, 0.5, 1.0, kRhoF, 0.0), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, 0.5, 1.0, kRhoF, -kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, 0.5, 1.0, 0.0, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, 0.0, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, 1.0 + 1e-12, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, -0.5, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(beta(law, 1e-3, nan, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_NO_THROW(beta(law, 1e-3, 1.0, 1.0, kRhoF, kMu));
    EXPECT_THROW(beta_parcel(law, 3e-3, 0.0, true, 0.5, 1.0, kRhoF, kMu), std::invalid_argument);
    EXPECT_THROW(domel::plugins::fluid::validity(law, 0.0, 1.0), std::invalid_argument);
  }
  EXPECT_THROW(domel::plugins::fluid::reynolds(0.5, kRhoF, 1e-3, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(domel::plugins::fluid::ergun_pressure_gradient(0.3, 1.5, 1e-3, kRhoF, kMu), std::invalid_argument);
  EXPECT_THROW(domel::plugins::fluid::stokes_terminal_velocity(0.0, kRhoP, kRhoF, kMu, kG), std::invalid_argument);
}

TEST(DragLaws, ReynoldsNumber) {
  // 0.5 * 1.2 * 1e-3 * 2 / 1.8e-5 = 66.666...; the sign of the slip is ignored.
  EXPECT_TRUE(close(domel::plugins::fluid::reynolds(0.5, kRhoF, 1e-3, -2.0, kMu), 200.0 / 3.0, kRoundoff));
  EXPECT_EQ(domel::plugins::fluid::reynolds(0.5, kRhoF, 1e-3, 0.0, kMu), 0.0);
}

// Zero slip (and the smallest slips representable) gives a finite positive
// coefficient for every law and voidage: no 1/Re, no 0 * inf, no overflow of
// Re^-(1+4 phi)/2 in Beetstra's denominator.
TEST(DragLaws, FiniteAtZeroSlip) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (DragLaw law : kLaws) {
    for (double eps : {1.0, 0.95, 0.81, 0.8, 0.6, 0.4, 0.3}) {
      for (double slip : {0.0, tiny, 1e-300, 1e-200, -1e-300}) {
        const double b = beta(law, 1e-3, eps, slip, kRhoF, kMu);
        EXPECT_TRUE(std::isfinite(b) && b > 0.0) << domel::plugins::fluid::name(law) << " eps " << eps << " slip "
                                                 << slip << " beta " << b;
      }
    }
  }
}

// The U -> 0 limits derived in the header, against the closed forms.
TEST(DragLaws, ZeroSlipLimits) {
  const double d = 1e-3;
  const double stokes = 3.0 * kPi * kMu * d;
  for (double eps : {1.0, 0.9, 0.8, 0.6, 0.4}) {
    const double phi = 1.0 - eps;
    // Schiller-Naumann: Stokes, whatever eps.
    EXPECT_TRUE(close(beta(DragLaw::schiller_naumann, d, eps, 0.0, kRhoF, kMu), stokes, kRoundoff));
    // Di Felice: C_d U -> 4.8^2 mu/(eps rho_f d), chi -> 3.7:
    //   beta -> (pi/8) rho_f d^2 * 23.04 mu/(eps rho_f d) * eps^(2-3.7) = 2.88 pi mu d eps^-2.7.
    EXPECT_TRUE(close(beta(DragLaw::di_felice, d, eps, 0.0, kRhoF, kMu), 2.88 * kPi * kMu * d * std::pow(eps, -2.7),
                      kRoundoff));
    // Gidaspow: Ergun V_p 150 phi mu/(eps d^2) = 25 pi phi mu d/eps; Wen-Yu 3 pi mu d eps^-2.65.
    const double gidaspow0 = eps <= 0.8 ? 25.0 * kPi * phi * kMu * d / eps : stokes * std::pow(eps, -2.65);
    EXPECT_TRUE(close(beta(DragLaw::gidaspow, d, eps, 0.0, kRhoF, kMu), gidaspow0, kRoundoff));
    // Beetstra: 3 pi mu d eps (10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi))).
    const double beetstra0 = stokes * eps * (10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * std::sqrt(phi)));
    EXPECT_TRUE(close(beta(DragLaw::beetstra, d, eps, 0.0, kRhoF, kMu), beetstra0, kRoundoff));
  }
}

// Continuity at U = 0: at slip 1e-24 m/s every law is within 1e-9 relative of
// its U = 0 value. The slowest approach is Di Felice's, whose departure is
// 2 * 0.63 sqrt(U) / (4.8 sqrt(mu/(eps rho_f d))) ~ 2e-12 here; Schiller-
// Naumann / Wen-Yu depart by 0.15 Re^0.687 ~ 1e-15 (Re ~ 7e-23), Ergun by
// 1.75 rho_f U d eps / (150 phi mu) ~ 1e-24, Beetstra by O(Re^1.157).
TEST(DragLaws, ContinuousAtZeroSlip) {
  for (DragLaw law : kLaws) {
    for (double eps : {1.0, 0.9, 0.8, 0.6, 0.4}) {
      const double b0 = beta(law, 1e-3, eps, 0.0, kRhoF, kMu);
      EXPECT_TRUE(close(beta(law, 1e-3, eps, 1e-24, kRhoF, kMu), b0, 1e-9))
          << domel::plugins::fluid::name(law) << " eps " << eps;
      // 1e-300 m/s: every departure is below one ulp.
      EXPECT_TRUE(close(beta(law, 1e-3, eps, 1e-300, kRhoF, kMu), b0, 1e-15))
          << domel::plugins::fluid::name(law) << " eps " << eps;
    }
  }
}

// At slip 1e-12 m/s (Re ~ 1e-11) the departures from the U = 0 value are not
// yet below 1e-9, but they must be the leading-order terms the derivation
// predicts, which is the quantitative form of continuity. The measured
// departure beta(U)/beta(0) - 1 is a difference of numbers near 1, so it
// carries an absolute error of ~2e-16, i.e. a relative error of at most
// 2e-16/1e-8 = 2e-8 for the smallest departure checked (~1e-8); 1e-6 leaves
// margin. Next-order terms are below 1e-6 relative of the leading one
// (Di Felice's is included; its chi correction is exp(-72) here).
TEST(DragLaws, LeadingOrderDepartureAtSmallSlip) {
  const double d = 1e-3;
  const double u = 1e-12;
  auto departure = [&](DragLaw law, double eps) {
    return beta(law, d, eps, u, kRhoF, kMu) / beta(law, d, eps, 0.0, kRhoF, kMu) - 1.0;
  };
  // Schiller-Naumann: beta = 3 pi mu d (1 + 0.15 Re^0.687), Re at eps = 1.
  const double re1 = kRhoF * d * u / kMu;
  EXPECT_TRUE(close(departure(DragLaw::schiller_naumann, 0.5), 0.15 * std::pow(re1, 0.687), 1e-6));
  for (double eps : {1.0, 0.7, 0.4}) {
    // Di Felice: (0.63 sqrt(U) + 4.8 s)^2 / (4.8 s)^2 - 1 = 2x + x^2, x = 0.63 sqrt(U)/(4.8 s),
    // s = sqrt(mu/(eps rho_f d)).
    const double x = 0.63 * std::sqrt(u) / (4.8 * std::sqrt(kMu / (eps * kRhoF * d)));
    EXPECT_TRUE(close(departure(DragLaw::di_felice, eps), 2.0 * x + x * x, 1e-6)) << "eps " << eps;
    // Beetstra: the Re term is O(Re^(1.157)) ~ 1e-13, so within 1e-9.
    EXPECT_LT(std::fabs(departure(DragLaw::beetstra, eps)), 1e-9) << "eps " << eps;
  }
  // Gidaspow / Wen-Yu at eps = 0.9: 0.15 Re^0.687 with Re = eps rho_f d U / mu.
  const double re09 = 0.9 * re1;
  EXPECT_TRUE(close(departure(DragLaw::gidaspow, 0.9), 0.15 * std::pow(re09, 0.687), 1e-6));
}

// Schiller-Naumann at eps = 1 and Re -> 0 is Stokes drag 3 pi mu d, and the
// law ignores the eps it is given (single sphere).
TEST(DragLaws, SchillerNaumannStokesLimit) {
  for (double d : {1e-5, 1e-4, 1e-3}) {
    EXPECT_TRUE(close(beta(DragLaw::schiller_naumann, d, 1.0, 0.0, kRhoF, kMu), 3.0 * kPi * kMu * d, kRoundoff));
    // Re = rho_f d U/mu <= 1.2 * 1e-3 * 1e-24 / 1.8e-5 ~ 7e-23, 0.15 Re^0.687 ~ 1e-16.
    EXPECT_TRUE(close(beta(DragLaw::schiller_naumann, d, 1.0, 1e-24, kRhoF, kMu), 3.0 * kPi * kMu * d, kRoundoff));
  }
  EXPECT_EQ(beta(DragLaw::schiller_naumann, 1e-3, 0.5, 0.7, kRhoF, kMu),
            beta(DragLaw::schiller_naumann, 1e-3, 1.0, 0.7, kRhoF, kMu));
}

// Schiller-Naumann follows its printed C_d: F = beta U = (pi/8) C_d rho_f d^2 U^2
// on both sides of Re = 1000. The source's curve is discontinuous there (it
// jumps up by 330000 / (18000 (1 + 0.15 * 1000^0.687)) - 1 = 0.39 %), which is
// checked as a property of the law, not smoothed.
TEST(DragLaws, SchillerNaumannFollowsItsDragCurve) {
  const double d = 1e-3;
  for (double re : {1e-3, 0.5, 10.0, 300.0, 999.0, 1000.0 * (1.0 - 1e-9), 1000.0 * (1.0 + 1e-9), 5000.0, 1e5}) {
    const double u = slip_for(re, 1.0, d);
    const double re_in = domel::plugins::fluid::reynolds(1.0, kRhoF, d, u, kMu);  // the Re the law sees
    const double force = beta(DragLaw::schiller_naumann, d, 0.3, u, kRhoF, kMu) * u;
    EXPECT_TRUE(close(force, kPi / 8.0 * literal_sn_cd(re_in) * kRhoF * d * d * u * u, kRoundoff)) << "Re " << re;
  }
  const double below = beta(DragLaw::schiller_naumann, d, 1.0, slip_for(1000.0 * (1.0 - 1e-12), 1.0, d), kRhoF, kMu);
  const double above = beta(DragLaw::schiller_naumann, d, 1.0, slip_for(1000.0 * (1.0 + 1e-12), 1.0, d), kRhoF, kMu);
  // Jump ratio 1.0039057866816...: the slips differ by 2e-12 relative, far
  // below the printed 4 digits.
  EXPECT_TRUE(printed(above / below, 1.0039, 1e-4));
}

// Terminal fall of glass beads in air under Schiller-Naumann drag. The printed
// numbers (Ar, Re, v_t to 3 digits) are checked to half a unit in their last
// digit; the exact statement, beta(v_t) v_t = (rho_p - rho_f) V g, to 1e-10
// (the solver converges to ~1e-15 in Re, and the balance is a few roundings
// away from it).
TEST(DragLaws, TerminalVelocityGlassInAir) {
  using domel::plugins::fluid::archimedes;
  using domel::plugins::fluid::schiller_naumann_terminal_velocity;
  using domel::plugins::fluid::stokes_terminal_velocity;
  struct Case {
    double d, ar, ar_unit, re, re_unit, vt, vt_unit;
  };
  // d = 100 um: Ar = 1.2 * 2498.8 * 9.81 * 1e-12 / 3.24e-10 = 90.79 -> Re = 3.688, v_t = 0.5532 m/s.
  // d = 1 mm:   Ar = 9.079e4 -> Re = 455.9, v_t = 6.839 m/s.
  for (const Case& c : {Case{1e-4, 90.8, 0.1, 3.69, 0.01, 0.553, 0.001},
                        Case{1e-3, 9.08e4, 0.01e4, 456.0, 1.0, 6.84, 0.01}}) {
    const double vt = schiller_naumann_terminal_velocity(c.d, kRhoP, kRhoF, kMu, kG);
    EXPECT_TRUE(printed(archimedes(c.d, kRhoP, kRhoF, kMu, kG), c.ar, c.ar_unit)) << "d " << c.d;
    EXPECT_TRUE(printed(kRhoF * c.d * vt / kMu, c.re, c.re_unit)) << "d " << c.d;
    EXPECT_TRUE(printed(vt, c.vt, c.vt_unit)) << "d " << c.d;
    EXPECT_TRUE(close(beta(DragLaw::schiller_naumann, c.d, 1.0, vt, kRhoF, kMu) * vt, buoyant_weight(c.d), 1e-10))
        << "d " << c.d;
    // Inertia slows the fall below Stokes' (rho_p - rho_f) g d^2 / (18 mu).
    EXPECT_LT(vt, stokes_terminal_velocity(c.d, kRhoP, kRhoF, kMu, kG));
  }
  // Stokes: 2498.8 * 9.81 * 1e-8 / (18 * 1.8e-5) = 0.75658111... m/s at 100 um.
  EXPECT_TRUE(close(stokes_terminal_velocity(1e-4, kRhoP, kRhoF, kMu, kG), 2498.8 * 9.81 * 1e-8 / 3.24e-4, kRoundoff));
  // A 10 nm bead: Re ~ 5e-12, so Schiller-Naumann's fall departs from Stokes'
  // by about 0.15 Re^0.687 / 1.687 ~ 2.6e-9; 1e-7 bounds that.
  EXPECT_TRUE(close(schiller_naumann_terminal_velocity(1e-8, kRhoP, kRhoF, kMu, kG),
                    stokes_terminal_velocity(1e-8, kRhoP, kRhoF, kMu, kG), 1e-7));
  // Newton regime, d = 5 mm: Ar = 1.135e7 >= 330000, so 0.33 Re^2 = Ar, Re = 5865.
  const double d5 = 5e-3;
  const double vt5 = schiller_naumann_terminal_velocity(d5, kRhoP, kRhoF, kMu, kG);
  const double re5 = kRhoF * d5 * vt5 / kMu;
  EXPECT_GT(re5, 1000.0);
  EXPECT_TRUE(close(re5, std::sqrt(archimedes(d5, kRhoP, kRhoF, kMu, kG) / 0.33), kRoundoff));
  EXPECT_TRUE(close(beta(DragLaw::schiller_naumann, d5, 1.0, vt5, kRhoF, kMu) * vt5, buoyant_weight(d5), 1e-10));
  // Inside the gap of the drag curve (328716 <= Ar < 330000) no balance
  // exists; the solver returns the switch point Re = 1000. g is chosen so
  // that Ar = 329000 for a 1 mm bead.
  const double g_gap = 329000.0 * kMu * kMu / (kRhoF * (kRhoP - kRhoF) * 1e-9);
  const double vt_gap = schiller_naumann_terminal_velocity(1e-3, kRhoP, kRhoF, kMu, g_gap);
  EXPECT_TRUE(close(kRhoF * 1e-3 * vt_gap / kMu, 1000.0, kRoundoff));
  // A sphere lighter than the fluid rises: the velocity is negative, and the
  // balance holds with the magnitudes.
  const double v_up = schiller_naumann_terminal_velocity(1e-3, 0.6, kRhoF, kMu, kG);
  EXPECT_LT(v_up, 0.0);
  EXPECT_TRUE(close(beta(DragLaw::schiller_naumann, 1e-3, 1.0, v_up, kRhoF, kMu) * -v_up,
                    (kRhoF - 0.6) * sphere_volume(1e-3) * kG, 1e-10));
  EXPECT_EQ(schiller_naumann_terminal_velocity(1e-3, kRhoF, kRhoF, kMu, kG), 0.0);
}

// Gidaspow's Ergun branch in a uniform fixed bed reproduces Ergun. In model A
// the fluid momentum balance is eps dp/dx = n F, with n = phi / V_p particles
// per unit volume and F = beta U, U = U_s/eps the interstitial slip; so
// dp/dx = phi beta U / (V_p eps) must be Ergun's gradient at U_s.
TEST(DragLaws, GidaspowErgunBranchReproducesErgun) {
  using domel::plugins::fluid::ergun_pressure_gradient;
  const double d = 1e-3;
  for (double eps : {0.35, 0.4, 0.5, 0.8}) {
    for (double us : {1e-4, 0.05, 0.3, 2.0}) {
      const double phi = 1.0 - eps;
      const double u = us / eps;
      const double dpdx = phi * beta(DragLaw::gidaspow, d, eps, u, kRhoF, kMu) * u / (sphere_volume(d) * eps);
      EXPECT_TRUE(close(dpdx, ergun_pressure_gradient(us, eps, d, kRhoF, kMu), kRoundoff))
          << "eps " << eps << " U_s " << us;
    }
  }
  // d = 1 mm, eps = 0.40, U_s = 0.3 m/s, air, by hand:
  //   150 * 1.8e-5 * 0.3 * 0.36 / (0.064 * 1e-6) = 4556.25
  //   1.75 * 1.2 * 0.09 * 0.6 / (0.064 * 1e-3)   = 1771.875   -> 6328.125 Pa/m
  const double ergun = ergun_pressure_gradient(0.3, 0.40, d, kRhoF, kMu);
  EXPECT_TRUE(printed(ergun, 6.33e3, 0.01e3));
  EXPECT_TRUE(close(ergun, 6328.125, kRoundoff));
  // Signed with the flow.
  EXPECT_TRUE(close(ergun_pressure_gradient(-0.3, 0.40, d, kRhoF, kMu), -6328.125, kRoundoff));
}

// Gidaspow's Wen-Yu branch: V_p beta_WY / phi with beta_WY as printed equals
// the simplified per-particle form; at eps = 1 it is Schiller-Naumann.
TEST(DragLaws, GidaspowWenYuBranch) {
  const double d = 1e-3;
  for (double eps : {0.81, 0.9, 0.99}) {
    for (double re : {1e-2, 1.0, 50.0, 900.0, 2000.0, 1e5}) {
      const double u = slip_for(re, eps, d);
      const double phi = 1.0 - eps;
      const double re_in = domel::plugins::fluid::reynolds(eps, kRhoF, d, u, kMu);
      const double beta_wy = 0.75 * literal_sn_cd(re_in) * kRhoF * eps * phi * u / d * std::pow(eps, -2.65);
      EXPECT_TRUE(close(beta(DragLaw::gidaspow, d, eps, u, kRhoF, kMu), sphere_volume(d) * beta_wy / phi, kRoundoff))
          << "eps " << eps << " Re " << re;
    }
  }
  for (double u : {0.0, 1e-3, 0.5, 20.0, 200.0}) {
    EXPECT_TRUE(close(beta(DragLaw::gidaspow, d, 1.0, u, kRhoF, kMu),
                      beta(DragLaw::schiller_naumann, d, 1.0, u, kRhoF, kMu), kRoundoff))
        << "U " << u;
  }
}

// Minimum fluidisation of glass beads in air. Printed values to half a unit in
// their last digit; the defining equations to round-off.
TEST(DragLaws, MinimumFluidisation) {
  using domel::plugins::fluid::archimedes;
  using domel::plugins::fluid::ergun_minimum_fluidisation_velocity;
  using domel::plugins::fluid::ergun_pressure_gradient;
  using domel::plugins::fluid::wen_yu_minimum_fluidisation_velocity;
  // Wen & Yu: 1 mm: Re_mf = sqrt(33.7^2 + 0.0408 * 90790) - 33.7 = 35.87, U_mf = 0.5380 m/s;
  //           100 um: Re_mf = 0.05491, U_mf = 8.24 mm/s.
  EXPECT_TRUE(printed(wen_yu_minimum_fluidisation_velocity(1e-3, kRhoP, kRhoF, kMu, kG), 0.538, 0.001));
  EXPECT_TRUE(printed(wen_yu_minimum_fluidisation_velocity(1e-4, kRhoP, kRhoF, kMu, kG), 8.2e-3, 0.1e-3));
  for (double d : {1e-4, 1e-3}) {
    const double re = kRhoF * d * wen_yu_minimum_fluidisation_velocity(d, kRhoP, kRhoF, kMu, kG) / kMu;
    EXPECT_TRUE(close((re + 33.7) * (re + 33.7), 33.7 * 33.7 + 0.0408 * archimedes(d, kRhoP, kRhoF, kMu, kG), kRoundoff));
  }
  // Ergun: 1 mm at eps_mf = 0.40: 0.5608 m/s; 0.42: 0.6291 m/s; 100 um at 0.40: 9.67 mm/s.
  EXPECT_TRUE(printed(ergun_minimum_fluidisation_velocity(1e-3, kRhoP, kRhoF, kMu, kG, 0.40), 0.561, 0.001));
  EXPECT_TRUE(printed(ergun_minimum_fluidisation_velocity(1e-3, kRhoP, kRhoF, kMu, kG, 0.42), 0.629, 0.001));
  EXPECT_TRUE(printed(ergun_minimum_fluidisation_velocity(1e-4, kRhoP, kRhoF, kMu, kG, 0.40), 9.7e-3, 0.1e-3));
  // At U_mf the Ergun gradient carries the bed's buoyant weight (1 - eps)(rho_p - rho_f) g.
  for (double d : {1e-4, 1e-3}) {
    for (double eps : {0.40, 0.42, 0.5}) {
      const double umf = ergun_minimum_fluidisation_velocity(d, kRhoP, kRhoF, kMu, kG, eps);
      EXPECT_TRUE(close(ergun_pressure_gradient(umf, eps, d, kRhoF, kMu), (1.0 - eps) * (kRhoP - kRhoF) * kG, kRoundoff))
          << "d " << d << " eps " << eps;
    }
  }
  EXPECT_TRUE(std::isnan(wen_yu_minimum_fluidisation_velocity(1e-3, 1.0, kRhoF, kMu, kG)));
  EXPECT_TRUE(std::isnan(ergun_minimum_fluidisation_velocity(1e-3, 1.0, kRhoF, kMu, kG, 0.4)));
}

// Di Felice: the voidage factor eps^(2 - chi) against the printed correlation,
// and the exponent chi's shape.
TEST(DragLaws, DiFeliceVoidageFactor) {
  using domel::plugins::fluid::di_felice_chi;
  const double d = 1e-3;
  for (double eps : {0.4, 0.6, 0.8, 0.95, 1.0}) {
    for (double re : {0.02, 1.0, std::pow(10.0, 1.5), 500.0, 5000.0}) {
      const double u = slip_for(re, eps, d);
      const double re_in = domel::plugins::fluid::reynolds(eps, kRhoF, d, u, kMu);
      const double cd = (0.63 + 4.8 / std::sqrt(re_in)) * (0.63 + 4.8 / std::sqrt(re_in));
      // F / [(1/8) C_d rho_f pi d^2 U^2] = eps^(2 - chi), chi as printed.
      const double f_single = cd * kRhoF * kPi * d * d * u * u / 8.0;
      const double force = beta(DragLaw::di_felice, d, eps, u, kRhoF, kMu) * u;
      EXPECT_TRUE(close(force / f_single, std::pow(eps, 2.0 - literal_chi(re_in)), kRoundoff))
          << "eps " << eps << " Re " << re;
      // Same Re (hence same C_d and chi) at eps = 1: F(eps)/F(1) = (U_eps/U_1)^2 eps^(2-chi)
      // with U_eps/U_1 = 1/eps, i.e. beta(eps) eps / beta(1) = eps^(2 - chi).
      const double u1 = slip_for(re, 1.0, d);
      const double ratio =
          beta(DragLaw::di_felice, d, eps, u, kRhoF, kMu) * eps / beta(DragLaw::di_felice, d, 1.0, u1, kRhoF, kMu);
      EXPECT_TRUE(close(ratio, std::pow(eps, 2.0 - di_felice_chi(re)), kRoundoff)) << "eps " << eps << " Re " << re;
    }
  }
  // chi -> 3.7 as Re -> 0 and Re -> infinity (the Gaussian term is exp(-(1.5 - log10 Re)^2/2),
  // exp(-480) at Re = 1e-30 and exp(-420) at 1e30: below round-off of 3.7).
  EXPECT_EQ(di_felice_chi(0.0), 3.7);
  EXPECT_TRUE(close(di_felice_chi(1e-30), 3.7, 1e-15));
  EXPECT_TRUE(close(di_felice_chi(1e30), 3.7, 1e-15));
  EXPECT_EQ(di_felice_chi(std::numeric_limits<double>::infinity()), 3.7);
  // Minimum 3.7 - 0.65 = 3.05 at log10 Re = 1.5 (10^1.5 rounds, so log10 comes back as 1.5 +- 1 ulp).
  EXPECT_TRUE(close(di_felice_chi(std::pow(10.0, 1.5)), 3.05, kRoundoff));
  EXPECT_GT(di_felice_chi(std::pow(10.0, 1.4)), 3.05);
  EXPECT_GT(di_felice_chi(std::pow(10.0, 1.6)), 3.05);
  for (double re : {1e-3, 0.1, 3.0, 100.0, 1e4}) {
    EXPECT_TRUE(close(di_felice_chi(re), literal_chi(re), kRoundoff)) << "Re " << re;
  }
}

// Beetstra: the printed formula; the Stokes-flow limit (van der Hoef et al.
// 2005) at Re -> 0; the isolated sphere (F -> 1, Stokes drag) at phi -> 0.
TEST(DragLaws, BeetstraLimits) {
  using domel::plugins::fluid::beetstra_normalised_force;
  const double d = 1e-3;
  // Rearranged (numerator and denominator times Re^a) versus printed form.
  for (double eps : {0.4, 0.45, 0.6, 0.9, 0.99}) {
    for (double re : {1e-3, 0.5, 50.0, 800.0, 1000.0}) {
      EXPECT_TRUE(close(beetstra_normalised_force(eps, re), literal_beetstra_f(eps, re), kRoundoff))
          << "eps " << eps << " Re " << re;
      const double u = slip_for(re, eps, d);
      const double re_in = domel::plugins::fluid::reynolds(eps, kRhoF, d, u, kMu);
      EXPECT_TRUE(close(beta(DragLaw::beetstra, d, eps, u, kRhoF, kMu),
                        3.0 * kPi * kMu * d * eps * literal_beetstra_f(eps, re_in), kRoundoff))
          << "eps " << eps << " Re " << re;
    }
    // Re -> 0: F -> 10 phi/eps^2 + eps^2 (1 + 1.5 sqrt(phi)). At Re = 1e-12 the Re term is
    // ~0.413 * 8.4 / 24 * Re^(1.157) / eps^2 < 1e-13; 1e-9 bounds it.
    const double phi = 1.0 - eps;
    const double stokes_fit = 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * std::sqrt(phi));
    EXPECT_EQ(beetstra_normalised_force(eps, 0.0), stokes_fit);
    EXPECT_TRUE(close(beetstra_normalised_force(eps, 1e-12), stokes_fit, 1e-9)) << "eps " << eps;
  }
  // phi -> 0, Re -> 0: F -> 1, so beta -> 3 pi mu d.
  EXPECT_EQ(beetstra_normalised_force(1.0, 0.0), 1.0);
  EXPECT_TRUE(close(beta(DragLaw::beetstra, d, 1.0, 0.0, kRhoF, kMu), 3.0 * kPi * kMu * d, kRoundoff));
  // F approaches 1 like 1.5 sqrt(phi): at phi = 1e-12 (eps = 1 - 1e-12) and Re = 1e-12,
  // F - 1 = 1.5e-6 + O(1e-11); checked to the 2 digits that survive 1 - 1e-12's rounding.
  EXPECT_TRUE(printed(beetstra_normalised_force(1.0 - 1e-12, 1e-12) - 1.0, 1.5e-6, 0.1e-6));
}

// Coarse-grain scaling (Sakai & Koshizuka 2009; physics.md §6.3) is a
// definition: beta_parcel(alpha d, alpha, scaling) = alpha^3 beta(d). With
// alpha a power of two, (alpha d)/alpha is exactly d, so the two agree bitwise;
// with alpha = 3 the round trip d -> 3d -> d may move d by an ulp, and beta's
// sensitivity |d ln beta / d ln d| <= 3 makes that <= ~1e-15 relative.
TEST(DragLaws, ParcelScalingIsTheDefinition) {
  const double d = 1e-3;
  for (DragLaw law : kLaws) {
    for (double eps : {1.0, 0.9, 0.6, 0.4}) {
      for (double u : {0.0, 1e-3, 0.4, 30.0}) {
        for (double alpha : {1.0, 2.0, 4.0}) {
          EXPECT_EQ(beta_parcel(law, alpha * d, alpha, true, eps, u, kRhoF, kMu),
                    alpha * alpha * alpha * beta(law, d, eps, u, kRhoF, kMu))
              << domel::plugins::fluid::name(law) << " eps " << eps << " U " << u << " alpha " << alpha;
        }
        EXPECT_TRUE(close(beta_parcel(law, 3.0 * d, 3.0, true, eps, u, kRhoF, kMu),
                          27.0 * beta(law, d, eps, u, kRhoF, kMu), 1e-14))
            << domel::plugins::fluid::name(law) << " eps " << eps << " U " << u;
        // Without scaling: the parcel is one big particle.
        EXPECT_EQ(beta_parcel(law, 3.0 * d, 3.0, false, eps, u, kRhoF, kMu), beta(law, 3.0 * d, eps, u, kRhoF, kMu));
      }
    }
  }
}

// A scaled parcel falls at the original particle's terminal velocity; an
// unscaled one, in the Stokes regime, alpha^2 times faster.
TEST(DragLaws, ParcelTerminalVelocity) {
  using domel::plugins::fluid::schiller_naumann_terminal_velocity;
  using domel::plugins::fluid::stokes_terminal_velocity;
  const double d = 1e-4;
  const double alpha = 3.0;
  const double dp = alpha * d;
  // Stokes regime (U -> 0, beta independent of U): v = weight / beta.
  const double v_scaled = buoyant_weight(dp) / beta_parcel(DragLaw::schiller_naumann, dp, alpha, true, 1.0, 0.0, kRhoF, kMu);
  EXPECT_TRUE(close(v_scaled, stokes_terminal_velocity(d, kRhoP, kRhoF, kMu, kG), kRoundoff));
  const double v_unscaled =
      buoyant_weight(dp) / beta_parcel(DragLaw::schiller_naumann, dp, alpha, false, 1.0, 0.0, kRhoF, kMu);
  EXPECT_TRUE(close(v_unscaled, alpha * alpha * stokes_terminal_velocity(d, kRhoP, kRhoF, kMu, kG), kRoundoff));
  // Schiller-Naumann: the original particle's v_t balances the parcel's weight
  // under the scaled drag (1e-10: the solver's ~1e-15 plus the d round trip).
  for (double dd : {1e-4, 1e-3}) {
    const double vt = schiller_naumann_terminal_velocity(dd, kRhoP, kRhoF, kMu, kG);
    for (double a : {2.0, 3.0, 10.0}) {
      EXPECT_TRUE(close(beta_parcel(DragLaw::schiller_naumann, a * dd, a, true, 1.0, vt, kRhoF, kMu) * vt,
                        buoyant_weight(a * dd), 1e-10))
          << "d " << dd << " alpha " << a;
      // Unscaled, the parcel's drag at v_t is too small to hold it: it falls faster.
      EXPECT_LT(beta_parcel(DragLaw::schiller_naumann, a * dd, a, false, 1.0, vt, kRhoF, kMu) * vt,
                buoyant_weight(a * dd));
    }
  }
}

TEST(DragLaws, ValidityRanges) {
  using domel::plugins::fluid::validity;
  for (DragLaw law : {DragLaw::gidaspow, DragLaw::beetstra, DragLaw::di_felice}) {
    const auto v = validity(law, 0.4, 10.0);
    EXPECT_TRUE(v.ok) << domel::plugins::fluid::name(law) << ": " << v.regime;
    EXPECT_TRUE(v.regime.empty());
  }
  // Schiller-Naumann: fine for a lone sphere, also in the Newton regime; not in a dense bed.
  EXPECT_TRUE(validity(DragLaw::schiller_naumann, 1.0, 10.0).ok);
  EXPECT_TRUE(validity(DragLaw::schiller_naumann, 0.95, 5000.0).ok);
  const auto sn = validity(DragLaw::schiller_naumann, 0.4, 10.0);
  EXPECT_FALSE(sn.ok);
  EXPECT_NE(sn.regime.find("single-sphere"), std::string::npos) << sn.regime;
  // Beetstra outside 0.1 <= phi <= 0.6, Re <= 1000.
  const auto dilute = validity(DragLaw::beetstra, 0.95, 10.0);
  EXPECT_FALSE(dilute.ok);
  EXPECT_NE(dilute.regime.find("phi < 0.1"), std::string::npos) << dilute.regime;
  EXPECT_FALSE(validity(DragLaw::beetstra, 0.3, 10.0).ok);
  EXPECT_FALSE(validity(DragLaw::beetstra, 0.5, 2000.0).ok);
  EXPECT_TRUE(validity(DragLaw::beetstra, 0.9, 1000.0).ok);  // phi = 0.1 (to round-off) is inside
  // Di Felice outside 1e-2 < Re < 1e4.
  EXPECT_FALSE(validity(DragLaw::di_felice, 0.6, 1e-3).ok);
  EXPECT_FALSE(validity(DragLaw::di_felice, 0.6, 1e5).ok);
  EXPECT_FALSE(validity(DragLaw::di_felice, 0.6, 1e5).regime.empty());
  // Gidaspow: Ergun branch denser than a packed bed.
  EXPECT_FALSE(validity(DragLaw::gidaspow, 0.25, 10.0).ok);
  EXPECT_TRUE(validity(DragLaw::gidaspow, 0.9, 5000.0).ok);
  // Two findings are both reported.
  const auto two = validity(DragLaw::beetstra, 0.95, 5000.0);
  EXPECT_NE(two.regime.find("; "), std::string::npos) << two.regime;
  EXPECT_FALSE(validity(DragLaw::gidaspow, 0.5, -1.0).ok);
}

}  // namespace
