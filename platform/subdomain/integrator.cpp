// SPDX-License-Identifier: MIT
// The integration passes (integrator.hpp) as restrict-parameter kernels:
// GCC honours __restrict on parameters (not on local pointers), and with ~20
// arrays the alias checks it would otherwise need exceed its versioning
// limit, so the loops would stay scalar. With restrict parameters they
// vectorise.
#include "subdomain/integrator.hpp"

#include "core/neighbor_list.hpp"

#include <cmath>
#include <limits>

namespace domel::platform {

namespace {

/// 1 for a particle whose position or velocity is inf or NaN, else 0, with
/// no branch: !(|x + y + ...| <= max) holds for inf and NaN.
inline double nonfinite(double sum_of_coordinates) {
  return std::fabs(sum_of_coordinates) <= std::numeric_limits<double>::max() ? 0.0 : 1.0;
}

enum Reset { kNoReset = 0, kGravity = 1, kGravityExternal = 2 };

/// Half kick, drift, displacement since the last list build (kCheck), and
/// the force/torque reset to the body forces (kReset). The displacement
/// counts are sums of 0/1 in double: GCC 12 vectorises them, but not a
/// floating-point max without -ffast-math, nor an integer OR of a double
/// comparison. With kFinish it first does the previous step's second half
/// kick (of half_prev, with the same forces) and its finiteness check,
/// counted into `bad`: one sweep over the store per step instead of two.
/// The arithmetic is that of the two passes, value by value.
template <bool kCheck, bool kFinish, int kReset, bool kPack>
void kick_drift_kernel(std::size_t first, std::size_t last, double dt, double half, double half_prev,
                       const double g[3], double* __restrict x, double* __restrict y, double* __restrict z,
                       double* __restrict vx, double* __restrict vy, double* __restrict vz, double* __restrict wx,
                       double* __restrict wy, double* __restrict wz, double* __restrict fx, double* __restrict fy,
                       double* __restrict fz, double* __restrict tx, double* __restrict ty, double* __restrict tz,
                       const double* __restrict im, const double* __restrict ii, const double* __restrict m,
                       const double* __restrict ex, const double* __restrict ey, const double* __restrict ez,
                       const double* __restrict x0, const double* __restrict y0, const double* __restrict z0,
                       const double* __restrict r, double* __restrict pack, double limit2, double limit2_far,
                       DriftCounts& out) {
  const double g0 = g[0], g1 = g[1], g2 = g[2];
  double far = 0.0, tier = 0.0, bad_count = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    double ux = vx[k], uy = vy[k], uz = vz[k], ox = wx[k], oy = wy[k], oz = wz[k];
    const double gx = fx[k], gy = fy[k], gz = fz[k], qx = tx[k], qy = ty[k], qz = tz[k];
    double px = x[k], py = y[k], pz = z[k];
    if constexpr (kFinish) {
      const double hm = half_prev * im[k], hi = half_prev * ii[k];
      ux += hm * gx; uy += hm * gy; uz += hm * gz;
      ox += hi * qx; oy += hi * qy; oz += hi * qz;
      bad_count += nonfinite(px + py + pz + ux + uy + uz);
    }
    const double hm = half * im[k], hi = half * ii[k];
    ux += hm * gx; uy += hm * gy; uz += hm * gz;
    ox += hi * qx; oy += hi * qy; oz += hi * qz;
    px += dt * ux; py += dt * uy; pz += dt * uz;
    vx[k] = ux; vy[k] = uy; vz[k] = uz;
    wx[k] = ox; wy[k] = oy; wz[k] = oz;
    x[k] = px; y[k] = py; z[k] = pz;
    if constexpr (kPack) {
      pack[4 * k] = px; pack[4 * k + 1] = py; pack[4 * k + 2] = pz; pack[4 * k + 3] = r[k];
    }
    if constexpr (kCheck) {
      const double dx = px - x0[k], dy = py - y0[k], dz = pz - z0[k];
      const double d2 = dx * dx + dy * dy + dz * dz;
      far += (d2 > limit2) ? 1.0 : 0.0;
      tier += (d2 > limit2_far) ? 1.0 : 0.0;
    }
    if constexpr (kReset == kGravity) {
      fx[k] = m[k] * g0; fy[k] = m[k] * g1; fz[k] = m[k] * g2;
    } else if constexpr (kReset == kGravityExternal) {
      fx[k] = m[k] * g0 + ex[k]; fy[k] = m[k] * g1 + ey[k]; fz[k] = m[k] * g2 + ez[k];
    }
    if constexpr (kReset != kNoReset) {
      tx[k] = 0.0; ty[k] = 0.0; tz[k] = 0.0;
    }
  }
  out.beyond_skin = far;
  out.beyond_near = tier;
  out.nonfinite = bad_count;
}

using KernelFn = decltype(&kick_drift_kernel<true, true, kGravity, false>);

template <bool kCheck, bool kFinish, bool kPack>
KernelFn pick_reset(int reset) {
  if (reset == kGravity) return &kick_drift_kernel<kCheck, kFinish, kGravity, kPack>;
  if (reset == kGravityExternal) return &kick_drift_kernel<kCheck, kFinish, kGravityExternal, kPack>;
  return &kick_drift_kernel<kCheck, kFinish, kNoReset, kPack>;
}

template <bool kPack>
KernelFn pick(bool check, bool finish, int reset) {
  return check ? (finish ? pick_reset<true, true, kPack>(reset) : pick_reset<true, false, kPack>(reset))
               : (finish ? pick_reset<false, true, kPack>(reset) : pick_reset<false, false, kPack>(reset));
}

double kick_check_kernel(std::size_t first, std::size_t last, double half, const double* __restrict x,
                         const double* __restrict y, const double* __restrict z, double* __restrict vx,
                         double* __restrict vy, double* __restrict vz, double* __restrict wx, double* __restrict wy,
                         double* __restrict wz, const double* __restrict fx, const double* __restrict fy,
                         const double* __restrict fz, const double* __restrict tx, const double* __restrict ty,
                         const double* __restrict tz, const double* __restrict im, const double* __restrict ii) {
  double bad = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    const double hm = half * im[k], hi = half * ii[k];
    vx[k] += hm * fx[k]; vy[k] += hm * fy[k]; vz[k] += hm * fz[k];
    wx[k] += hi * tx[k]; wy[k] += hi * ty[k]; wz[k] += hi * tz[k];
    bad += nonfinite(x[k] + y[k] + z[k] + vx[k] + vy[k] + vz[k]);
  }
  return bad;
}

}  // namespace

void BodyForces::apply(ParticleStore& s, std::size_t first, std::size_t last) const {
  const bool ext = s.has_external_force();
  for (std::size_t k = first; k < last; ++k) {
    s.fx[k] = s.mass[k] * gravity[0];
    s.fy[k] = s.mass[k] * gravity[1];
    s.fz[k] = s.mass[k] * gravity[2];
    if (ext) {
      s.fx[k] += s.ext_fx[k];
      s.fy[k] += s.ext_fy[k];
      s.fz[k] += s.ext_fz[k];
    }
    s.tx[k] = s.ty[k] = s.tz[k] = 0.0;
  }
}

DriftCounts kick_drift(ParticleStore& s, std::size_t first, std::size_t last, const KickDrift& how) {
  const int reset = how.reset ? (s.has_external_force() ? kGravityExternal : kGravity) : kNoReset;
  const bool check = how.check != nullptr;
  const KernelFn kernel = how.pack ? pick<true>(check, how.finish, reset) : pick<false>(check, how.finish, reset);
  static const double kNoGravity[3] = {0, 0, 0};
  const double* g = how.reset ? how.reset->gravity : kNoGravity;
  const double* ex = s.has_external_force() ? s.ext_fx.data() : nullptr;
  const double* ey = s.has_external_force() ? s.ext_fy.data() : nullptr;
  const double* ez = s.has_external_force() ? s.ext_fz.data() : nullptr;
  DriftCounts out;
  kernel(first, last, how.dt, how.half, how.finish_half, g, s.x.data(), s.y.data(), s.z.data(), s.vx.data(),
         s.vy.data(), s.vz.data(), s.wx.data(), s.wy.data(), s.wz.data(), s.fx.data(), s.fy.data(), s.fz.data(),
         s.tx.data(), s.ty.data(), s.tz.data(), s.inv_mass.data(), s.inv_inertia.data(), s.mass.data(), ex, ey, ez,
         check ? how.check->x0() : nullptr, check ? how.check->y0() : nullptr, check ? how.check->z0() : nullptr,
         s.radius.data(), how.pack, check ? how.check->rebuild_displacement2() : 0.0,
         check ? how.check->far_tier_displacement2() : 0.0, out);
  return out;
}

double kick_check(ParticleStore& s, std::size_t first, std::size_t last, double half) {
  return kick_check_kernel(first, last, half, s.x.data(), s.y.data(), s.z.data(), s.vx.data(), s.vy.data(),
                           s.vz.data(), s.wx.data(), s.wy.data(), s.wz.data(), s.fx.data(), s.fy.data(), s.fz.data(),
                           s.tx.data(), s.ty.data(), s.tz.data(), s.inv_mass.data(), s.inv_inertia.data());
}

std::size_t first_nonfinite(const ParticleStore& s) {
  for (std::size_t k = 0; k < s.size(); ++k)
    if (nonfinite(s.x[k] + s.y[k] + s.z[k] + s.vx[k] + s.vy[k] + s.vz[k]) != 0.0) return k;
  return s.size();
}

}  // namespace domel::platform
