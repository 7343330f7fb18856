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
  for (uint32_t c = 0; c < b.n; ++c) {
    double* xi = b.history + static_cast<size_t>(c) * s;
    const double nx = b.nx[c], ny = b.ny[c], nz = b.nz[c];
    const double proj = xi[0] * nx + xi[1] * ny + xi[2] * nz;
    double x0 = xi[0] - proj * nx + b.vtx[c] * dt;
    double x1 = xi[1] - proj * ny + b.vty[c] * dt;
    double x2 = xi[2] - proj * nz + b.vtz[c] * dt;
    double kt, eta_t;
    coeffs(c, kt, eta_t);
    double f0 = -kt * x0, f1 = -kt * x1, f2 = -kt * x2;
    const double f_spring = std::sqrt(f0 * f0 + f1 * f1 + f2 * f2);
    const double f_max = mu * std::fabs(b.fn[c]);
    if (f_spring > f_max) {
      const double scale = f_spring > 0.0 ? f_max / f_spring : 0.0;
      f0 *= scale; f1 *= scale; f2 *= scale;
      if (kt > 0.0) { x0 = -f0 / kt; x1 = -f1 / kt; x2 = -f2 / kt; }
    } else {
      f0 -= eta_t * b.vtx[c]; f1 -= eta_t * b.vty[c]; f2 -= eta_t * b.vtz[c];
    }
    xi[0] = x0; xi[1] = x1; xi[2] = x2;
    b.ftx[c] = f0; b.fty[c] = f1; b.ftz[c] = f2;
  }
}

}  // namespace domel::plugins::contact
