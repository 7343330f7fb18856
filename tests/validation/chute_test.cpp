// SPDX-License-Identifier: MIT
// Guards periodic boundaries in a flow (issue 18 item 6): the steady chute
// flow of scenarios/validation/chute.json (24 degrees, about 13 d deep,
// periodic along and across the flow) run with two periodic lengths, 10 d
// and 20 d, gives the same velocity profile: in every bulk layer (from 2.5 d
// above the base to 1.5 d below the free surface) the two mean velocities
// over the last second agree within 5 % of the surface velocity (the
// issue's tolerance). And the profile has the shape of
// Bagnold's: v_s - v(z) ~ (H - z)^beta with beta = 3/2 (Silbert et al.
// 2001, Phys. Rev. E 64, 051302, fig. 4 and eq. 9, for flows between
// theta_stop and theta_max): the least-squares beta of each run lies in
// [1.3, 1.7] (a linear profile would give 1; measured values in
// docs/validation/chute.md). The
// free surface H is where the layer's volume fraction falls through half
// the bulk value. Label "slow": about 2 min on two threads.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>
#include <vector>

namespace dt = domel::test;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
constexpr double kD = 2.8e-3;

struct Profile {
  std::vector<double> z, v, phi;  ///< per layer: centre, mean vx and volume fraction over the window
};

/// Run the chute with periodic length `lx_d` diameters; the layer means of
/// the grid files in the last second.
Profile run_chute(double lx_d) {
  std::ifstream in(DOMEL_SOURCE_DIR "/scenarios/validation/chute.json");
  json doc = json::parse(in);
  const double L = lx_d * kD;
  auto& sd = doc["subdomains"][0];
  sd["periodic"]["x"] = {0.0, L};
  for (auto& ins : sd["insert"]) ins["region"]["box"]["max"][0] = L;
  doc["output"]["grids"][0]["max"][0] = L;
  doc["output"]["vtk_interval"] = 0;
  const fs::path out = dt::run_into_temp(doc, DOMEL_SOURCE_DIR "/scenarios/validation/chute.json",
                                         "chute_" + std::to_string(static_cast<int>(lx_d)), 2);
  const double t_from = doc["run"]["duration"].get<double>() - 1.0 + 1e-9;
  const dt::Csv csv = dt::read_csv(out / "profile_profile.csv");
  std::map<int, std::vector<double>> sum;  // layer -> z, v, phi, samples
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    if (csv.at(r, "time") < t_from) continue;
    auto& s = sum[static_cast<int>(csv.at(r, "layer"))];
    if (s.empty()) s.assign(4, 0.0);
    s[0] = csv.at(r, "centre");
    s[1] += csv.at(r, "vx");
    s[2] += csv.at(r, "volume_fraction");
    s[3] += 1;
  }
  Profile p;
  for (const auto& [layer, s] : sum) {
    p.z.push_back(s[0]);
    p.v.push_back(s[1] / s[3]);
    p.phi.push_back(s[2] / s[3]);
  }
  fs::remove_all(out);
  return p;
}

/// Free surface: where the volume fraction falls through half its bulk value.
double surface(const Profile& p) {
  double bulk = 0;
  for (std::size_t k = 2; k < 8; ++k) bulk += p.phi[k] / 6;
  for (std::size_t k = 3; k < p.z.size(); ++k)
    if (p.phi[k] < 0.5 * bulk)
      return p.z[k - 1] + (p.z[k] - p.z[k - 1]) * (p.phi[k - 1] - 0.5 * bulk) / (p.phi[k - 1] - p.phi[k]);
  return p.z.back();
}

/// The exponent beta of the least-squares fit v = c0 + c1 (H - z)^beta over
/// the bulk layers (a scan of beta in steps of 0.01, linear fit for c0, c1).
double bagnold_exponent(const Profile& p, double H) {
  double best = 0, best_rms = 1e300;
  for (double beta = 0.8; beta < 2.5; beta += 0.01) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    std::vector<std::pair<double, double>> pts;
    for (std::size_t k = 0; k < p.z.size(); ++k)
      if (p.z[k] > 2.5 * kD && p.z[k] < H - 1.5 * kD) {
        const double x = std::pow(H - p.z[k], beta), y = p.v[k];
        pts.emplace_back(x, y);
        n += 1; sx += x; sy += y; sxx += x * x; sxy += x * y;
      }
    const double c1 = (n * sxy - sx * sy) / (n * sxx - sx * sx), c0 = (sy - c1 * sx) / n;
    double rms = 0;
    for (const auto& [x, y] : pts) rms += (c0 + c1 * x - y) * (c0 + c1 * x - y);
    if (rms < best_rms) {
      best_rms = rms;
      best = beta;
    }
  }
  return best;
}
}  // namespace

TEST(Chute, TwoPeriodicLengthsGiveOneBagnoldProfile) {
  const Profile a = run_chute(10), b = run_chute(20);
  ASSERT_EQ(a.z.size(), b.z.size());
  const double Ha = surface(a), Hb = surface(b);
  EXPECT_NEAR(Ha, Hb, 0.5 * kD) << "the same depth (particles per base area)";
  double v_surface = 0;
  for (double v : a.v) v_surface = std::max(v_surface, v);
  ASSERT_GT(v_surface, 0.1) << "the layer flows";
  std::size_t compared = 0;
  double worst = 0;
  for (std::size_t k = 0; k < a.z.size(); ++k) {
    if (a.z[k] <= 2.5 * kD || a.z[k] >= std::min(Ha, Hb) - 1.5 * kD) continue;
    EXPECT_NEAR(a.v[k], b.v[k], 0.05 * v_surface) << "layer at z = " << a.z[k] / kD << " d";
    worst = std::max(worst, std::fabs(a.v[k] - b.v[k]) / v_surface);
    ++compared;
  }
  EXPECT_GE(compared, 7u);
  const double beta_a = bagnold_exponent(a, Ha), beta_b = bagnold_exponent(b, Hb);
  EXPECT_NEAR(beta_a, 1.5, 0.2);
  EXPECT_NEAR(beta_b, 1.5, 0.2);
  std::printf("chute: H = %.2f d and %.2f d, surface velocity %.3f m/s, largest layer difference %.1f %% of it over "
              "%zu layers, Bagnold exponents %.2f and %.2f\n",
              Ha / kD, Hb / kD, v_surface, 100 * worst, compared, beta_a, beta_b);
}
