// SPDX-License-Identifier: MIT
// Surface-cell cone fit of a heap (see repose_probe.hpp).
#include "subdomain/repose_probe.hpp"

#include "geometry/region.hpp"

#include <cmath>
#include <map>
#include <utility>

namespace domel::platform {

std::optional<double> repose_angle(const ParticleStore& s, const ReposeProbeSettings& settings) {
  const double v2max = settings.max_speed ? *settings.max_speed * *settings.max_speed : 0.0;
  auto counted = [&](std::size_t k) {
    if (s.fixed(k)) return false;
    if (settings.region && !region_contains(*settings.region, s.x[k], s.y[k], s.z[k])) return false;
    return !settings.max_speed || s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k] + s.vz[k] * s.vz[k] < v2max;
  };
  double xc = 0, yc = 0, dsum = 0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!counted(k)) continue;
    xc += s.x[k]; yc += s.y[k]; dsum += 2.0 * s.radius[k];
    ++n;
  }
  if (n < 10) return std::nullopt;
  xc /= n; yc /= n;
  if (settings.planar && settings.crest) (settings.axis == 0 ? xc : yc) = *settings.crest;
  const double cs = settings.cell * dsum / n;
  std::map<std::pair<long, long>, double> top;
  // a cell index beyond what a key holds (a crest 1e300 m away: the run-time
  // fuzzer) has no place in the fit; converting it would be undefined
  constexpr double kMaxCell = 1e18;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!counted(k)) continue;
    const double qx = std::floor((s.x[k] - xc) / cs), qy = std::floor((s.y[k] - yc) / cs);
    if (!(std::abs(qx) < kMaxCell && std::abs(qy) < kMaxCell)) continue;
    const std::pair<long, long> key{static_cast<long>(qx), static_cast<long>(qy)};
    const double h = s.z[k] + s.radius[k] - settings.base_height;
    auto it = top.find(key);
    if (it == top.end() || h > it->second) top[key] = h;
  }
  double hmax = -1e300;
  for (const auto& [key, h] : top) hmax = std::max(hmax, h);
  double sr = 0, sh = 0, srr = 0, srh = 0;
  std::size_t m = 0;
  for (const auto& [key, h] : top) {
    if (!(h > settings.band_lo * hmax && h < settings.band_hi * hmax)) continue;
    const double cx = (key.first + 0.5) * cs, cy = (key.second + 0.5) * cs;
    const double r = !settings.planar ? std::hypot(cx, cy) : std::abs(settings.axis == 0 ? cx : cy);
    sr += r; sh += h; srr += r * r; srh += r * h;
    ++m;
  }
  if (m < 3) return std::nullopt;
  const double den = m * srr - sr * sr;
  if (den <= 0) return std::nullopt;
  const double slope = (m * srh - sr * sh) / den;
  if (slope >= 0) return std::nullopt;
  return std::atan(-slope) * 180.0 / M_PI;
}

}  // namespace domel::platform
