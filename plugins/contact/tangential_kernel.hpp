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

constexpr uint32_t kChunk = 256;  // contacts per stick pass (a stack array of slip flags)

// Pass 1, vectorised: every contact as if it sticks (no division), and a
// slip flag (1.0/0.0) per contact. A free function with __restrict
// parameters: GCC honours restrict there, not on local pointer variables,
// and without it does not vectorise the loop. Returns the number of slips.
template <Dashpot kMode>
inline double stick_pass(uint32_t n, uint32_t s, double mu, double dt, double K, double D,
                         const double* __restrict u, const double* __restrict v, const double* __restrict bnx,
                         const double* __restrict bny, const double* __restrict bnz, const double* __restrict vtx,
                         const double* __restrict vty, const double* __restrict vtz, const double* __restrict fn,
                         double* __restrict hist, double* __restrict ftx, double* __restrict fty,
                         double* __restrict ftz, double* __restrict slip) {
  double slips = 0.0;
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
    const double flag = f_spring > f_max ? 1.0 : 0.0;
    slip[c] = flag;
    slips += flag;
    xi[0] = x0; xi[1] = x1; xi[2] = x2;
    ftx[c] = f0 - eta_t * vtx[c];  // stick: dashpot
    fty[c] = f1 - eta_t * vty[c];
    ftz[c] = f2 - eta_t * vtz[c];
  }
  return slips;
}

}  // namespace detail

// Two passes, so that the common case (sticking) runs vectorised and without
// divisions: the stick pass above, then the few slipping contacts redone
// from the displacement the stick pass stored (the same expressions, so the
// results are those of a one-pass if/else loop bit for bit). Keep
// xi = -F_t/k_t as written: rescaling xi by the Coulomb ratio instead (equal
// in exact arithmetic, two divisions fewer) leaves k_t|xi| a rounding above
// mu|F_n| more often; the contact then slips again every step, without its
// dashpot, and a static pile does not come to rest
// (tests/validation/collapse_test.cpp: median |omega| 3e-6 instead of 3e-9
// rad/s at t = 1.5 s with S-D rolling, dt = 5e-6 s).
template <Dashpot kMode>
inline void tangential_spring_coulomb(domel_contact_batch_v2& b, double K, double D, const double* u,
                                      const double* v) {
  const double mu = b.pair->friction;
  const uint32_t s = b.history_stride;
  double slip[detail::kChunk];
  for (uint32_t c0 = 0; c0 < b.n; c0 += detail::kChunk) {
    const uint32_t m = b.n - c0 < detail::kChunk ? b.n - c0 : detail::kChunk;
    const double slips = detail::stick_pass<kMode>(
        m, s, mu, b.dt, K, D, u + c0, v + c0, b.nx + c0, b.ny + c0, b.nz + c0, b.vtx + c0, b.vty + c0, b.vtz + c0,
        b.fn + c0, b.history + static_cast<size_t>(c0) * s, b.ftx + c0, b.fty + c0, b.ftz + c0, slip);
    if (slips == 0.0) continue;
    for (uint32_t k = 0; k < m; ++k) {
      if (slip[k] == 0.0) continue;
      const uint32_t c = c0 + k;
      double* xi = b.history + static_cast<size_t>(c) * s;  // holds the new displacement x
      const double kt = K * u[c];
      const double f0 = -kt * xi[0], f1 = -kt * xi[1], f2 = -kt * xi[2];
      const double f_spring = std::sqrt(f0 * f0 + f1 * f1 + f2 * f2);
      const double f_max = mu * std::fabs(b.fn[c]);
      const double scale = f_max / f_spring;  // f_spring > f_max >= 0
      const double g0 = f0 * scale, g1 = f1 * scale, g2 = f2 * scale;
      if (kt > 0.0) {  // slip: xi = -F_t/k_t
        xi[0] = -g0 / kt;
        xi[1] = -g1 / kt;
        xi[2] = -g2 / kt;
      }
      b.ftx[c] = g0;  // no dashpot while slipping
      b.fty[c] = g1;
      b.ftz[c] = g2;
    }
  }
}

}  // namespace domel::plugins::contact
