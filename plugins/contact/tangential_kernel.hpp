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

/// k_t and eta_t for contact c are given by `coeffs(c, kt, eta_t)`.
template <class Coeffs>
inline void tangential_spring_coulomb(domel_contact_batch_v1& b, Coeffs&& coeffs) {
  const double mu = b.pair->friction;
  const double dt = b.dt;
  const uint32_t s = b.history_stride;
  const uint32_t n = b.n;
  // The batch's arrays as local pointers: read through `b` inside the loop,
  // GCC reloads them every iteration and will not vectorise.
  const double* __restrict bnx = b.nx; const double* __restrict bny = b.ny; const double* __restrict bnz = b.nz;
  const double* __restrict vtx = b.vtx; const double* __restrict vty = b.vty; const double* __restrict vtz = b.vtz;
  const double* __restrict fn = b.fn;
  double* __restrict hist = b.history;
  double* __restrict ftx = b.ftx; double* __restrict fty = b.fty; double* __restrict ftz = b.ftz;
  // Written without branches (selects only), so that the compiler can
  // vectorise the loop; the results are bit-identical to the if/else form.
  for (uint32_t c = 0; c < n; ++c) {
    double* xi = hist + static_cast<size_t>(c) * s;
    const double nx = bnx[c], ny = bny[c], nz = bnz[c];
    const double proj = xi[0] * nx + xi[1] * ny + xi[2] * nz;
    const double x0 = xi[0] - proj * nx + vtx[c] * dt;
    const double x1 = xi[1] - proj * ny + vty[c] * dt;
    const double x2 = xi[2] - proj * nz + vtz[c] * dt;
    double kt, eta_t;
    coeffs(c, kt, eta_t);
    const double f0 = -kt * x0, f1 = -kt * x1, f2 = -kt * x2;
    const double f_spring = std::sqrt(f0 * f0 + f1 * f1 + f2 * f2);
    const double f_max = mu * std::fabs(fn[c]);
    const bool slip = f_spring > f_max;                        // then f_spring > 0
    // Divisions are unconditional (by 1 where unused) so no branch is needed.
    const double q = f_max / (slip ? f_spring : 1.0);
    const double scale = slip ? q : 1.0;
    const double g0 = f0 * scale, g1 = f1 * scale, g2 = f2 * scale;
    const bool rescale = slip & (kt > 0.0);                    // slip: xi = -F_t/k_t
    const double kd = rescale ? kt : 1.0;
    const double h0 = -g0 / kd, h1 = -g1 / kd, h2 = -g2 / kd;
    xi[0] = rescale ? h0 : x0;
    xi[1] = rescale ? h1 : x1;
    xi[2] = rescale ? h2 : x2;
    ftx[c] = slip ? g0 : f0 - eta_t * vtx[c];                  // stick: dashpot
    fty[c] = slip ? g1 : f1 - eta_t * vty[c];
    ftz[c] = slip ? g2 : f2 - eta_t * vtz[c];
  }
}

}  // namespace domel::plugins::contact
