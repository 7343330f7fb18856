// SPDX-License-Identifier: MIT
// Insertion model "random": non-overlapping spheres at random positions by
// Sequential Simple Inhibition, also called random sequential addition (RSA;
// Widom, J. Chem. Phys. 44, 3888 (1966); Diggle, Statistical Analysis of
// Spatial Point Patterns (1983)). Particles are placed one after another:
// each draws its diameter (uniform in [diameter, diameter_max] when a range
// is given, times the coarse-grain ratio alpha of the request), then draws
// candidate centres uniformly over the set where the sphere lies fully
// inside the region, and keeps the first candidate that overlaps
// (|x_i - x_j| < r_i + r_j) neither an accepted particle nor a particle
// already present. A uniform cell grid (cell edge >= the largest diameter)
// makes each check O(1). The number of particles is `count`, or follows
// from `volume_fraction`: round(region volume * phi / mean sphere volume),
// with the mean of d^3 for a uniform diameter in [a, b] being
// (b^4 - a^4) / (4 (b - a)). RSA cannot exceed its jamming limit, a volume
// fraction of about 0.383 in 3-D (Torquato, Uche & Stillinger, Phys. Rev. E
// 74, 061308 (2006)), and gets slow well before it; bounded regions jam
// earlier still because of their walls. A particle that finds no place in
// max_attempts draws makes the insertion fail with an explanation.
// With a `distribution` (domel/sdk/size_distribution.hpp) every diameter is
// drawn first and the spheres are placed largest first, since RSA rejects a
// large sphere more often than a small one and would otherwise jam before
// the large ones are in; the placed spheres are then handed over in random
// order, so that any first part of them (a pour keeps the first ones until
// its mass is reached) has the requested composition. A mixture's
// particles (several materials) are drawn and placed together, each keeping
// its component for the host.
// Deterministic: std::mt19937_64 seeded with the request's seed.
// Units: diameters in m; volume_fraction dimensionless.
#pragma once

#include "region.hpp"

#include <domel/sdk/plugin.hpp>
#include <domel/sdk/size_distribution.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace domel::plugins::insertion {

class RandomFill {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_INSERTION;
  static constexpr const char* kName = "random";
  static constexpr const char* kVersion = "1.2.0";
  static constexpr const char* kSummary =
      "non-overlapping spheres at random positions (sequential simple inhibition / RSA)";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Random sequential addition of non-overlapping spheres inside the region. Give exactly one of count or volume_fraction.",
  "properties": {
    "model": { "const": "random", "description": "insertion model name" },
    "diameter": { "type": "number", "exclusiveMinimum": 0, "x-unit": "m",
                  "description": "particle diameter, or the smallest diameter when diameter_max is given (multiplied by the subdomain's coarse-grain ratio alpha)" },
    "diameter_max": { "type": "number", "exclusiveMinimum": 0, "x-unit": "m",
                      "description": "largest diameter: diameters are then uniform in [diameter, diameter_max]; must not be below diameter" },
    "distribution": { "type": "object", "description": "particle diameters drawn from a distribution by number, in place of diameter (multiplied by alpha): {\"type\": \"uniform\", \"min\", \"max\"}, {\"type\": \"normal\", \"mean\", \"std\", \"min\", \"max\"} (truncated, default mean +- 3 std), {\"type\": \"lognormal\", \"median\", \"sigma\" (of ln d), \"min\", \"max\"} (truncated, default median e^(+-3 sigma)) or {\"type\": \"table\", \"diameters\": [...], \"fractions\": [...], \"by\": \"number\" or \"mass\"}, or a mixture of materials {\"type\": \"mixture\", \"by\": \"mass\" | \"volume\" | \"number\", \"components\": [{\"material\", \"fraction\", \"diameter\" or \"distribution\"}, ...]}; docs/getting-started.md, \"Size distributions\" and \"Mixtures\"" },
    "count": { "type": "integer", "minimum": 1, "maximum": 100000000,
               "description": "number of particles to insert" },
    "volume_fraction": { "type": "number", "exclusiveMinimum": 0, "maximum": 0.38, "x-unit": "1",
                         "description": "target solid volume fraction of the region; the count is region volume * fraction / mean sphere volume. At most 0.38, about the jamming limit of random sequential addition in 3-D; walls make bounded regions jam lower and filling beyond about 0.3 gets slow and may fail, so use the lattice model for dense packings" },
    "max_attempts": { "type": "integer", "minimum": 1, "maximum": 1000000000, "default": 1000,
                      "description": "candidate positions drawn for one particle before the insertion fails" }
  },
  "allOf": [ { "oneOf": [ { "required": ["count"] }, { "required": ["volume_fraction"] } ] },
             { "oneOf": [ { "required": ["diameter"] }, { "required": ["distribution"] } ] } ],
  "additionalProperties": false
})json";

  explicit RandomFill(const sdk::Params& p)
      : host_(p.host()), d_min_(p.has("distribution") ? 1.0 : p.number("diameter")), d_max_(p.number_or("diameter_max", d_min_)) {
    if (p.has("distribution")) {
      if (p.has("diameter") || p.has("diameter_max"))
        throw sdk::ParameterError("random: give either 'distribution' or 'diameter' (and 'diameter_max'), not both");
      distribution_ = sdk::SizeDistribution::parse(p.json().at("distribution"), "random: 'distribution'");
      has_distribution_ = true;
      d_min_ = distribution_.min();
      d_max_ = distribution_.max();
    }
    if (!std::isfinite(d_min_) || !(d_min_ > 0.0))
      throw sdk::ParameterError("random: 'diameter' must be > 0");
    if (!std::isfinite(d_max_) || !(d_max_ > 0.0))
      throw sdk::ParameterError("random: 'diameter_max' must be > 0");
    if (d_max_ < d_min_) {
      std::ostringstream m;
      m << "random: 'diameter_max' " << d_max_ << " is below 'diameter' " << d_min_;
      throw sdk::ParameterError(m.str());
    }
    const bool has_count = p.has("count"), has_fraction = p.has("volume_fraction");
    if (has_count == has_fraction)
      throw sdk::ParameterError("random: give exactly one of 'count' or 'volume_fraction'");
    if (has_count) {
      const double c = p.number("count");
      if (!(c >= 1.0) || c != std::floor(c) || c > kMaxParticles)
        throw sdk::ParameterError("random: 'count' must be an integer in [1, 1e8]");
      count_ = static_cast<std::size_t>(c);
    } else {
      volume_fraction_ = p.number("volume_fraction");
      if (!(volume_fraction_ > 0.0) || !(volume_fraction_ <= kJammingLimit))
        throw sdk::ParameterError(
            "random: 'volume_fraction' must be in (0, 0.38]; random sequential addition jams "
            "near 0.38 — use the lattice model for denser packings");
    }
    const double attempts = p.number_or("max_attempts", 1000.0);
    if (!(attempts >= 1.0) || attempts != std::floor(attempts) || attempts > 1e12)
      throw sdk::ParameterError("random: 'max_attempts' must be an integer >= 1");
    max_attempts_ = static_cast<std::size_t>(attempts);
  }

  void insert(const domel_insert_request_v1& req, sdk::Inserted& out) const {
    const domel_region_v1& g = req.region;
    check_region(g, kName);
    const double alpha = checked_length_scale(req, kName);
    const double d_lo = d_min_ * alpha, d_hi = d_max_ * alpha;
    const double volume = region_volume(g);
    const std::size_t target = target_count(volume, d_lo, d_hi, alpha);
    out.expect(static_cast<double>(target));
    const Bounds b = region_bounds(g);

    const auto nearby = nearby_existing(req, b, 0.5 * d_hi);
    SphereGrid grid(b, d_hi, std::max<std::size_t>(1024, 2 * (target + nearby.size())));
    for (std::size_t i : nearby) grid.add(req.ex_x[i], req.ex_y[i], req.ex_z[i], req.ex_r[i]);

    std::mt19937_64 rng(req.seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // a distribution: every diameter first, placed largest first into a
    // buffer that is handed over shuffled (see the file's comment)
    // (a mixture's particles carry their component along)
    std::vector<sdk::SizeDistribution::Draw> drawn;
    std::vector<std::uint32_t> placed_component;
    sdk::Inserted placed_sorted;
    sdk::Inserted& dest = has_distribution_ ? placed_sorted : out;
    const bool mixture = has_distribution_ && distribution_.type() == sdk::SizeDistribution::Type::mixture;
    if (has_distribution_) {
      drawn.resize(target);
      for (auto& d : drawn) {
        d = distribution_.draw(rng);
        d.diameter *= alpha;
      }
      std::sort(drawn.begin(), drawn.end(), [](const auto& a, const auto& b) { return a.diameter > b.diameter; });
    }
    dest.x.reserve(target); dest.y.reserve(target); dest.z.reserve(target); dest.r.reserve(target);
    double solid = 0.0;     // volume of the spheres placed so far
    std::size_t tried = 0;  // attempts so far: a stop request is looked at every 4096
    for (std::size_t n = 0; n < target; ++n) {
      const double d = has_distribution_ ? drawn[n].diameter : d_hi > d_lo ? d_lo + (d_hi - d_lo) * unit(rng) : d_lo;
      const double r = 0.5 * d;
      check_fits(g, r);
      bool placed = false;
      for (std::size_t attempt = 0; attempt < max_attempts_ && !placed; ++attempt) {
        if ((++tried & 4095) == 0 && host_.stop_requested())
          throw sdk::StopRequested("random: stopped on request after placing " + std::to_string(n) + " of " +
                                   std::to_string(target) + " particles");
        double p[3];
        draw_centre(g, r, rng, unit, p);
        if (grid.overlaps(p[0], p[1], p[2], r)) continue;
        grid.add(p[0], p[1], p[2], r);
        dest.push(p[0], p[1], p[2], r);
        if (mixture) placed_component.push_back(drawn[n].component);
        solid += kPi / 6.0 * d * d * d;
        placed = true;
      }
      if (!placed) {
        std::ostringstream m;
        m << "random: placed " << n << " of " << target << " particles in the region (volume fraction "
          << std::setprecision(3) << solid / volume << ") before " << max_attempts_
          << " attempts failed; random sequential addition jams near volume fraction 0.38"
             " — use a larger region, fewer particles or the lattice model";
        throw std::runtime_error(m.str());
      }
    }
    if (has_distribution_) {
      std::vector<std::size_t> order(placed_sorted.size());
      for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::shuffle(order.begin(), order.end(), rng);
      for (std::size_t k : order)
        if (mixture)
          out.push(placed_sorted.x[k], placed_sorted.y[k], placed_sorted.z[k], placed_sorted.r[k], placed_component[k]);
        else
          out.push(placed_sorted.x[k], placed_sorted.y[k], placed_sorted.z[k], placed_sorted.r[k]);
    }
  }

 private:
  static constexpr double kJammingLimit = 0.38;
  static constexpr double kMaxParticles = 1e8;

  /// Particles to insert: `count`, or from the volume fraction with the mean
  /// sphere volume (pi/6) E[d^3] of the diameter distribution.
  std::size_t target_count(double volume, double d_lo, double d_hi, double alpha) const {
    if (count_ != 0) return count_;
    const double mean_d3 = has_distribution_ ? distribution_.mean_cube() * alpha * alpha * alpha
                           : d_hi > d_lo     ? (std::pow(d_hi, 4) - std::pow(d_lo, 4)) / (4.0 * (d_hi - d_lo))
                                             : d_lo * d_lo * d_lo;
    const double n = std::round(volume * volume_fraction_ / (kPi / 6.0 * mean_d3));
    if (!(n >= 1.0)) {
      std::ostringstream m;
      m << "random: volume fraction " << volume_fraction_ << " of the region (" << volume
        << " m^3) is less than half a particle; enlarge the region or use 'count'";
      throw std::runtime_error(m.str());
    }
    if (n > kMaxParticles) {
      std::ostringstream m;
      m << "random: volume fraction " << volume_fraction_ << " asks for " << n
        << " particles, more than " << kMaxParticles << "; check the diameter's units";
      throw std::runtime_error(m.str());
    }
    return static_cast<std::size_t>(n);
  }

  /// Refuses a particle that cannot lie inside the region at all.
  static void check_fits(const domel_region_v1& g, double r) {
    bool fits = true;
    if (g.shape == kRegionCylinder) {
      fits = g.hi[g.axis] - g.lo[g.axis] >= 2.0 * r && g.radius >= r;
    } else {
      for (int k = 0; k < 3; ++k) fits = fits && g.hi[k] - g.lo[k] >= 2.0 * r;
    }
    if (!fits) {
      std::ostringstream m;
      m << "random: a particle of diameter " << 2.0 * r << " m does not fit inside the region";
      throw std::runtime_error(m.str());
    }
  }

  /// A centre drawn uniformly over the set where the sphere of radius r lies
  /// inside the region (box: shrunk box; cylinder: shrunk disk by sqrt-radius
  /// sampling times the shrunk axial range).
  static void draw_centre(const domel_region_v1& g, double r, std::mt19937_64& rng,
                          std::uniform_real_distribution<double>& unit, double p[3]) {
    if (g.shape == kRegionCylinder) {
      const uint32_t a = g.axis, u = (a + 1) % 3, v = (a + 2) % 3;
      const double s = unit(rng), t = unit(rng), w = unit(rng);
      const double rho = (g.radius - r) * std::sqrt(s);
      const double phi = 2.0 * kPi * t;
      p[u] = g.center[u] + rho * std::cos(phi);
      p[v] = g.center[v] + rho * std::sin(phi);
      p[a] = g.lo[a] + r + (g.hi[a] - g.lo[a] - 2.0 * r) * w;
      return;
    }
    for (int k = 0; k < 3; ++k) p[k] = g.lo[k] + r + (g.hi[k] - g.lo[k] - 2.0 * r) * unit(rng);
  }

  sdk::Host host_;
  double d_min_;
  double d_max_;
  sdk::SizeDistribution distribution_;
  bool has_distribution_ = false;
  std::size_t count_ = 0;         // 0: use volume_fraction_
  double volume_fraction_ = 0.0;
  std::size_t max_attempts_ = 1000;
};

}  // namespace domel::plugins::insertion
