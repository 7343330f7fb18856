// SPDX-License-Identifier: MIT
// Guards the SDK's size distributions (domel/sdk/size_distribution.hpp): at
// 10^4 draws each continuous distribution passes a Kolmogorov-Smirnov test
// against its truncated CDF (critical value 1.63/sqrt(n): the asymptotic 1 % point
// of the Kolmogorov distribution, 1.628; Massey, JASA 46 (1951) 68; significance
// 1 %, so a correct sampler fails one seed in a hundred: the seeds are fixed),
// a table's number or mass fractions are met within 2 % (issue 18 item 2),
// E[d^3] is right, and bad blocks are refused naming the key.
#include <domel/sdk/size_distribution.hpp>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

using domel::sdk::ParameterError;
using domel::sdk::SizeDistribution;
using nlohmann::json;

namespace {

constexpr int kDraws = 10000;

double phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

/// The largest gap between the empirical CDF of the draws and `cdf`.
double ks_statistic(std::vector<double> d, const std::function<double(double)>& cdf) {
  std::sort(d.begin(), d.end());
  double worst = 0;
  const double n = static_cast<double>(d.size());
  for (std::size_t k = 0; k < d.size(); ++k) {
    const double f = cdf(d[k]);
    worst = std::max({worst, std::fabs(f - k / n), std::fabs((k + 1) / n - f)});
  }
  return worst;
}

std::vector<double> draws(const SizeDistribution& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<double> d(kDraws);
  for (double& x : d) x = s.sample(rng);
  return d;
}

const double kCritical = 1.63 / std::sqrt(static_cast<double>(kDraws));

/// The message a block is refused with, as random would report it ("accepted" if it is not).
std::string why(const json& j) {
  try {
    SizeDistribution::parse(j, "random: 'distribution'");
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(SizeDistribution, ContinuousOnesPassAKolmogorovSmirnovTestAgainstTheirTruncatedCdf) {
  const auto uniform = SizeDistribution::parse({{"type", "uniform"}, {"min", 1e-3}, {"max", 3e-3}}, "t");
  EXPECT_LT(ks_statistic(draws(uniform, 1), [](double d) { return (d - 1e-3) / 2e-3; }), kCritical);

  // normal, mean 2 mm, std 0.4 mm, truncated to [1.5, 3] mm (not symmetric: the truncation shows)
  const auto normal = SizeDistribution::parse(
      {{"type", "normal"}, {"mean", 2e-3}, {"std", 0.4e-3}, {"min", 1.5e-3}, {"max", 3e-3}}, "t");
  const double n0 = phi((1.5 - 2) / 0.4), n1 = phi((3 - 2) / 0.4);
  EXPECT_LT(ks_statistic(draws(normal, 2), [&](double d) { return (phi((d * 1e3 - 2) / 0.4) - n0) / (n1 - n0); }),
            kCritical);
  EXPECT_NEAR(normal.kept_share(), n1 - n0, 1e-12);

  // log-normal, median 1 mm, sigma 0.5, default truncation median e^(+-3 sigma)
  const auto lognormal = SizeDistribution::parse({{"type", "lognormal"}, {"median", 1e-3}, {"sigma", 0.5}}, "t");
  EXPECT_NEAR(lognormal.min(), 1e-3 * std::exp(-1.5), 1e-15);
  EXPECT_NEAR(lognormal.max(), 1e-3 * std::exp(1.5), 1e-15);
  const double l0 = phi(-3), l1 = phi(3);
  EXPECT_LT(ks_statistic(draws(lognormal, 3),
                         [&](double d) { return (phi(std::log(d / 1e-3) / 0.5) - l0) / (l1 - l0); }),
            kCritical);
  // a wrong sampler fails the same test: the untruncated normal against the truncated CDF
  std::mt19937_64 rng(4);
  std::normal_distribution<double> wrong(2e-3, 0.4e-3);
  std::vector<double> w(kDraws);
  for (double& x : w) x = wrong(rng);
  EXPECT_GT(ks_statistic(w, [&](double d) {
              return std::clamp((phi((d * 1e3 - 2) / 0.4) - n0) / (n1 - n0), 0.0, 1.0);
            }),
            kCritical);
}

TEST(SizeDistribution, ATableMeetsItsFractionsByNumberOrByMassWithinTwoPercent) {
  // 1, 2 and 4 mm: by number 0.5 / 0.3 / 0.2; by mass 0.2 / 0.3 / 0.5
  const json d = {1e-3, 2e-3, 4e-3};
  const auto by_number = SizeDistribution::parse({{"type", "table"}, {"diameters", d}, {"fractions", {0.5, 0.3, 0.2}}}, "t");
  const auto by_mass = SizeDistribution::parse(
      {{"type", "table"}, {"diameters", d}, {"fractions", {0.2, 0.3, 0.5}}, {"by", "mass"}}, "t");
  for (const auto& [s, want, mass] :
       {std::tuple{&by_number, std::vector<double>{0.5, 0.3, 0.2}, false},
        std::tuple{&by_mass, std::vector<double>{0.2, 0.3, 0.5}, true}}) {
    double sum[3] = {0, 0, 0}, total = 0;
    for (double x : draws(*s, 5)) {
      const int k = x < 1.5e-3 ? 0 : x < 3e-3 ? 1 : 2;
      const double w = mass ? x * x * x : 1.0;
      sum[k] += w;
      total += w;
    }
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(sum[k] / total, want[k], 0.02) << (mass ? "by mass " : "by number ") << k;
  }
  // E[d^3] by number of the mass table: (0.2 + 0.3 + 0.5) / sum(f_i / d_i^3)
  const double inv = 0.2 / 1e-9 + 0.3 / 8e-9 + 0.5 / 64e-9;
  EXPECT_NEAR(by_mass.mean_cube(), 1.0 / inv, 1e-12 / inv);
}

TEST(SizeDistribution, MeanCubeMatchesTheDraws) {
  // E[d^3] sets the count that fills a volume fraction: quadrature against 10^5 draws, within 1 %
  for (const json& j : {json{{"type", "normal"}, {"mean", 2e-3}, {"std", 0.5e-3}},
                        json{{"type", "lognormal"}, {"median", 1e-3}, {"sigma", 0.4}},
                        json{{"type", "uniform"}, {"min", 1e-3}, {"max", 2e-3}}}) {
    const auto s = SizeDistribution::parse(j, "t");
    std::mt19937_64 rng(6);
    double m = 0;
    for (int k = 0; k < 100000; ++k) m += std::pow(s.sample(rng), 3);
    m /= 100000;
    EXPECT_NEAR(s.mean_cube(), m, 0.01 * m) << j.dump();
  }
}

TEST(SizeDistribution, BadBlocksAreRefusedNamingTheKey) {
  EXPECT_EQ(why({{"type", "table"}, {"diameters", {1e-3, 2e-3}}, {"fractions", {0.5, 0.6}}}),
            "random: 'distribution': expected 'fractions' summing to 1, found 1.1");
  EXPECT_EQ(why({{"type", "table"}, {"diameters", {1e-3, -2e-3}}, {"fractions", {0.5, 0.5}}}),
            "random: 'distribution': expected 'diameters/1' > 0, found -0.002");
  EXPECT_EQ(why({{"type", "table"}, {"diameters", {0, 2e-3}}, {"fractions", {0.5, 0.5}}}),
            "random: 'distribution': expected 'diameters/0' > 0, found 0");
  EXPECT_NE(why({{"type", "gaussian"}, {"mean", 1e-3}}).find("unknown 'type' \"gaussian\""), std::string::npos);
  EXPECT_NE(why({{"type", "uniform"}, {"min", 2e-3}, {"max", 1e-3}}).find("expected 'max' >= 'min'"), std::string::npos);
  EXPECT_NE(why({{"type", "normal"}, {"mean", 1e-3}, {"std", 1e-4}, {"min", 2e-3}, {"max", 3e-3}}).find("less than 1 %"),
            std::string::npos);
  EXPECT_NE(why({{"type", "lognormal"}, {"median", 1e-3}}).find("'sigma'"), std::string::npos);
}

// Guards mixtures (issue 18 item 2): each draw picks a component by its
// number share, which the fractions give by volume (f_i / E_i[d^3],
// normalised) or by number; the component's diameters then follow its own
// law (Kolmogorov-Smirnov as above), the volume fractions are met within
// 2 % at 10^4 draws, E[d^3] is the share-weighted mean, and draw() of a
// plain distribution draws exactly what sample() does.
TEST(SizeDistribution, AMixtureDrawsEachComponentByItsShareAndFromItsOwnLaw) {
  const json ln = {{"type", "lognormal"}, {"median", 1e-3}, {"sigma", 0.2}};
  const auto mix = SizeDistribution::parse(
      {{"type", "mixture"},
       {"by", "volume"},
       {"components", {{{"material", "glass"}, {"distribution", ln}, {"fraction", 0.3}},
                       {{"material", "steel"}, {"diameter", 2e-3}, {"fraction", 0.7}}}}},
      "t");
  ASSERT_EQ(mix.components(), 2u);
  const double e0 = SizeDistribution::parse(ln, "t").mean_cube(), e1 = 8e-9;
  const double n0 = (0.3 / e0) / (0.3 / e0 + 0.7 / e1);
  EXPECT_NEAR(mix.number_share(0), n0, 1e-12);
  EXPECT_NEAR(mix.mean_cube(), n0 * e0 + (1 - n0) * e1, 1e-12 * e1);
  EXPECT_DOUBLE_EQ(mix.min(), 1e-3 * std::exp(-0.6));
  EXPECT_DOUBLE_EQ(mix.max(), 2e-3);

  std::mt19937_64 rng(8);
  std::vector<double> first;
  double volume[2] = {0, 0};
  for (int k = 0; k < kDraws; ++k) {
    const auto d = mix.draw(rng);
    ASSERT_LT(d.component, 2u);
    volume[d.component] += d.diameter * d.diameter * d.diameter;
    if (d.component == 0) first.push_back(d.diameter);
    else EXPECT_EQ(d.diameter, 2e-3);
  }
  EXPECT_NEAR(volume[0] / (volume[0] + volume[1]), 0.3, 0.02);
  const double l0 = phi(-3), l1 = phi(3);
  EXPECT_LT(ks_statistic(first, [&](double d) { return (phi(std::log(d / 1e-3) / 0.2) - l0) / (l1 - l0); }),
            1.63 / std::sqrt(static_cast<double>(first.size())));

  // by number: the fractions are the shares
  const auto by_number = SizeDistribution::parse(
      {{"type", "mixture"}, {"by", "number"}, {"components", {{{"diameter", 1e-3}, {"fraction", 0.25}},
                                                              {{"diameter", 3e-3}, {"fraction", 0.75}}}}},
      "t");
  EXPECT_DOUBLE_EQ(by_number.number_share(0), 0.25);

  // a plain distribution: draw() is sample() with component 0
  const auto plain = SizeDistribution::parse(ln, "t");
  std::mt19937_64 a(3), b(3);
  for (int k = 0; k < 100; ++k) {
    const auto d = plain.draw(a);
    EXPECT_EQ(d.diameter, plain.sample(b));
    EXPECT_EQ(d.component, 0u);
  }
}

TEST(SizeDistribution, BadMixturesAreRefusedNamingTheComponent) {
  const json a = {{"diameter", 1e-3}, {"fraction", 0.5}};
  EXPECT_EQ(why({{"type", "mixture"}, {"by", "mass"}, {"components", {a, {{"diameter", 2e-3}, {"fraction", 0.6}}}}}),
            "random: 'distribution': expected the components' 'fraction's summing to 1, found 1.1");
  EXPECT_EQ(why({{"type", "mixture"}, {"by", "mass"}, {"components", {a, {{"diameter", 0.0}, {"fraction", 0.5}}}}}),
            "random: 'distribution': 'components/1': expected 'diameter' > 0, found 0.0");
  EXPECT_EQ(why({{"type", "mixture"}, {"components", {a, a}}}),
            "random: 'distribution': expected 'by': \"mass\", \"volume\" or \"number\" (what the components' "
            "fractions measure)");
  EXPECT_EQ(why({{"type", "mixture"}, {"by", "mass"}, {"components", {a, {{"fraction", 0.5}}}}}),
            "random: 'distribution': 'components/1': expected exactly one of 'diameter' or 'distribution'");
  EXPECT_NE(why({{"type", "mixture"}, {"by", "mass"},
                 {"components", {a, {{"fraction", 0.5}, {"distribution", {{"type", "mixture"}}}}}}})
                .find("cannot itself be a mixture"),
            std::string::npos);
  EXPECT_NE(why({{"type", "mixture"}, {"by", "mass"},
                 {"components", {a, {{"fraction", 0.5}, {"distribution", {{"type", "table"}, {"diameters", {1e-3}},
                                                                          {"fractions", {0.9}}}}}}}})
                .find("'components/1': 'distribution': expected 'fractions' summing to 1, found 0.9"),
            std::string::npos);
  EXPECT_NE(why({{"type", "mixture"}, {"by", "mass"}, {"components", {a, {{"diameter", 1e-3}, {"fraction", 0.5},
                                                                          {"colour", "red"}}}}})
                .find("unknown key 'colour'"),
            std::string::npos);
}
