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
//   {"type": "mixture", "by": "number" | "volume" | "mass",
//    "components": [{"fraction": f, "diameter": d | "distribution": {...}, "material": name}, ...]}
//        several components, each a diameter or one of the distributions
//        above (not a mixture); fractions sum to 1 (to 1e-6) and measure
//        what "by" says: the number share of component i is f_i for
//        "number", (f_i / E_i[d^3]) / sum_j (f_j / E_j[d^3]) for "volume"
//        and for "mass" (one density: the host turns mass fractions of
//        materials of different densities into volume fractions before the
//        model sees them). "material" is the host's (which material each
//        component's particles are); a model ignores it. draw() returns the
//        component with the diameter, for Inserted::push.
//
// Truncated continuous distributions are sampled by rejection from the
// untruncated one (the truncation keeps at least 1 % of it, or the
// distribution is refused). Diameters in m.
#pragma once

#include <domel/sdk/plugin.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace domel::sdk {

class SizeDistribution {
 public:
  enum class Type { uniform, normal, lognormal, table, mixture };

  /// One draw: a diameter and the mixture component it belongs to (0
  /// without a mixture).
  struct Draw {
    double diameter;
    std::uint32_t component;
  };

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
    if (t == j.end() || !t->is_string())
      fail("expected 'type': \"uniform\", \"normal\", \"lognormal\", \"table\" or \"mixture\"");
    const std::string type = t->get<std::string>();
    SizeDistribution s;
    if (type == "mixture") return parse_mixture(j, where);
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
      fail("unknown 'type' \"" + type + "\" (expected \"uniform\", \"normal\", \"lognormal\", \"table\" or \"mixture\")");
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
  /// Components of a mixture (1 otherwise).
  std::size_t components() const { return type_ == Type::mixture ? parts_.size() : 1; }
  /// Component k of a mixture (the distribution itself otherwise).
  const SizeDistribution& component(std::size_t k) const { return type_ == Type::mixture ? parts_.at(k) : *this; }
  /// The number share of component k.
  double number_share(std::size_t k) const { return type_ == Type::mixture ? weights_.at(k) : 1.0; }

  /// One diameter and its component (by number). Without a mixture it draws
  /// exactly what sample() does.
  template <class Rng>
  Draw draw(Rng& rng) const {
    if (type_ != Type::mixture) return {sample(rng), 0u};
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double u = unit(rng);
    std::size_t k = 0;
    for (; k + 1 < parts_.size(); ++k) {
      if (u < weights_[k]) break;
      u -= weights_[k];
    }
    return {parts_[k].sample(rng), static_cast<std::uint32_t>(k)};
  }

  /// One diameter (by number).
  template <class Rng>
  double sample(Rng& rng) const {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    switch (type_) {
      case Type::mixture: return draw(rng).diameter;
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
      case Type::mixture: {
        double m = 0;
        for (std::size_t k = 0; k < parts_.size(); ++k) m += weights_[k] * parts_[k].mean_cube();
        return m;
      }
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
  static SizeDistribution parse_mixture(const nlohmann::json& j, const std::string& where) {
    auto fail = [&](const std::string& what) { throw ParameterError(where + ": " + what); };
    for (const auto& [key, v] : j.items()) {
      (void)v;
      if (key != "type" && key != "by" && key != "components")
        fail("unknown key '" + key + "' in a mixture (expected 'by' and 'components')");
    }
    const auto by_it = j.find("by");
    if (by_it == j.end() || !by_it->is_string())
      fail("expected 'by': \"mass\", \"volume\" or \"number\" (what the components' fractions measure)");
    const std::string by = by_it->get<std::string>();
    if (by != "number" && by != "volume" && by != "mass")
      fail("expected 'by': \"mass\", \"volume\" or \"number\", found \"" + by + "\"");
    const auto c = j.find("components");
    if (c == j.end() || !c->is_array() || c->empty()) fail("expected 'components': a non-empty array");
    SizeDistribution s;
    s.type_ = Type::mixture;
    double sum = 0;
    for (std::size_t k = 0; k < c->size(); ++k) {
      const nlohmann::json& e = (*c)[k];
      const std::string at = where + ": 'components/" + std::to_string(k) + "'";
      if (!e.is_object()) throw ParameterError(at + ": expected an object");
      for (const auto& [key, v] : e.items()) {
        (void)v;
        if (key != "fraction" && key != "diameter" && key != "distribution" && key != "material")
          throw ParameterError(at + ": unknown key '" + key +
                               "' (expected 'fraction', 'diameter' or 'distribution', and 'material')");
      }
      const auto f = e.find("fraction");
      if (f == e.end() || !f->is_number() || !(f->get<double>() >= 0) || !std::isfinite(f->get<double>())) {
        std::ostringstream m;
        m << at << ": expected 'fraction' >= 0, found " << (f == e.end() ? std::string("nothing") : f->dump());
        throw ParameterError(m.str());
      }
      const bool has_d = e.contains("diameter"), has_dist = e.contains("distribution");
      if (has_d == has_dist) throw ParameterError(at + ": expected exactly one of 'diameter' or 'distribution'");
      SizeDistribution part;
      if (has_d) {
        const auto& d = e["diameter"];
        if (!d.is_number() || !(d.get<double>() > 0) || !std::isfinite(d.get<double>())) {
          std::ostringstream m;
          m << at << ": expected 'diameter' > 0, found " << d.dump();
          throw ParameterError(m.str());
        }
        part = constant(d.get<double>());
      } else {
        const auto& d = e["distribution"];
        if (d.is_object() && d.value("type", std::string()) == "mixture")
          throw ParameterError(at + ": a component cannot itself be a mixture");
        part = parse(d, at + ": 'distribution'");
      }
      sum += f->get<double>();
      s.weights_.push_back(f->get<double>());
      s.parts_.push_back(std::move(part));
    }
    if (std::fabs(sum - 1.0) > 1e-6) {
      std::ostringstream m;
      m.precision(10);
      m << "expected the components' 'fraction's summing to 1, found " << sum;
      fail(m.str());
    }
    if (by != "number")  // number shares from volume (or one-density mass) fractions
      for (std::size_t k = 0; k < s.parts_.size(); ++k) s.weights_[k] /= s.parts_[k].mean_cube();
    double total = 0;
    for (double w : s.weights_) total += w;
    for (double& w : s.weights_) w /= total;
    s.lo_ = s.parts_[0].min();
    s.hi_ = s.parts_[0].max();
    for (const auto& p : s.parts_) {
      s.lo_ = std::min(s.lo_, p.min());
      s.hi_ = std::max(s.hi_, p.max());
    }
    return s;
  }

  Type type_ = Type::uniform;
  double lo_ = 0, hi_ = 0;
  double a_ = 0, b_ = 0;  ///< normal: mean, std; lognormal: median, sigma of ln d
  std::vector<double> sizes_, weights_;  ///< table: diameters and number fractions; mixture: number shares
  std::vector<SizeDistribution> parts_;  ///< mixture: the components
};

}  // namespace domel::sdk
