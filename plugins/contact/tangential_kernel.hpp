// SPDX-License-Identifier: MIT
// The incremental tangential spring with a Coulomb cap, shared by the
// "mindlin" and "linear" tangential models (docs/physics.md §1.1):
//   xi -= (xi . n) n            history projected onto the current tangent plane
//   xi += v_t dt                incremental tangential displacement
//   F_t = -k_t xi
//   |F_t| > mu |F_n|:  F_t *= mu|F_n|/|F_t|,  xi = -F_t/k_t   (slip; no dashpot)
//   otherwise:         F_t -= eta_t v_t                        (stick; dashpot)
// The Coulomb test on the spring part only and the dashpot only while
// sticking is LIGGGHTS' tangential_model_history reading; we keep it so the
// two codes agree (physics.md §1.1, note).
#pragma once

#include <domel/sdk/abi.h>

#include <cmath>

namespace domel::plugins::contact {

/// How k_t and eta_t follow from the two per-contact inputs u and v of
/// tangential_spring_coulomb(): k_t = K u[c] always, and
///   kSqrtMass:  eta_t = D sqrt(k_t v[c])   (Mindlin: u = a, v = m*)
///   kScaled:    eta_t = D v[c]             (linear: u = k_n, v = eta_n)
enum class Dashpot { kSqrtMass, kScaled };

namespace detail {

// A free function with __restrict parameters: GCC honours restrict there,
// not on local pointer variables, and without it does not vectorise the loop.
template <Dashpot kMode>
inline void spring_coulomb_loop(uint32_t n, uint32_t s, double mu, double dt, double K, double D,
                                const double* __restrict u, const double* __restrict v,
                                const double* __restrict bnx, const double* __restrict bny,
                                const double* __restrict bnz, const double* __restrict vtx,
                                const double* __restrict vty, const double* __restrict vtz,
                                const double* __restrict fn, double* __restrict hist, double* __restrict ftx,
                                double* __restrict fty, double* __restrict ftz) {
  // Written without branches, and so that every contact loads the same
  // inputs, so that the compiler vectorises the loop: with
  // -fno-trapping-math GCC if-converts the selects and computes both sides
  // (a division by 1 where unused); a load used only under a condition
  // (m* for the dashpot) would still block it, so the dashpot is weighted
  // by 1 while sticking and 0 while slipping instead of selected. The
  // results are those of the if/else form bit for bit (the sign of a zero
  // force aside).
  // Keep xi = -F_t/k_t as written. Rescaling xi by the Coulomb ratio instead
  // (equal in exact arithmetic, two divisions fewer) leaves k_t|xi| a
  // rounding above mu|F_n| more often: the contact then slips again every
  // step, without its dashpot, and a static pile does not come to rest
  // (tests/validation/collapse_test.cpp: median |omega| 3e-6 instead of
  // 3e-9 rad/s at t = 1.5 s with S-D rolling, dt = 5e-6 s).
  for (uint32_t c = 0; c < n; ++c) {
    double* xi = hist + static_cast<size_t>(c) * s;
    const double nx = bnx[c], ny = bny[c], nz = bnz[c];
    const double proj = xi[0] * nx + xi[1] * ny + xi[2] * nz;
    const double x0 = xi[0] - proj * nx + vtx[c] * dt;
    const double x1 = xi[1] - proj * ny + vty[c] * dt;
    const double x2 = xi[2] - proj * nz + vtz[c] * dt;
    const double kt = K * u[c];
    const double eta_t = kMode == Dashpot::kSqrtMass ? D * std::sqrt(kt * v[c]) : D * v[c];
    const double f0 = -kt * x0, f1 = -kt * x1, f2 = -kt * x2;
    const double f_spring = std::sqrt(f0 * f0 + f1 * f1 + f2 * f2);
    const double f_max = mu * std::fabs(fn[c]);
    const bool slip = f_spring > f_max;                        // then f_spring > 0
    const double q = f_max / (slip ? f_spring : 1.0);
    const double scale = slip ? q : 1.0;
    const double g0 = f0 * scale, g1 = f1 * scale, g2 = f2 * scale;
    const bool rescale = slip & (kt > 0.0);                    // slip: xi = -F_t/k_t
    const double kd = rescale ? kt : 1.0;
    xi[0] = rescale ? -g0 / kd : x0;
    xi[1] = rescale ? -g1 / kd : x1;
    xi[2] = rescale ? -g2 / kd : x2;
    const double eta_stick = (slip ? 0.0 : 1.0) * eta_t;       // stick: dashpot
    ftx[c] = g0 - eta_stick * vtx[c];
    fty[c] = g1 - eta_stick * vty[c];
    ftz[c] = g2 - eta_stick * vtz[c];
  }
}

}  // namespace detail

template <Dashpot kMode>
inline void tangential_spring_coulomb(domel_contact_batch_v1& b, double K, double D, const double* u,
                                      const double* v) {
  detail::spring_coulomb_loop<kMode>(b.n, b.history_stride, b.pair->friction, b.dt, K, D, u, v, b.nx, b.ny, b.nz,
                                     b.vtx, b.vty, b.vtz, b.fn, b.history, b.ftx, b.fty, b.ftz);
}

}  // namespace domel::plugins::contact
