// SPDX-License-Identifier: MIT
// Particle size distributions for insertion models: one parser, one sampler
// and one mean, so that every model (built-in or third-party) reads the same
// "distribution" block. A distribution is of diameters by number unless a
// table says "by": "mass".
//
//   {"type": "uniform",   "min": d0, "max": d1}
//   {"type": "normal",    "mean": m, "std": s, "min": d0, "max": d1}
//        truncated to [min, max]; default [max(m - 3 s, m / 100), m + 3 s]
//   {"type": "lognormal", "median": m, "sigma": s, "min": d0, "max": d1}
//        ln d normal with mean ln m and standard deviation s (the geometric
//        standard deviation is e^s), truncated to [min, max]; default
//        [m e^-3s, m e^3s]
//   {"type": "table", "diameters": [d...], "fractions": [f...], "by": "number" | "mass"}
//        discrete sizes; fractions sum to 1 (to 1e-6); by mass, the number
//        fraction of size i is (f_i / d_i^3) / sum_j (f_j / d_j^3) for one
//        density
//
// Truncated continuous distributions are sampled by rejection from the
// untruncated one (the truncation keeps at least 1 % of it, or the
// distribution is refused). Diameters in m.
#pragma once

#include <domel/sdk/plugin.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace domel::sdk {

class SizeDistribution {
 public:
  enum class Type { uniform, normal, lognormal, table };

  /// A single diameter.
  static SizeDistribution constant(double d) {
    SizeDistribution s;
    s.type_ = Type::uniform;
    s.lo_ = s.hi_ = d;
    return s;
  }

  /// Parse a "distribution" block; throws ParameterError naming the key
  /// (prefixed with `where`, e.g. "random: 'distribution'").
  static SizeDistribution parse(const nlohmann::json& j, const std::string& where) {
    auto fail = [&](const std::string& what) { throw ParameterError(where + ": " + what); };
    if (!j.is_object()) fail("expected an object");
    auto num = [&](const char* key) -> double {
      const auto it = j.find(key);
      if (it == j.end() || !it->is_number()) fail(std::string("expected a number '") + key + "'");
      const double v = it->get<double>();
      if (!std::isfinite(v)) fail(std::string("'") + key + "' is not finite");
      return v;
    };
    auto positive = [&](const char* key) {
      const double v = num(key);
      if (!(v > 0)) {
        std::ostringstream m;
        m << "expected '" << key << "' > 0, found " << v;
        fail(m.str());
      }
      return v;
    };
    const auto t = j.find("type");
    if (t == j.end() || !t->is_string()) fail("expected 'type': \"uniform\", \"normal\", \"lognormal\" or \"table\"");
    const std::string type = t->get<std::string>();
    SizeDistribution s;
    if (type == "uniform") {
      s.type_ = Type::uniform;
      s.lo_ = positive("min");
      s.hi_ = positive("max");
    } else if (type == "normal") {
      s.type_ = Type::normal;
      s.a_ = positive("mean");
      s.b_ = positive("std");
      s.lo_ = j.contains("min") ? positive("min") : std::max(s.a_ - 3 * s.b_, 0.01 * s.a_);
      s.hi_ = j.contains("max") ? positive("max") : s.a_ + 3 * s.b_;
    } else if (type == "lognormal") {
      s.type_ = Type::lognormal;
      s.a_ = positive("median");
      s.b_ = positive("sigma");
      s.lo_ = j.contains("min") ? positive("min") : s.a_ * std::exp(-3 * s.b_);
      s.hi_ = j.contains("max") ? positive("max") : s.a_ * std::exp(3 * s.b_);
    } else if (type == "table") {
      s.type_ = Type::table;
      const auto d = j.find("diameters"), f = j.find("fractions");
      if (d == j.end() || !d->is_array() || d->empty()) fail("expected 'diameters': a non-empty array");
      if (f == j.end() || !f->is_array() || f->size() != d->size())
        fail("expected 'fractions': an array as long as 'diameters'");
      const std::string by = j.value("by", std::string("number"));
      if (by != "number" && by != "mass") fail("expected 'by': \"number\" or \"mass\", found \"" + by + "\"");
      double sum = 0;
      for (std::size_t k = 0; k < d->size(); ++k) {
        if (!(*d)[k].is_number() || !((*d)[k].get<double>() > 0)) {
          std::ostringstream m;
          m << "expected 'diameters/" << k << "' > 0, found " << (*d)[k].dump();
          fail(m.str());
        }
        if (!(*f)[k].is_number() || !((*f)[k].get<double>() >= 0)) {
          std::ostringstream m;
          m << "expected 'fractions/" << k << "' >= 0, found " << (*f)[k].dump();
          fail(m.str());
        }
        s.sizes_.push_back((*d)[k].get<double>());
        s.weights_.push_back((*f)[k].get<double>());
        sum += s.weights_.back();
      }
      if (std::fabs(sum - 1.0) > 1e-6) {
        std::ostringstream m;
        m.precision(10);
        m << "expected 'fractions' summing to 1, found " << sum;
        fail(m.str());
      }
      if (by == "mass")  // number fractions from mass fractions (one density)
        for (std::size_t k = 0; k < s.sizes_.size(); ++k) s.weights_[k] /= std::pow(s.sizes_[k], 3);
      double total = 0;
      for (double w : s.weights_) total += w;
      for (double& w : s.weights_) w /= total;
      s.lo_ = *std::min_element(s.sizes_.begin(), s.sizes_.end());
      s.hi_ = *std::max_element(s.sizes_.begin(), s.sizes_.end());
    } else {
      fail("unknown 'type' \"" + type + "\" (expected \"uniform\", \"normal\", \"lognormal\" or \"table\")");
    }
    if (s.hi_ < s.lo_) {
      std::ostringstream m;
      m << "expected 'max' >= 'min', found " << s.hi_ << " < " << s.lo_;
      fail(m.str());
    }
    if ((s.type_ == Type::normal || s.type_ == Type::lognormal) && s.kept_share() < 0.01) {
      std::ostringstream m;
      m << "the truncation [" << s.lo_ << ", " << s.hi_ << "] m keeps " << s.kept_share()
        << " of the distribution, less than 1 %";
      fail(m.str());
    }
    return s;
  }

  Type type() const { return type_; }
  double min() const { return lo_; }
  double max() const { return hi_; }

  /// One diameter (by number).
  template <class Rng>
  double sample(Rng& rng) const {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    switch (type_) {
      case Type::uniform: return hi_ > lo_ ? lo_ + (hi_ - lo_) * unit(rng) : lo_;
      case Type::normal:
      case Type::lognormal: {
        std::normal_distribution<double> g(0.0, 1.0);
        for (;;) {  // rejection from the untruncated distribution (kept share >= 1 %)
          const double z = g(rng);
          const double d = type_ == Type::normal ? a_ + b_ * z : a_ * std::exp(b_ * z);
          if (d >= lo_ && d <= hi_) return d;
        }
      }
      case Type::table: {
        double u = unit(rng);
        for (std::size_t k = 0; k + 1 < sizes_.size(); ++k) {
          if (u < weights_[k]) return sizes_[k];
          u -= weights_[k];
        }
        return sizes_.back();
      }
    }
    return lo_;
  }

  /// E[d^3] by number, for the count that fills a volume fraction: exact for
  /// uniform and tables, by quadrature (2000 points over [min, max]) for the
  /// truncated normal and log-normal.
  double mean_cube() const {
    switch (type_) {
      case Type::uniform:
        return hi_ > lo_ ? (std::pow(hi_, 4) - std::pow(lo_, 4)) / (4.0 * (hi_ - lo_)) : lo_ * lo_ * lo_;
      case Type::table: {
        double m = 0;
        for (std::size_t k = 0; k < sizes_.size(); ++k) m += weights_[k] * std::pow(sizes_[k], 3);
        return m;
      }
      default: {
        constexpr int n = 2000;
        double num = 0, den = 0;
        for (int k = 0; k < n; ++k) {
          const double d = lo_ + (hi_ - lo_) * (k + 0.5) / n;
          const double w = density(d);
          num += w * d * d * d;
          den += w;
        }
        return den > 0 ? num / den : lo_ * lo_ * lo_;
      }
    }
  }

  /// The untruncated probability density (unnormalised) of a diameter.
  double density(double d) const {
    if (type_ == Type::normal) return std::exp(-0.5 * std::pow((d - a_) / b_, 2));
    if (type_ == Type::lognormal) return d > 0 ? std::exp(-0.5 * std::pow(std::log(d / a_) / b_, 2)) / d : 0.0;
    return 1.0;
  }

  /// The share of the untruncated distribution inside [min, max].
  double kept_share() const {
    auto phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
    if (type_ == Type::normal) return phi((hi_ - a_) / b_) - phi((lo_ - a_) / b_);
    if (type_ == Type::lognormal) return phi(std::log(hi_ / a_) / b_) - phi(std::log(lo_ / a_) / b_);
    return 1.0;
  }

 private:
  Type type_ = Type::uniform;
  double lo_ = 0, hi_ = 0;
  double a_ = 0, b_ = 0;  ///< normal: mean, std; lognormal: median, sigma of ln d
  std::vector<double> sizes_, weights_;  ///< table: diameters and number fractions
};

}  // namespace domel::sdk
