// SPDX-License-Identifier: MIT
// Guards the particle state files (platform/io/particle_state.cpp): a
// write/read round trip is bit-exact for every column, malformed files are
// refused with the file, line and column named, and a run with output.state
// followed by a run with initial_state starts from exactly the particles the
// first run ended with.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "io/particle_state.hpp"
#include "support/fixture.hpp"

namespace fs = std::filesystem;
using domel::platform::ParticleStore;
using domel::platform::io::format_particle_state;
using domel::platform::io::read_particle_state;
using domel::platform::io::write_particle_state;

namespace {

fs::path temp_file(const std::string& name, const std::string& contents) {
  const fs::path p = fs::path(::testing::TempDir()) / name;
  std::ofstream(p) << contents;
  return p;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::string error_of(const fs::path& p) {
  try {
    read_particle_state(p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

const char* kHeader = "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed\n";

}  // namespace

TEST(ParticleState, AMixtureWritesEachParticlesMaterialByName) {
  // several materials: format v2 with a 13th column, read back per particle; one material stays v1
  ParticleStore st;
  for (std::uint8_t k = 0; k < 6; ++k) st.add(k + 1, 0.01 * k, 0, 0, 1e-3, 2500.0, false, k % 3);
  const fs::path p = fs::path(::testing::TempDir()) / "state_mixture.csv";
  write_particle_state(p, st, "mix", 0.5, 1.0, {"glass", "steel", "sand"});
  const auto rows = read_particle_state(p);
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k)
    EXPECT_EQ(rows[k].material, (std::vector<std::string>{"glass", "steel", "sand"})[k % 3]) << k;
  EXPECT_EQ(rows[4].x, 0.04);
  EXPECT_NE(format_particle_state(st, "mix", 0.5, 1.0, {"glass"}).find(kHeader), std::string::npos);
  EXPECT_EQ(format_particle_state(st, "mix", 0.5, 1.0, {"glass"}).find("material"), std::string::npos);
  const fs::path bad = temp_file("state_no_material.csv",
                                 std::string("id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed,material\n") +
                                     "1,0,0,0,0.001,0,0,0,0,0,0,0,\n");
  EXPECT_NE(error_of(bad).find(":2: expected a material name in column 13"), std::string::npos) << error_of(bad);
}

TEST(ParticleState, RoundTripIsBitExact) {
  ParticleStore st;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::uint64_t k = 0; k < 200; ++k) {
    // values with full 53-bit mantissas over many decades, including tiny and negative ones
    const double scale = std::pow(10.0, -12.0 + 0.1 * static_cast<double>(k));
    st.add(1000 + 3 * k, u(rng) * scale, u(rng), u(rng) * 1e-3, 1e-3 * (1.0 + std::abs(u(rng))), 2500.0, k % 7 == 0);
    st.vx.back() = u(rng) * scale; st.vy.back() = u(rng); st.vz.back() = -0.0;
    st.wx.back() = u(rng) * 1e3; st.wy.back() = std::nextafter(1.0, 2.0); st.wz.back() = 5e-324;
  }
  const fs::path p = fs::path(::testing::TempDir()) / "state_roundtrip.csv";
  write_particle_state(p, st, "bed", 0.125, 2.0);
  const auto rows = read_particle_state(p);
  ASSERT_EQ(rows.size(), st.size());
  for (std::size_t k = 0; k < st.size(); ++k) {
    EXPECT_EQ(rows[k].id, st.id[k]);
    EXPECT_TRUE(same_bits(rows[k].x, st.x[k]) && same_bits(rows[k].y, st.y[k]) && same_bits(rows[k].z, st.z[k]))
        << "position of row " << k;
    EXPECT_TRUE(same_bits(rows[k].radius, st.radius[k])) << "radius of row " << k;
    EXPECT_TRUE(same_bits(rows[k].vx, st.vx[k]) && same_bits(rows[k].vy, st.vy[k]) && same_bits(rows[k].vz, st.vz[k]))
        << "velocity of row " << k;
    EXPECT_TRUE(same_bits(rows[k].wx, st.wx[k]) && same_bits(rows[k].wy, st.wy[k]) && same_bits(rows[k].wz, st.wz[k]))
        << "angular velocity of row " << k;
    EXPECT_EQ(rows[k].fixed, st.fixed(k));
  }
  // the header comment names the subdomain, count and time
  const std::string text = format_particle_state(st, "bed", 0.125, 2.0);
  EXPECT_NE(text.find("subdomain 'bed', 200 particles, t = 0.125 s, coarse_grain 2"), std::string::npos) << text.substr(0, 200);
}

TEST(ParticleState, MalformedFilesNameFileLineAndColumn) {
  const std::string ok = "1,0,0,0,0.001,0,0,0,0,0,0,0\n";
  struct Case {
    std::string name, contents, message;
  } cases[] = {
      {"no_header.csv", ok, ":1: expected the header 'id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed' (or "},
      {"empty.csv", "# only a comment\n", ":1: expected the header"},
      {"short_row.csv", std::string(kHeader) + ok + "2,0,0,0,0.001,0,0,0,0,0,0\n",
       ":3: expected 12 comma-separated columns, 11 given"},
      {"long_row.csv", std::string(kHeader) + "2,0,0,0,0.001,0,0,0,0,0,0,0,9\n", ":2: expected 12 comma-separated columns"},
      {"nan.csv", std::string(kHeader) + "# comment lines are skipped\n2,0,nan,0,0.001,0,0,0,0,0,0,0\n",
       ":3: expected a finite number in column 3 (y), found 'nan'"},
      {"radius.csv", std::string(kHeader) + "2,0,0,0,-0.001,0,0,0,0,0,0,0\n", ":2: expected a radius > 0 in column 5"},
      {"fixed.csv", std::string(kHeader) + "2,0,0,0,0.001,0,0,0,0,0,0,2\n", ":2: expected fixed = 0 or 1 in column 12"},
      {"id.csv", std::string(kHeader) + "2.5,0,0,0,0.001,0,0,0,0,0,0,0\n", ":2: expected an integer id >= 0"},
  };
  for (const auto& c : cases) {
    const fs::path p = temp_file(c.name, c.contents);
    const std::string e = error_of(p);
    EXPECT_NE(e.find(p.string() + c.message), std::string::npos) << c.name << ": " << e;
  }
  EXPECT_NE(error_of(fs::path(::testing::TempDir()) / "does_not_exist.csv").find("cannot open"), std::string::npos);
}

TEST(ParticleState, RunWritesStateAndNextRunStartsFromIt) {
  namespace dt = domel::test;
  using nlohmann::json;
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  dt::add_plane(doc, "floor", {0, 0, 0}, {0, 0, 1});
  json ins = {{"model", "random"}, {"diameter", 0.003}, {"count", 300}, {"seed", 5}};
  ins["region"]["box"] = {{"min", {0, 0, 0}}, {"max", {0.03, 0.03, 0.06}}};
  doc["subdomains"][0]["insert"] = json::array({ins});
  doc["run"] = {{"steps", 3000}};
  doc["output"]["state"] = true;
  auto first = dt::build(doc);
  domel::platform::RunOptions opt;
  opt.progress = false;
  opt.output_directory = ::testing::TempDir() + "/particle_state_first";
  const auto result = first->run(opt, dt::builtin_registry());
  const fs::path state = fs::path(opt.output_directory) / "sd_state.csv";
  ASSERT_TRUE(fs::exists(state));
  EXPECT_EQ(result.summary["outputs"]["state"]["sd"], "sd_state.csv");

  json next = doc;
  next["subdomains"][0].erase("insert");
  next["subdomains"][0]["initial_state"] = state.string();
  next["output"].erase("state");
  auto second = dt::build(next);
  const ParticleStore& a = first->subdomains[0]->store();
  const ParticleStore& b = second->subdomains[0]->store();
  ASSERT_EQ(a.size(), b.size());
  double vmax = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_TRUE(same_bits(a.x[k], b.x[k]) && same_bits(a.y[k], b.y[k]) && same_bits(a.z[k], b.z[k])) << k;
    EXPECT_TRUE(same_bits(a.vz[k], b.vz[k]) && same_bits(a.wx[k], b.wx[k])) << k;
    EXPECT_TRUE(same_bits(a.mass[k], b.mass[k])) << "mass from the same material and radius, particle " << k;
    vmax = std::max(vmax, std::abs(a.vz[k]));
  }
  EXPECT_GT(vmax, 0.0) << "the particles must still be moving, or the velocity check proves nothing";
}
