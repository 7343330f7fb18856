// SPDX-License-Identifier: MIT
// Guards the component life cycle of the run loop (loop/component.hpp) and
// the way a new output is added (outputs/output_kinds.hpp): one class, one
// schema block and one registration line, nothing else. The throw-away
// output below ("test_tally") writes one line per due macro step with the
// time and the particles present into tally.txt, keeps how far the file got
// in its checkpoint section, and cuts the file back to it on a restart. A
// scenario with the block validates (defaults filled, an unknown key
// refused with its pointer), runs with the file written at the right
// times, and a run stopped at a checkpoint and restarted ends with
// tally.txt byte-identical to an uninterrupted run's. Cost: three runs of the
// settle example's first 1000 steps, well under a second.
#include <gtest/gtest.h>

#include "core/archive.hpp"
#include "core/error.hpp"
#include "outputs/output_kinds.hpp"
#include "scheduler/checkpoint.hpp"
#include "subdomain/subdomain.hpp"
#include "support/fixture.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
namespace dp = domel::platform;
using nlohmann::json;

/// The throw-away output: "<t> <particles>" lines every `interval` seconds.
class TallyOutput final : public dp::Component {
 public:
  explicit TallyOutput(double interval) : interval_(interval) {}
  unsigned points() const override { return kOutput; }
  std::string section() const override { return "test_tally/"; }
  void setup(dp::RunContext& ctx) override {
    lines_ = dp::Cadence::in_time(interval_, 0.0, ctx.macro);
    path_ = ctx.out / "tally.txt";
    if (!ctx.restart) std::ofstream(path_, std::ios::trunc);
  }
  void output(dp::RunContext& ctx, const dp::MacroStep& step) override {
    if (!lines_.take(step.index)) return;
    std::size_t n = 0;
    for (std::size_t k = 0; k < ctx.subdomains.size(); ++k) n += ctx.particles(k, step.t).size();
    std::ofstream(path_, std::ios::app) << step.t << " " << n << "\n";
  }
  void finish(dp::RunContext&, json& summary) override { summary["outputs"]["test_tally"] = "tally.txt"; }
  void save(dp::ArchiveWriter& w, const std::string& p) override {
    dp::save_fields(w, p, [&](dp::CheckpointFields& f) { fields(f); });
  }
  void load(dp::RunContext&, const dp::ArchiveReader& r, const std::string& p) override {
    dp::load_fields(r, p, [&](dp::CheckpointFields& f) { fields(f); });
  }

 private:
  /// Both directions of the checkpoint: the cadence's index and how far the file got.
  void fields(dp::CheckpointFields& f) {
    std::uint64_t index = lines_.index(), bytes = f.loading() ? 0 : fs::file_size(path_);
    f("index", index);
    f("bytes", bytes);
    if (!f.loading()) return;
    lines_.resume(index);
    fs::resize_file(path_, bytes);
  }

  double interval_;
  dp::Cadence lines_;
  fs::path path_;
};

// The registration line.
const dp::OutputKindRegistration kTally{
    {"test_tally",
     json::parse(R"({"type": "object", "additionalProperties": false,
                     "description": "a test's tally of the particles present",
                     "properties": {"interval": {"type": "number", "exclusiveMinimum": 0, "default": 0.002,
                                                 "description": "[s] between lines"}}})"),
     [](const dp::OutputSetting& s) { return std::make_unique<TallyOutput>(s.block["interval"].get<double>()); }}};

json settle_with_tally() {
  std::ifstream in(std::string(DOMEL_SOURCE_DIR) + "/scenarios/examples/settle.json");
  json doc = json::parse(in);
  doc["run"] = {{"duration", 0.01}};
  doc["output"] = {{"vtk_interval", 0}, {"probe_interval", 0.001}, {"test_tally", json::object()}};
  return doc;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("domel_output_kind_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(d);
  return d;
}

dp::RunResult run(const json& doc, const fs::path& out, std::uint64_t max_steps = 0, const fs::path& restart = {}) {
  auto sim = domel::test::build(doc);
  dp::RunOptions opt;
  opt.output_directory = out;
  opt.progress = false;
  opt.max_steps = max_steps;
  opt.restart = restart;
  return sim->run(opt, domel::test::builtin_registry());
}

TEST(OutputKind, ARegisteredOutputIsValidatedWrittenCheckpointedAndResumed) {
  // validated by its own schema: the default filled, an unknown key refused with its pointer
  const json doc = settle_with_tally();
  auto sim = domel::test::build(doc);
  EXPECT_EQ(sim->document["output"]["test_tally"]["interval"].get<double>(), 0.002);
  json bad = doc;
  bad["output"]["test_tally"]["intervall"] = 1;
  try {
    domel::test::build(bad);
    ADD_FAILURE() << "an unknown key of the registered block was accepted";
  } catch (const dp::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/output/test_tally"), std::string::npos) << e.what();
  }

  // written: a line at t = 0, 0.002, ..., 0.01 (6), each with the particles present
  const fs::path plain = scratch("plain");
  const dp::RunResult a = run(doc, plain);
  EXPECT_EQ(a.summary["outputs"]["test_tally"], "tally.txt");
  const std::string lines = slurp(plain / "tally.txt");
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 6) << lines;
  EXPECT_EQ(lines.substr(0, lines.find('\n')), "0 " + std::to_string(sim->subdomains[0]->size()));

  // checkpointed and resumed: stopped at macro step 555 (a checkpoint there),
  // restarted, the same bytes as the uninterrupted run
  json with = doc;
  with["run"]["checkpoint_interval"] = 0.004;
  const fs::path resumed = scratch("resumed");
  const dp::RunResult first = run(with, resumed, 555);
  ASSERT_EQ(first.macro_steps, 555u);
  const dp::ArchiveReader ck(resumed / dp::kCheckpointFile);
  EXPECT_TRUE(ck.has("test_tally/bytes"));
  EXPECT_NE(slurp(resumed / "tally.txt"), lines);
  run(with, resumed, 0, resumed / dp::kCheckpointFile);
  EXPECT_EQ(slurp(resumed / "tally.txt"), lines);
  fs::remove_all(plain);
  fs::remove_all(resumed);
}

}  // namespace
