// SPDX-License-Identifier: MIT
// Issue 41, plausibility at validate: each material and interaction value
// the schema gives a plausible range ("x-plausible": density, Young's
// modulus, Poisson's ratio, restitution, friction) is refused outside it at
// its own pointer with the range, unless /run/allow_implausible, which turns
// each into a warning; a density of 1.7e308 is blamed on the density, not on
// the damping model that fails on it later. The ranges themselves are the
// schema's (one source); the cases here take values just outside and just
// inside them. Builds the settle example without stepping: about a second.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scenario/scenario.hpp"
#include "support/fixture.hpp"

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace dp = domel::platform;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const fs::path kSettle = fs::path(DOMEL_SOURCE_DIR) / "scenarios/examples/settle.json";

json settle() {
  std::ifstream in(kSettle);
  json doc = json::parse(in);
  doc["subdomains"][0]["time_step"] = "auto";  // a changed stiffness or density changes the stable step
  return doc;
}

/// The problems validate reports, one "pointer: message" line each.
std::string problems(const json& doc) { return domel::test::problems(doc, kSettle); }

struct Value {
  const char* pointer;  ///< into settle.json
  double outside;       ///< just outside the schema's plausible range
  double inside;        ///< just inside it
  const char* range;    ///< as the message gives it
};
void PrintTo(const Value& v, std::ostream* os) { *os << v.pointer; }

class Implausible : public ::testing::TestWithParam<Value> {};

TEST_P(Implausible, IsRefusedAtItsPointerWithTheRange) {
  const Value& v = GetParam();
  json doc = settle();
  doc[json::json_pointer(v.pointer)] = v.outside;
  const std::string found = problems(doc);
  EXPECT_EQ(found.rfind(std::string(v.pointer) + ": expected a plausible value within " + v.range, 0), 0u) << found;
  EXPECT_EQ(std::count(found.begin(), found.end(), '\n'), 1) << found;  // that alone
  doc[json::json_pointer(v.pointer)] = v.inside;
  EXPECT_EQ(problems(doc), "");
}

INSTANTIATE_TEST_SUITE_P(
    Materials, Implausible,
    ::testing::Values(Value{"/materials/beads/density", 2.5e-6, 12, "[10, 25000] kg/m^3"},  // kg/mm^3 for kg/m^3
                      Value{"/materials/beads/density", 3e4, 2.4e4, "[10, 25000] kg/m^3"},
                      Value{"/materials/beads/youngs_modulus", 5e3, 2e4, "[10000, 1.2e+12] Pa"},
                      Value{"/materials/beads/youngs_modulus", 5e12, 1e12, "[10000, 1.2e+12] Pa"},
                      Value{"/materials/beads/poisson_ratio", -0.2, 0.0, "[0, 0.5] ("},
                      Value{"/interactions/0/restitution", 0.005, 0.02, "[0.01, 1] ("},
                      Value{"/interactions/0/friction", 50, 1.5, "[0, 2] ("}));

TEST(Implausible, AllowedTheyAreWarnedEach) {
  json doc = settle();
  doc["materials"]["beads"]["density"] = 2.5e5;  // density scaling by 100
  doc["interactions"][0]["friction"] = 10.0;
  doc["run"]["allow_implausible"] = true;
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto logger = std::make_shared<spdlog::logger>("plausibility_test", sink);
  auto before = spdlog::default_logger();
  spdlog::set_default_logger(logger);
  const std::string found = problems(doc);
  spdlog::set_default_logger(before);
  EXPECT_EQ(found, "");
  const std::string text = log.str();
  EXPECT_NE(text.find("/materials/beads/density: expected a plausible value"), std::string::npos) << text;
  EXPECT_NE(text.find("/interactions/0/friction: expected a plausible value"), std::string::npos) << text;
  EXPECT_NE(text.find("accepted (/run/allow_implausible)"), std::string::npos) << text;
}

TEST(Implausible, AnOverflowingDensityIsBlamedOnTheDensity) {
  json doc = settle();
  doc["materials"]["beads"]["density"] = 1.7e308;
  const std::string found = problems(doc);
  EXPECT_EQ(found.rfind("/materials/beads/density: expected a plausible value", 0), 0u) << found;
  EXPECT_EQ(found.find("/contact"), std::string::npos) << found;
}

}  // namespace
