// SPDX-License-Identifier: MIT
// Issue 41: every schedule a scenario gives in seconds is refused at validate
// when it is below the macro step, at its own pointer, with the step and the
// value (a 1e-22 s particle-file interval used to pass validate and then
// loop for ever before the first step); one case per schedule kind, on the
// scenarios that have it (the coupled CI silo: pours, deletion regions,
// grids, a coupling's grid files; the fluid chamber: the fluid exchange and
// its field files). An interval that makes more than 1e5 actions in a run
// is accepted with a warning that gives the count. Each case builds a
// scenario without stepping it: the whole file runs in a few seconds.
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

const fs::path kSilo = fs::path(DOMEL_SOURCE_DIR) / "scenarios/silo/silo_ci_2lvl_nostress.json";
const fs::path kChamber = fs::path(DOMEL_SOURCE_DIR) / "scenarios/fluid/chamber_a4_none.json";

json read(const fs::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

/// The problems validate reports for `doc` (read from `file`), as one text.
using domel::test::problems;

struct Kind {
  const char* name;
  const fs::path* file;
  const char* pointer;
};
void PrintTo(const Kind& k, std::ostream* os) { *os << k.pointer; }

class ScheduleBelowTheStep : public ::testing::TestWithParam<Kind> {};

TEST_P(ScheduleBelowTheStep, IsRefusedAtItsPointer) {
  const Kind& k = GetParam();
  json doc = read(*k.file);
  ASSERT_EQ(problems(doc, *k.file), "") << "the scenario itself must pass";
  doc[json::json_pointer(k.pointer)] = 1e-22;
  const std::string found = problems(doc, *k.file);
  EXPECT_NE(found.find(std::string(k.pointer) + ": expected at least the macro step"), std::string::npos) << found;
  EXPECT_NE(found.find("found 1e-22 s"), std::string::npos) << found;
}

INSTANTIATE_TEST_SUITE_P(
    EveryKind, ScheduleBelowTheStep,
    ::testing::Values(Kind{"particle_files", &kSilo, "/output/vtk_interval"},
                      Kind{"probe_rows", &kSilo, "/output/probe_interval"},
                      Kind{"contact_files", &kSilo, "/output/contacts/interval"},
                      Kind{"checkpoints", &kSilo, "/run/checkpoint_interval"},
                      Kind{"deletion_checks", &kSilo, "/run/deletion_interval"},
                      Kind{"grid_files", &kSilo, "/output/grids/0/write_interval"},
                      Kind{"pour_events", &kSilo, "/subdomains/0/pour/0/interval"},
                      Kind{"coupling_grid_files", &kSilo, "/couplings/0/grid_interval"},
                      Kind{"fluid_exchanges", &kChamber, "/fluid/interval"},
                      Kind{"fluid_field_files", &kChamber, "/fluid/write_interval"}),
    [](const ::testing::TestParamInfo<Kind>& info) { return std::string(info.param.name); });

TEST(Schedules, MoreThanAHundredThousandActionsAreAcceptedWithTheirCount) {
  json doc = read(kSilo);
  const double macro = dp::load_scenario(doc, kSilo, domel::test::builtin_registry())->macro_step();
  const double duration = 10.0;  // 2.8e5 macro steps of the silo's 3.6e-5 s
  doc["run"]["duration"] = duration;
  doc["output"]["probe_interval"] = macro;  // one row per macro step
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  auto logger = std::make_shared<spdlog::logger>("schedules_test", sink);
  auto before = spdlog::default_logger();
  spdlog::set_default_logger(logger);
  const std::string found = problems(doc, kSilo);
  spdlog::set_default_logger(before);
  EXPECT_EQ(found, "");
  const std::string text = log.str();
  char count[32];
  std::snprintf(count, sizeof count, "%.3g", duration / macro);
  EXPECT_NE(text.find("/output/probe_interval"), std::string::npos) << text;
  EXPECT_NE(text.find(std::string(count) + " rows of probes.csv"), std::string::npos) << text;
}

}  // namespace
