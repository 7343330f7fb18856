// SPDX-License-Identifier: MIT
// Insertion model "lattice": equal spheres on a simple cubic lattice filling
// the insertion region. With d the diameter and alpha the coarse-grain ratio
// of the request, the lattice constant is a = spacing * d * alpha; on each
// axis of the region's bounding box the sites are lo + (i + 0.5) a for
// i = 0 .. floor((hi - lo)/a + 1e-9) - 1, visited x fastest, then y, then z
// (a column fills from the bottom). This is the site rule of the LIGGGHTS
// benchmark deck's initial packing, reproduced exactly so that runs can be
// compared particle by particle. Only sites whose sphere (radius d alpha / 2,
// before jitter) lies fully inside the region are used (this trims the
// corners of a cylinder); sites whose sphere would overlap a particle
// already present are skipped and not counted; insertion stops after
// `count` particles. Optional jitter displaces each coordinate uniformly in
// [-jitter d alpha, +jitter d alpha] (std::mt19937_64 seeded with the
// request's seed, so a fixed seed gives the same packing); jitter is limited
// to (spacing - 1)/2 so neighbours can never overlap, and a jittered sphere
// that would leave the region is kept at its unjittered site.
// Units: diameter in m; spacing and jitter are multiples of the diameter.
#pragma once

#include "region.hpp"

#include <domel/sdk/plugin.hpp>
#include <domel/sdk/size_distribution.hpp>

#include <optional>

#include <cmath>
#include <cstddef>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace domel::plugins::insertion {

class Lattice {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_INSERTION;
  static constexpr const char* kName = "lattice";
  static constexpr const char* kVersion = "1.3.0";
  static constexpr const char* kSummary =
      "equal spheres on a simple cubic lattice filling the region, optionally jittered";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Equal spheres on a simple cubic lattice of constant spacing*diameter*alpha, sites at lo + (i+0.5)a in the region's bounding box, x fastest then y then z; only sites whose sphere lies inside the region are used.",
  "properties": {
    "model": { "const": "lattice", "description": "insertion model name" },
    "diameter": { "type": "number", "exclusiveMinimum": 0, "x-unit": "m",
                  "description": "particle diameter d (multiplied by the subdomain's coarse-grain ratio alpha)" },
    "spacing": { "type": "number", "minimum": 1, "default": 1.0, "x-unit": "1",
                 "description": "lattice constant as a multiple of the diameter; 1 puts neighbours in contact" },
    "jitter": { "type": "number", "minimum": 0, "default": 0, "x-unit": "1",
                "description": "each coordinate is displaced uniformly in [-jitter*d, +jitter*d]; at most (spacing-1)/2 so that particles cannot overlap" },
    "count": { "type": "integer", "minimum": 1, "maximum": 100000000,
               "description": "stop after this many particles (default: fill every site)" },
    "arrangement": { "enum": ["simple_cubic"], "default": "simple_cubic",
                     "description": "lattice type" },
    "distribution": { "type": "object", "description": "particle diameters drawn from a distribution by number, in place of diameter; the lattice is spaced for the largest (multiplied by alpha): {\"type\": \"uniform\", \"min\", \"max\"}, {\"type\": \"normal\", \"mean\", \"std\", \"min\", \"max\"} (truncated, default mean +- 3 std), {\"type\": \"lognormal\", \"median\", \"sigma\" (of ln d), \"min\", \"max\"} (truncated, default median e^(+-3 sigma)) or {\"type\": \"table\", \"diameters\": [...], \"fractions\": [...], \"by\": \"number\" or \"mass\"}, or a mixture of materials {\"type\": \"mixture\", \"by\": \"mass\" | \"volume\" | \"number\", \"components\": [{\"material\", \"fraction\", \"diameter\" or \"distribution\"}, ...]}; docs/getting-started.md, \"Size distributions\" and \"Mixtures\"" },
    "origin": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3, "x-unit": "m",
                "description": "anchor the lattice: sites at origin + (i + 0.5) a for integer i (default: the region's lower corner), e.g. to reproduce another code's lattice" }
  },
  "oneOf": [ { "required": ["diameter"] }, { "required": ["distribution"] } ],
  "additionalProperties": false
})json";

  explicit Lattice(const sdk::Params& p)
      : diameter_(p.has("distribution") ? largest(p) : p.number("diameter")),
        spacing_(p.number_or("spacing", 1.0)),
        jitter_(p.number_or("jitter", 0.0)) {
    if (!std::isfinite(diameter_) || !(diameter_ > 0.0))
      throw sdk::ParameterError("lattice: 'diameter' must be > 0");
    if (!std::isfinite(spacing_) || !(spacing_ >= 1.0))
      throw sdk::ParameterError("lattice: 'spacing' must be >= 1 (a multiple of the diameter)");
    if (!std::isfinite(jitter_) || !(jitter_ >= 0.0))
      throw sdk::ParameterError("lattice: 'jitter' must be >= 0");
    const double jitter_limit = 0.5 * (spacing_ - 1.0);
    if (jitter_ > jitter_limit + 1e-12) {
      std::ostringstream m;
      m << "lattice: 'jitter' " << jitter_ << " exceeds (spacing - 1)/2 = " << jitter_limit
        << " and could make neighbouring particles overlap; lower the jitter or raise the spacing";
      throw sdk::ParameterError(m.str());
    }
    if (p.has("count")) {
      const double c = p.number("count");
      if (!(c >= 1.0) || c != std::floor(c) || c > 1e15)
        throw sdk::ParameterError("lattice: 'count' must be an integer >= 1");
      count_ = static_cast<std::size_t>(c);
    }
    if (p.has("origin")) {
      const auto& o = p.json().at("origin");
      if (!o.is_array() || o.size() != 3) throw sdk::ParameterError("lattice: 'origin' must be [x, y, z]");
      for (int k = 0; k < 3; ++k) origin_[k] = o[k].get<double>();
      has_origin_ = true;
    }
    const std::string arrangement = p.string_or("arrangement", "simple_cubic");
    if (arrangement != "simple_cubic")
      throw sdk::ParameterError("lattice: unknown 'arrangement' '" + arrangement +
                                "' (supported: simple_cubic)");
  }

  void insert(const domel_insert_request_v1& req, sdk::Inserted& out) const {
    const domel_region_v1& g = req.region;
    check_region(g, kName);
    const double alpha = checked_length_scale(req, kName);
    const double d = diameter_ * alpha;
    const double r = 0.5 * d;
    const double a = spacing_ * d;
    const double jitter = jitter_ * d;
    const Bounds b = region_bounds(g);

    // sites at base + (i + 0.5) a for i = first[k] .. first[k] + n[k] - 1
    long long n[3], first[3] = {0, 0, 0};
    double base[3] = {b.lo[0], b.lo[1], b.lo[2]};
    double sites = 1.0;
    for (int k = 0; k < 3; ++k) {
      double f;
      if (has_origin_) {
        base[k] = origin_[k];
        const double i0 = std::ceil((b.lo[k] - base[k]) / a - 0.5 - 1e-9);
        const double i1 = std::floor((b.hi[k] - base[k]) / a - 0.5 + 1e-9);
        // a site index must be an integer the loop can count to (a tiny
        // diameter or a far origin gives an infinite or huge one)
        if (!(std::fabs(i0) <= 1e15) || !(std::fabs(i1) <= 1e15)) {
          std::ostringstream m;
          m << "lattice: the region lies more than 1e15 lattice spacings of " << a << " m from 'origin' ("
            << origin_[k] << " m along " << "xyz"[k] << "); check the diameter's units or the origin";
          throw std::runtime_error(m.str());
        }
        f = i1 - i0 + 1.0;
        first[k] = static_cast<long long>(i0);
      } else {
        f = std::floor((b.hi[k] - b.lo[k]) / a + 1e-9);
      }
      // the sites are visited one by one, those outside the region too: rows
      // of 1e10 (a diameter of 1e-12 m, or 5e-324: the run-time fuzzer) took
      // a minute, or for ever, even with a count a few of them would reach
      if (!(f <= kMaxSitesAlong)) {
        std::ostringstream m;
        m << "lattice: the region spans " << f << " lattice spacings of " << a << " m along " << "xyz"[k]
          << ", more than " << kMaxSitesAlong << "; check the diameter's units";
        throw std::runtime_error(m.str());
      }
      sites *= std::max(f, 0.0);
      n[k] = f > 0.0 ? static_cast<long long>(std::min(f, 1e15)) : 0;
    }
    out.expect(count_ == 0 ? sites : std::min(sites, static_cast<double>(count_)));
    if (count_ == 0 && sites > kMaxSites) {
      std::ostringstream m;
      m << "lattice: the region holds " << sites << " lattice sites of spacing " << a
        << " m, more than " << kMaxSites << "; check the diameter's units or set 'count'";
      throw std::runtime_error(m.str());
    }

    std::unique_ptr<SphereGrid> existing;
    const auto nearby = nearby_existing(req, b, r);
    if (!nearby.empty()) {
      existing = std::make_unique<SphereGrid>(b, d, std::max<std::size_t>(1024, 2 * nearby.size()));
      for (std::size_t i : nearby) existing->add(req.ex_x[i], req.ex_y[i], req.ex_z[i], req.ex_r[i]);
    }

    std::mt19937_64 rng(req.seed);
    std::mt19937_64 sizes(req.seed ^ 0x9e3779b97f4a7c15ull);  // the diameters' own stream: the jitter's is unchanged
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    bool any_site = false;
    for (long long iz = 0; iz < n[2]; ++iz)
      for (long long iy = 0; iy < n[1]; ++iy)
        for (long long ix = 0; ix < n[0]; ++ix) {
          const double sx = base[0] + (static_cast<double>(first[0] + ix) + 0.5) * a;
          const double sy = base[1] + (static_cast<double>(first[1] + iy) + 0.5) * a;
          const double sz = base[2] + (static_cast<double>(first[2] + iz) + 0.5) * a;
          if (!sphere_inside(g, sx, sy, sz, r)) continue;
          any_site = true;
          double x = sx, y = sy, z = sz;
          if (jitter > 0.0) {
            x += jitter * unit(rng);
            y += jitter * unit(rng);
            z += jitter * unit(rng);
            if (!sphere_inside(g, x, y, z, r)) { x = sx; y = sy; z = sz; }
          }
          if (existing && existing->overlaps(x, y, z, r)) continue;
          if (!distribution_) {
            out.push(x, y, z, r);
          } else if (distribution_->type() != sdk::SizeDistribution::Type::mixture) {
            out.push(x, y, z, 0.5 * alpha * distribution_->sample(sizes));
          } else {  // each site draws its component and diameter: the components interleave
            const auto dr = distribution_->draw(sizes);
            out.push(x, y, z, 0.5 * alpha * dr.diameter, dr.component);
          }
          if (count_ != 0 && out.size() >= count_) return;
        }
    if (!any_site) {
      std::ostringstream m;
      m << "lattice: no lattice site of spacing " << a << " m holds a sphere of diameter " << d
        << " m inside the region; the region is too small for this diameter";
      throw std::runtime_error(m.str());
    }
  }

 private:
  static constexpr double kMaxSites = 2e8;
  static constexpr double kMaxSitesAlong = 1e7;  ///< lattice sites along one axis of the region's box

  /// A distribution's largest diameter, which spaces the lattice.
  double largest(const sdk::Params& p) {
    if (p.has("diameter")) throw sdk::ParameterError("lattice: give either 'distribution' or 'diameter', not both");
    distribution_ = sdk::SizeDistribution::parse(p.json().at("distribution"), "lattice: 'distribution'");
    return distribution_->max();
  }

  /// Diameters by number; the lattice is spaced for the largest. Declared
  /// first: diameter_'s initialiser (largest()) sets it.
  std::optional<sdk::SizeDistribution> distribution_;
  double diameter_;
  double spacing_;
  double jitter_;
  double origin_[3] = {0, 0, 0};
  bool has_origin_ = false;
  std::size_t count_ = 0;  // 0: no limit
};

}  // namespace domel::plugins::insertion
