// SPDX-License-Identifier: MIT
// Shared geometry of the built-in insertion models: checks of an insertion
// region handed over through the ABI (domel_region_v1: shape 1 box, shape 2
// cylinder), its axis-aligned bounding box and volume, the test "does a
// sphere lie fully inside the region" (the sphere radius is the margin), and
// SphereGrid, a uniform cell grid answering "does this sphere overlap any
// stored sphere" in O(1) for the model's own particles and the particles
// already present. All lengths are in metres (SI), as everywhere in the ABI.
#pragma once

#include <domel/sdk/abi.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace domel::plugins::insertion {

constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kRegionBox = 1;       ///< domel_region_v1::shape of a box [lo, hi]
constexpr uint32_t kRegionCylinder = 2;  ///< domel_region_v1::shape of a cylinder

/// An axis-aligned box [lo, hi].
struct Bounds {
  double lo[3];
  double hi[3];
};

/// Throws std::runtime_error (message prefixed by `model`) unless the region
/// is a well-formed box or cylinder. Call before using the other helpers.
inline void check_region(const domel_region_v1& g, const char* model) {
  const std::string who = std::string(model) + ": ";
  auto finite = [](double v) { return std::isfinite(v); };
  for (int k = 0; k < 3; ++k)
    if (!finite(g.lo[k]) || !finite(g.hi[k]))
      throw std::runtime_error(who + "the insertion region has a non-finite corner");
  if (g.shape == kRegionBox) {
    for (int k = 0; k < 3; ++k)
      if (!(g.hi[k] > g.lo[k]))
        throw std::runtime_error(who + "the insertion box is empty: max must exceed min on every axis");
    return;
  }
  if (g.shape == kRegionCylinder) {
    if (g.axis > 2) throw std::runtime_error(who + "the insertion cylinder has an invalid axis");
    if (!finite(g.radius) || !(g.radius > 0.0))
      throw std::runtime_error(who + "the insertion cylinder needs a radius > 0");
    for (int k = 0; k < 3; ++k)
      if (!finite(g.center[k])) throw std::runtime_error(who + "the insertion cylinder has a non-finite center");
    if (!(g.hi[g.axis] > g.lo[g.axis]))
      throw std::runtime_error(who + "the insertion cylinder is empty: top must exceed bottom");
    return;
  }
  throw std::runtime_error(who + "unknown insertion region shape " + std::to_string(g.shape) +
                           " (1 box, 2 cylinder)");
}

/// Axis-aligned bounding box of the region. For a cylinder the axial extent
/// is lo[axis]..hi[axis] and the other two axes are center +- radius.
inline Bounds region_bounds(const domel_region_v1& g) {
  Bounds b{};
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = g.lo[k];
    b.hi[k] = g.hi[k];
  }
  if (g.shape == kRegionCylinder) {
    for (int k = 0; k < 3; ++k) {
      if (static_cast<uint32_t>(k) == g.axis) continue;
      b.lo[k] = g.center[k] - g.radius;
      b.hi[k] = g.center[k] + g.radius;
    }
  }
  return b;
}

/// Region volume [m^3]: box product of the extents; cylinder pi r^2 length.
inline double region_volume(const domel_region_v1& g) {
  if (g.shape == kRegionCylinder)
    return kPi * g.radius * g.radius * (g.hi[g.axis] - g.lo[g.axis]);
  return (g.hi[0] - g.lo[0]) * (g.hi[1] - g.lo[1]) * (g.hi[2] - g.lo[2]);
}

/// Absolute slack of the inside test: far below any particle size, large
/// enough that a sphere exactly touching the boundary (lattice sites computed
/// as lo + (i + 0.5) a) is not lost to rounding.
inline double region_tolerance(const domel_region_v1& g) {
  const Bounds b = region_bounds(g);
  double scale = 0.0;
  for (int k = 0; k < 3; ++k) scale = std::max({scale, std::fabs(b.lo[k]), std::fabs(b.hi[k])});
  return 1e-12 * scale;
}

/// True when the sphere of radius r centred at (x, y, z) lies fully inside
/// the region (touching the boundary counts as inside).
inline bool sphere_inside(const domel_region_v1& g, double x, double y, double z, double r) {
  const double p[3] = {x, y, z};
  const double tol = region_tolerance(g);
  if (g.shape == kRegionCylinder) {
    const uint32_t a = g.axis;
    if (p[a] - r < g.lo[a] - tol || p[a] + r > g.hi[a] + tol) return false;
    const uint32_t u = (a + 1) % 3, v = (a + 2) % 3;
    const double du = p[u] - g.center[u], dv = p[v] - g.center[v];
    return std::sqrt(du * du + dv * dv) + r <= g.radius + tol;
  }
  for (int k = 0; k < 3; ++k)
    if (p[k] - r < g.lo[k] - tol || p[k] + r > g.hi[k] + tol) return false;
  return true;
}

/// Euclidean distance from a point to the box (0 inside it).
inline double distance_to_bounds(const Bounds& b, double x, double y, double z) {
  const double p[3] = {x, y, z};
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({b.lo[k] - p[k], 0.0, p[k] - b.hi[k]});
    s += d * d;
  }
  return std::sqrt(s);
}

/// Uniform cell grid over a box holding spheres, for overlap queries. Cells
/// are cubes of edge >= min_cell; the edge grows when the box would need
/// more than about `cell_budget` cells (huge regions, few particles).
/// Spheres whose centre lies outside the box are kept in the nearest border
/// cell, which stays correct because queries search as many cells as the
/// largest stored radius requires.
class SphereGrid {
 public:
  SphereGrid(const Bounds& box, double min_cell, std::size_t cell_budget) : box_(box) {
    cell_budget = std::max<std::size_t>(cell_budget, 1);
    double volume = 1.0;
    for (int k = 0; k < 3; ++k) volume *= std::max(box_.hi[k] - box_.lo[k], 0.0);
    h_ = std::max(min_cell, std::cbrt(volume / static_cast<double>(cell_budget)));
    if (!(h_ > 0.0)) h_ = 1.0;
    for (;;) {
      double n[3], cells = 1.0;
      for (int k = 0; k < 3; ++k) {
        n[k] = std::max(1.0, std::ceil((box_.hi[k] - box_.lo[k]) / h_));  // NaN (an infinite extent): 1
        cells *= n[k];
      }
      if (cells <= 2.0 * static_cast<double>(cell_budget) + 8.0) {
        for (int k = 0; k < 3; ++k) n_[k] = static_cast<long long>(n[k]);  // counted first: no overflow
        break;
      }
      // thin boxes: ceil() on each axis inflated the count; a box far longer
      // than wide (1e300 m by 1 cm: the run-time fuzzer) needs far larger cells
      h_ *= std::max(1.25, std::cbrt(cells / (2.0 * static_cast<double>(cell_budget))));
    }
    head_.assign(static_cast<std::size_t>(n_[0] * n_[1] * n_[2]), kNone);
  }

  void add(double x, double y, double z, double r) {
    const std::size_t id = r_.size();
    x_.push_back(x); y_.push_back(y); z_.push_back(z); r_.push_back(r);
    r_max_ = std::max(r_max_, r);
    const std::size_t c = cell(coord(0, x), coord(1, y), coord(2, z));
    next_.push_back(head_[c]);
    head_[c] = id;
  }

  /// True when the sphere overlaps a stored one: |x_i - x_j| < r_i + r_j.
  bool overlaps(double x, double y, double z, double r) const {
    if (r_.empty()) return false;
    const long long reach = static_cast<long long>(std::ceil((r + r_max_) / h_));
    const long long c[3] = {coord(0, x), coord(1, y), coord(2, z)};
    long long lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max(0LL, c[k] - reach);
      hi[k] = std::min(n_[k] - 1, c[k] + reach);
    }
    for (long long iz = lo[2]; iz <= hi[2]; ++iz)
      for (long long iy = lo[1]; iy <= hi[1]; ++iy)
        for (long long ix = lo[0]; ix <= hi[0]; ++ix)
          for (std::size_t j = head_[cell(ix, iy, iz)]; j != kNone; j = next_[j]) {
            const double dx = x - x_[j], dy = y - y_[j], dz = z - z_[j];
            const double s = r + r_[j];
            if (dx * dx + dy * dy + dz * dz < s * s) return true;
          }
    return false;
  }

  std::size_t size() const { return r_.size(); }
  double cell_size() const { return h_; }

 private:
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

  long long coord(int k, double p) const {
    const double t = std::floor((p - box_.lo[k]) / h_);
    if (!(t > 0.0)) return 0;  // also catches NaN
    if (t >= static_cast<double>(n_[k] - 1)) return n_[k] - 1;
    return static_cast<long long>(t);
  }
  std::size_t cell(long long ix, long long iy, long long iz) const {
    return static_cast<std::size_t>((iz * n_[1] + iy) * n_[0] + ix);
  }

  Bounds box_;
  double h_ = 1.0;
  long long n_[3] = {1, 1, 1};
  double r_max_ = 0.0;
  std::vector<std::size_t> head_, next_;
  std::vector<double> x_, y_, z_, r_;
};

/// Indices of the particles already present (req.ex_*) that could overlap a
/// sphere of radius up to r_new lying inside `box`: those whose centre is
/// closer to the box than r_new + their own radius. The rest are ignored.
inline std::vector<std::size_t> nearby_existing(const domel_insert_request_v1& req, const Bounds& box,
                                                double r_new) {
  std::vector<std::size_t> keep;
  if (req.n_existing == 0 || !req.ex_x || !req.ex_y || !req.ex_z || !req.ex_r) return keep;
  for (std::size_t i = 0; i < req.n_existing; ++i)
    if (distance_to_bounds(box, req.ex_x[i], req.ex_y[i], req.ex_z[i]) < r_new + req.ex_r[i])
      keep.push_back(i);
  return keep;
}

/// Checks the coarse-grain ratio of a request; returns it.
inline double checked_length_scale(const domel_insert_request_v1& req, const char* model) {
  const double alpha = req.length_scale;
  if (!std::isfinite(alpha) || !(alpha > 0.0))
    throw std::runtime_error(std::string(model) + ": the coarse-grain ratio (length_scale) must be > 0");
  return alpha;
}

}  // namespace domel::plugins::insertion
