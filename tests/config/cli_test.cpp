// SPDX-License-Identifier: MIT
// Guards the domel command line end to end: exit codes (0 ok, 2 refused, 64
// usage), that a refused run writes nothing, the files a run leaves behind
// (summary.json contents, probes.csv, ParaView files, no temporaries), and
// the output of the plugins, schema, docs and version commands. Runs the
// built executable <build>/bin/domel with stdout and stderr captured to files.
#include "scenario/json_schema.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kDomel = DOMEL_BINARY_DIR "/bin/domel";
const fs::path kSettle = fs::path(DOMEL_SOURCE_DIR) / "scenarios" / "examples" / "settle.json";
const fs::path kCases = fs::path(DOMEL_SOURCE_DIR) / "tests" / "config" / "cases";

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Single-quotes an argument for /bin/sh.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    tmp_ = fs::temp_directory_path() /
           ("domel_cli_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "_" +
            std::to_string(stamp));
    fs::create_directories(tmp_);
    ASSERT_TRUE(fs::is_regular_file(kDomel)) << "the domel executable is missing: " << kDomel;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  /// Runs domel with the arguments; stdout/stderr are captured to files in tmp_.
  /// env: optional "NAME=value" set for this call only.
  Result domel(const std::vector<std::string>& args, const std::string& env = "") {
    const fs::path out = tmp_ / "stdout.txt", err = tmp_ / "stderr.txt";
    std::string cmd = (env.empty() ? std::string() : "env " + shell_quote(env) + " ") + shell_quote(kDomel);
    for (const auto& a : args) cmd += " " + shell_quote(a);
    cmd += " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string()) + " </dev/null";
    const int status = std::system(cmd.c_str());
    Result r;
    r.exit_code = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }

  static std::string show(const Result& r) {
    return "exit code " + std::to_string(r.exit_code) + "\n--- stdout ---\n" + r.out + "\n--- stderr ---\n" + r.err;
  }

  fs::path tmp_;
};

// ---- validate ----------------------------------------------------------------

TEST_F(Cli, ValidateGoodScenarioSaysValid) {
  const Result r = domel({"validate", kSettle.string()});
  EXPECT_EQ(r.exit_code, 0) << show(r);
  EXPECT_NE(r.out.find(kSettle.string() + ": valid"), std::string::npos) << show(r);
}

TEST_F(Cli, ValidateBadScenarioIsRefusedNamingFileAndPointer) {
  const fs::path bad = kCases / "normal_model_typo.json";
  const Result r = domel({"validate", bad.string()});
  EXPECT_EQ(r.exit_code, 2) << show(r);
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("/subdomains/0/contact/normal/model"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("did you mean 'hertz'?"), std::string::npos) << show(r);
  EXPECT_EQ(r.out.find("valid"), std::string::npos) << show(r);
}

TEST_F(Cli, ValidateSeveralFilesReportsEachAndFailsIfAnyIsBad) {
  const fs::path bad = kCases / "restitution_out_of_range.json";
  const Result r = domel({"validate", kSettle.string(), bad.string()});
  EXPECT_EQ(r.exit_code, 2) << show(r);
  EXPECT_NE(r.out.find(kSettle.string() + ": valid"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("/interactions/0/restitution"), std::string::npos) << show(r);
}

// ---- run ---------------------------------------------------------------------

TEST_F(Cli, RunOfBadScenarioIsRefusedAndWritesNothing) {
  const fs::path out = tmp_ / "x";
  const fs::path bad = kCases / "wall_material_unknown.json";
  const Result r = domel({"run", bad.string(), "--out", out.string(), "--quiet"});
  EXPECT_EQ(r.exit_code, 2) << show(r);
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("/walls/0/material"), std::string::npos) << show(r);
  EXPECT_FALSE(fs::exists(out)) << "a refused run created " << out;
}

// A problem found only while building (after particles were inserted) must
// leave nothing behind either.
TEST_F(Cli, RunRefusedAtBuildStageWritesNothing) {
  const fs::path out = tmp_ / "x";
  const fs::path bad = kCases / "time_step_too_large.json";
  const Result r = domel({"run", bad.string(), "--out", out.string(), "--quiet"});
  EXPECT_EQ(r.exit_code, 2) << show(r);
  EXPECT_NE(r.err.find("/subdomains/0/time_step"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("stability limit"), std::string::npos) << show(r);
  EXPECT_FALSE(fs::exists(out)) << "a refused run created " << out;
}

// ---- sanity checks before a run (issue 17, item 4) ----------------------------

/// The settle example with its particles from a state file of `rows`
/// ("id,x,y,z,radius" per row, the rest zero), written into `dir`.
fs::path settle_from_state(const fs::path& dir, const std::vector<std::string>& rows) {
  std::ofstream state(dir / "state.csv");
  state << "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed\n";
  for (const auto& r : rows) state << r << ",0,0,0,0,0,0,0\n";
  json doc = json::parse(read_file(kSettle));
  doc["subdomains"][0].erase("insert");
  doc["subdomains"][0]["initial_state"] = "state.csv";
  const fs::path f = dir / "from_state.json";
  std::ofstream(f) << doc.dump(1);
  return f;
}

TEST_F(Cli, AStateFileWithLargeOverlapsIsRefusedAtValidateNamingTheParticles) {
  // two pairs overlapping by 73 % and 10 % of their mean diameter, one by 1 %
  const fs::path f = settle_from_state(tmp_, {"1,0.01,0.01,0.01,0.0014", "2,0.01,0.01,0.010756,0.0014",
                                              "3,0.02,0.02,0.01,0.0014", "4,0.02,0.02,0.01252,0.0014",
                                              "5,0.01,0.02,0.01,0.0014", "6,0.01,0.02,0.012772,0.0014"});
  const Result r = domel({"validate", f.string()});
  EXPECT_EQ(r.exit_code, 2) << show(r);
  EXPECT_NE(r.err.find("/subdomains/0/initial_state"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("2 particle pair(s) overlap"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("ids 1 and 2 (73 %), 3 and 4 (10 %)"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("state.csv"), std::string::npos) << show(r);
  const Result run = domel({"run", f.string(), "--out", (tmp_ / "o").string(), "--quiet"});
  EXPECT_EQ(run.exit_code, 2) << show(run);
  EXPECT_FALSE(fs::exists(tmp_ / "o"));
  // a pair within the limit: reported, accepted
  const fs::path ok = settle_from_state(tmp_, {"5,0.01,0.02,0.01,0.0014", "6,0.01,0.02,0.012772,0.0014"});
  const Result fine = domel({"validate", ok.string()});
  EXPECT_EQ(fine.exit_code, 0) << show(fine);
  EXPECT_NE(fine.err.find("1 overlapping pair(s) at the start, the worst 1 %"), std::string::npos) << show(fine);
}

TEST_F(Cli, AScenarioInMillimetresAndAnEmptySubdomainAreWarnedAbout) {
  json doc = json::parse(read_file(kSettle));
  auto& ins = doc["subdomains"][0]["insert"][0];
  ins["diameter"] = 2.8;  // millimetres
  ins["region"]["box"]["max"] = {28.56, 28.56, 57.12};
  doc["walls"][0]["max"] = {28.56, 28.56, 120};
  doc["subdomains"][0]["time_step"] = "auto";
  doc["subdomains"].push_back({{"name", "empty"}, {"material", "beads"}, {"time_step", 1e-5}});
  const fs::path f = tmp_ / "mm.json";
  std::ofstream(f) << doc.dump(1);
  const Result r = domel({"validate", f.string()});
  EXPECT_NE(r.err.find("particles of 2.8 m diameter; domel works in SI units (m, kg, s), so a scenario written in "
                       "millimetres looks like this"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("/subdomains/0/insert"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("subdomain 'empty' (/subdomains/1) is empty and nothing adds particles to it"),
            std::string::npos) << show(r);
}

TEST_F(Cli, TwoSubdomainsSharingSpaceWithoutACouplingAreWarnedAboutAndAMixtureIsNot) {
  // a "mixture" written as two subdomains in one box: their particles would
  // pass through each other (issue 18 item 3)
  json doc = json::parse(read_file(kSettle));
  doc["subdomains"].push_back(doc["subdomains"][0]);
  doc["subdomains"][1]["name"] = "second";
  const fs::path f = tmp_ / "two.json";
  std::ofstream(f) << doc.dump(1);
  const Result r = domel({"validate", f.string()});
  EXPECT_EQ(r.exit_code, 0) << show(r);
  EXPECT_NE(r.err.find("subdomains 'column' and 'second' share space but no coupling joins them: subdomains never "
                       "touch"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("for a mixture use several materials in one subdomain"), std::string::npos) << show(r);
  // the same two sizes as one subdomain of two materials: no warning
  json mix = json::parse(read_file(kSettle));
  mix["materials"]["steel"] = {{"density", 7800}, {"youngs_modulus", 2e7}, {"poisson_ratio", 0.3}};
  mix["interactions"].push_back({{"materials", {"beads", "steel"}}, {"restitution", 0.5}, {"friction", 0.5}});
  mix["interactions"].push_back({{"materials", {"steel", "steel"}}, {"restitution", 0.5}, {"friction", 0.5}});
  auto& ins = mix["subdomains"][0]["insert"];
  ins.push_back(ins[0]);
  ins[0]["region"]["box"]["max"][2] = 0.02856;
  ins[1]["region"]["box"]["min"][2] = 0.02856;
  ins[1]["material"] = "steel";
  const fs::path g = tmp_ / "mix.json";
  std::ofstream(g) << mix.dump(1);
  const Result m = domel({"validate", g.string()});
  EXPECT_EQ(m.exit_code, 0) << show(m);
  EXPECT_EQ(m.err.find("share space"), std::string::npos) << show(m);
}

// ---- hostile files (issue 17, item 6; docs/reliability.md) ----------------------

// Shapes a fuzzer's short inputs miss, generated here: each is refused with
// exit 2 and a message naming the file, never a crash or a raw library
// exception.
TEST_F(Cli, HostileFilesAreRefusedNamingTheFile) {
  const json settle = json::parse(read_file(kSettle));
  struct Case {
    std::string name, expect;
  };
  std::vector<Case> cases;
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(tmp_ / name, std::ios::binary) << text;
  };
  auto scenario = [&](const std::string& name, const json& doc, const std::string& expect) {
    write(name, doc.dump());
    cases.push_back({name, expect});
  };
  // nesting hundreds of thousands deep, as arrays and as an unknown member
  write("deep.json", std::string(300000, '[') + std::string(300000, ']'));
  cases.push_back({"deep.json", "nest deeper than 64 levels"});
  {
    std::string d = settle.dump();
    d.pop_back();
    d += ",\"extra\":" + std::string(200000, '[') + std::string(200000, ']') + "}";
    write("deep_member.json", d);
    cases.push_back({"deep_member.json", "nest deeper than 64 levels"});
  }
  // tens of megabytes of garbage, and of a valid file's text cut in half
  {
    std::string g(30u << 20, 'x');
    for (std::size_t k = 0; k < g.size(); k += 7) g[k] = static_cast<char>(k * 131 % 256);
    write("garbage.json", g);
    cases.push_back({"garbage.json", "not valid JSON"});
    json big = settle;
    big["description"] = std::string(30u << 20, 'd');
    const std::string text = big.dump();
    write("cut.json", text.substr(0, text.size() / 2));
    cases.push_back({"cut.json", "not valid JSON"});
  }
  // numbers beyond a double, and beyond 64 bits where an integer is read
  {
    // named by its pointer, line and column (the parser's DOM build gives none: a second pass finds it)
    const std::string over = std::regex_replace(settle.dump(), std::regex("\"duration\":0\\.3"), "\"duration\":1e400");
    write("overflow.json", over);
    cases.push_back({"overflow.json", "at /run/duration: not a usable number at line 1, column " +
                                          std::to_string(over.find("1e400") + 1) + ": "});
    // in an array, on the third line
    const std::string arr = "{\"x\": 1,\n \"y\": [1,\n 2, 3e999]}";
    write("overflow_array.json", arr);
    cases.push_back({"overflow_array.json", "at /y/2: not a usable number at line 3, column 5: "});
  }
  {
    json d = settle;
    d["run"]["seed"] = 1e26;
    scenario("seed.json", d, "/run/seed: expected an integer <= 18446744073709551615");
  }
  // a long string where a name goes
  {
    json d = settle;
    d["subdomains"][0]["material"] = std::string(5u << 20, 'm');
    scenario("long.json", d, "/subdomains/0/material");
  }
  // every file a scenario can name, truncated or garbage
  {
    std::string junk(5000, '\0');
    for (std::size_t k = 0; k < junk.size(); ++k) junk[k] = static_cast<char>((k * 7919 + 13) % 256);
    const std::string stl = read_file(fs::path(DOMEL_SOURCE_DIR) / "scenarios/examples/chute.stl");
    json hopper = json::parse(read_file(fs::path(DOMEL_SOURCE_DIR) / "scenarios/examples/hopper.json"));
    std::size_t mesh = 0;
    while (hopper["walls"][mesh]["type"] != "mesh") ++mesh;
    for (const auto& [file, text] : std::vector<std::pair<std::string, std::string>>{
             {"cut.stl", stl.substr(0, stl.size() / 2)}, {"junk.stl", junk}, {"solid_junk.stl", "solid x\n" + junk}}) {
      write(file, text);
      hopper["walls"][mesh]["file"] = file;
      scenario("mesh_" + file + ".json", hopper, file);
    }
    const std::string header = "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed\n";
    for (const auto& [file, text] : std::vector<std::pair<std::string, std::string>>{
             {"cut.csv", header + "1,0.01,0.01,0.01,0.0014,0,0,0,0,0,0,0\n2,0.02,0.0"}, {"junk.csv", junk},
             {"nan.csv", header + "1,nan,0.01,0.01,0.0014,0,0,0,0,0,0,0\n"}, {"big.csv", header + "1,1e400,0,0,1,0,0,0,0,0,0,0\n"}}) {
      write(file, text);
      json d = settle;
      d["subdomains"][0].erase("insert");
      d["subdomains"][0]["initial_state"] = file;
      scenario("state_" + file + ".json", d, file);
    }
    write("junk.so", junk);
    write("empty.so", "");
    for (const char* lib : {"junk.so", "empty.so"}) {
      json d = settle;
      d["plugins"] = {lib};
      scenario(std::string("plugin_") + lib + ".json", d, lib);
    }
  }
  for (const auto& c : cases) {
    const Result r = domel({"validate", (tmp_ / c.name).string()});
    EXPECT_EQ(r.exit_code, 2) << c.name << ": " << show(r).substr(0, 2000);
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.name << ": " << show(r).substr(0, 2000);
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << c.name << ": a raw library exception";
    const Result run = domel({"run", (tmp_ / c.name).string(), "--out", (tmp_ / "never").string(), "--quiet"});
    EXPECT_EQ(run.exit_code, 2) << c.name << ": " << show(run).substr(0, 2000);
    EXPECT_FALSE(fs::exists(tmp_ / "never")) << c.name;
  }
}

// ---- output folders, signals, restarts (docs/checkpoint.md) ---------------------

TEST_F(Cli, ASecondRunIntoAFolderIsRefusedAndOverwriteRemovesOnlyTheFirstRunsFiles) {
  const fs::path out = tmp_ / "o";
  ASSERT_EQ(domel({"run", kSettle.string(), "--out", out.string(), "--max-steps", "1100", "--quiet"}).exit_code, 0);
  ASSERT_TRUE(fs::exists(out / "particles_000001.vtp"));
  std::ofstream(out / "notes.txt") << "mine\n";
  const Result again = domel({"run", kSettle.string(), "--out", out.string(), "--max-steps", "5", "--quiet"});
  EXPECT_EQ(again.exit_code, 2) << show(again);
  EXPECT_NE(again.err.find(out.string()), std::string::npos) << show(again);
  EXPECT_NE(again.err.find("--overwrite"), std::string::npos) << show(again);
  EXPECT_TRUE(fs::exists(out / "particles_000001.vtp")) << "a refused run removed a file";
  const Result over = domel({"run", kSettle.string(), "--out", out.string(), "--max-steps", "5", "--quiet", "--overwrite"});
  ASSERT_EQ(over.exit_code, 0) << show(over);
  EXPECT_FALSE(fs::exists(out / "particles_000001.vtp")) << "the first run's later frame was left behind";
  EXPECT_TRUE(fs::exists(out / "particles_000000.vtp"));
  EXPECT_EQ(read_file(out / "notes.txt"), "mine\n") << "--overwrite removed a file domel did not write";
  const Result both = domel({"run", kSettle.string(), "--out", out.string(), "--overwrite", "--restart",
                             (out / "checkpoint.ckpt").string()});
  EXPECT_EQ(both.exit_code, 64) << show(both);
}

TEST_F(Cli, SigintWritesACheckpointAndTheRestartEndsLikeAnUninterruptedRun) {
  // the settle example for its first 0.1 s (the column falls and piles up), stopped by SIGINT part way,
  // then continued
  const fs::path plain = tmp_ / "plain", cut = tmp_ / "cut", settle = tmp_ / "settle_0.1s.json";
  {
    json d = json::parse(read_file(kSettle));
    d["run"]["duration"] = 0.1;
    std::ofstream(settle) << d.dump();
  }
  ASSERT_EQ(domel({"run", settle.string(), "--out", plain.string(), "--quiet", "--threads", "1"}).exit_code, 0);
  const std::string cmd = "exec " + shell_quote(kDomel) + " run " + shell_quote(settle.string()) + " --out " +
                          shell_quote(cut.string()) + " --quiet --threads 1 >" + shell_quote((tmp_ / "cut.log").string()) +
                          " 2>&1";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // wait until it has written a few frames (it takes about a second in all,
  // many times that under the sanitizers), so that the handler is installed
  for (int k = 0; k < 3000 && !fs::exists(cut / "particles_000003.vtp"); ++k) usleep(20000);
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << read_file(tmp_ / "cut.log");
  if (WEXITSTATUS(status) == 0) GTEST_SKIP() << "the run ended before the signal came";
  EXPECT_EQ(WEXITSTATUS(status), 130) << read_file(tmp_ / "cut.log");
  const json s = json::parse(read_file(cut / "summary.json"));
  EXPECT_EQ(s["status"], "interrupted");
  EXPECT_EQ(s["signal"], "SIGINT");
  ASSERT_TRUE(fs::exists(cut / "checkpoint.ckpt"));
  EXPECT_NE(read_file(tmp_ / "cut.log").find("--restart"), std::string::npos) << "it says how to continue";
  const Result r = domel({"run", settle.string(), "--restart", (cut / "checkpoint.ckpt").string(), "--quiet",
                          "--threads", "1"});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  const json done = json::parse(read_file(cut / "summary.json"));
  EXPECT_EQ(done["status"], "completed");
  EXPECT_TRUE(done.contains("restarted_from"));
  EXPECT_TRUE(read_file(plain / "probes.csv") == read_file(cut / "probes.csv"));
  EXPECT_TRUE(read_file(plain / "particles.pvd") == read_file(cut / "particles.pvd"));
  EXPECT_TRUE(read_file(plain / "particles_000010.vtp") == read_file(cut / "particles_000010.vtp"));
  EXPECT_FALSE(fs::exists(cut / "particles_000011.vtp"));
}

TEST_F(Cli, RunWritesCompleteOutputs) {
  const fs::path out = tmp_ / "y";
  const Result r = domel({"run", kSettle.string(), "--out", out.string(), "--max-steps", "50", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << show(r);

  ASSERT_TRUE(fs::is_regular_file(out / "summary.json")) << show(r);
  json summary;
  ASSERT_NO_THROW(summary = json::parse(read_file(out / "summary.json")));
  ASSERT_TRUE(summary.is_object());
  EXPECT_TRUE(summary.contains("domel_version") && summary["domel_version"].is_string() &&
              !summary["domel_version"].get<std::string>().empty())
      << summary.dump(2);
  ASSERT_TRUE(summary.contains("plugin_libraries") && summary["plugin_libraries"].is_array()) << summary.dump(2);
  EXPECT_FALSE(summary["plugin_libraries"].empty()) << summary.dump(2);
  for (const auto& lib : summary["plugin_libraries"]) {
    EXPECT_TRUE(lib.contains("name") && lib["name"].is_string()) << lib.dump();
    EXPECT_TRUE(lib.contains("version") && lib["version"].is_string() && !lib["version"].get<std::string>().empty())
        << lib.dump();
  }
  ASSERT_TRUE(summary.contains("steps") && summary["steps"].is_number_integer()) << summary.dump(2);
  EXPECT_EQ(summary["steps"].get<long long>(), 50);
  ASSERT_TRUE(summary.contains("particle_steps_per_s") && summary["particle_steps_per_s"].is_number())
      << summary.dump(2);
  EXPECT_GT(summary["particle_steps_per_s"].get<double>(), 0.0);

  EXPECT_TRUE(fs::is_regular_file(out / "probes.csv"));
  EXPECT_TRUE(fs::is_regular_file(out / "particles.pvd"));
  int vtp = 0;
  std::vector<std::string> temporaries;
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".vtp") ++vtp;
    if (name.find(".tmp-") != std::string::npos) temporaries.push_back(name);
  }
  EXPECT_GE(vtp, 1) << "no .vtp file in " << out;
  EXPECT_TRUE(temporaries.empty()) << "left-over temporary file " << temporaries.front();
}

// ---- plugins -------------------------------------------------------------------

TEST_F(Cli, PluginsListsModelsWithVersionsAndAbi) {
  const Result r = domel({"plugins"});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(library \S+ \S+ \(ABI \d+\.\d+\))"))) << show(r);
  for (const char* model : {"hertz", "mindlin", "lattice"})
    EXPECT_TRUE(std::regex_search(r.out, std::regex(std::string(R"(\s)") + model + R"(\s+\d+\.\d+\.\d+\s)")))
        << model << " with a version\n" << show(r);
}

TEST_F(Cli, PluginsJsonParses) {
  const Result r = domel({"plugins", "--json"});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  json list;
  ASSERT_NO_THROW(list = json::parse(r.out)) << show(r);
  ASSERT_TRUE(list.is_array());
  for (const char* model : {"hertz", "mindlin", "lattice"}) {
    bool found = false;
    for (const auto& m : list) {
      if (m.value("name", "") != model) continue;
      found = true;
      EXPECT_FALSE(m.value("version", "").empty()) << m.dump();
      EXPECT_TRUE(std::regex_match(m.value("abi", ""), std::regex(R"(\d+\.\d+)"))) << m.dump();
      EXPECT_TRUE(m.contains("parameters")) << m.dump();
    }
    EXPECT_TRUE(found) << model << " missing from `domel plugins --json`";
  }
}

// ---- schema and docs -----------------------------------------------------------

TEST_F(Cli, SchemaHasEveryNormalModelAndIsUsableBySchemaValidator) {
  const Result r = domel({"schema"});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  json schema;
  ASSERT_NO_THROW(schema = json::parse(r.out)) << show(r);
  ASSERT_TRUE(schema.contains("$defs")) << show(r);
  const json& normal = schema["$defs"]["normal_model"];
  ASSERT_TRUE(normal.contains("oneOf") && normal["oneOf"].is_array()) << normal.dump(2);
  std::vector<std::string> names;
  for (const auto& alt : normal["oneOf"])
    if (alt.contains("properties") && alt["properties"].contains("model") &&
        alt["properties"]["model"].contains("const"))
      names.push_back(alt["properties"]["model"]["const"].get<std::string>());
  for (const char* model : {"hertz", "linear"})
    EXPECT_NE(std::find(names.begin(), names.end(), model), names.end()) << model << " not in normal_model.oneOf";

  // The printed schema is one domel's own validator accepts, and it accepts
  // the example scenario.
  std::unique_ptr<domel::platform::SchemaValidator> validator;
  ASSERT_NO_THROW(validator = std::make_unique<domel::platform::SchemaValidator>(schema));
  std::vector<domel::platform::Diagnostic> diags;
  validator->validate(json::parse(read_file(kSettle)), diags);
  for (const auto& d : diags) ADD_FAILURE() << "the composed schema refuses settle.json: " << d.format();
}

TEST_F(Cli, SchemaOutWritesTheSameText) {
  const fs::path file = tmp_ / "schema.json";
  const Result printed = domel({"schema"});
  const Result written = domel({"schema", "--out", file.string()});
  ASSERT_EQ(written.exit_code, 0) << show(written);
  EXPECT_EQ(read_file(file), printed.out);
}

TEST_F(Cli, DocsPrintsMarkdownReference) {
  const Result r = domel({"docs"});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  EXPECT_NE(r.out.find("### `hertz`"), std::string::npos) << show(r);
  EXPECT_NE(r.out.find("### `lattice`"), std::string::npos) << show(r);
}

// ---- usage errors and version --------------------------------------------------

TEST_F(Cli, UnknownCommandSuggestsTheClosest) {
  const Result r = domel({"rnu"});
  EXPECT_EQ(r.exit_code, 64) << show(r);
  EXPECT_NE(r.err.find("unknown command 'rnu'"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("did you mean 'run'?"), std::string::npos) << show(r);
}

TEST_F(Cli, UnknownOptionIsAUsageError) {
  const fs::path out = tmp_ / "z";
  const Result r = domel({"run", kSettle.string(), "--out", out.string(), "--max-step", "5"});
  EXPECT_EQ(r.exit_code, 64) << show(r);
  EXPECT_NE(r.err.find("unknown option --max-step"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("did you mean '--max-steps'?"), std::string::npos) << show(r);
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, BadThreadEnvironmentIsAUsageErrorAndWritesNothing) {
  const fs::path out = tmp_ / "t";
  for (const std::string bad : {"abc", "0", "300", "2x"}) {
    const Result r = domel({"run", kSettle.string(), "--out", out.string(), "--max-steps", "5"}, "DOMEL_THREADS=" + bad);
    EXPECT_EQ(r.exit_code, 64) << show(r);
    EXPECT_NE(r.err.find("DOMEL_THREADS expects an integer from 1 to 256, found '" + bad + "'"), std::string::npos)
        << show(r);
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
  const Result ok = domel({"run", kSettle.string(), "--out", out.string(), "--max-steps", "5", "--quiet"},
                          "DOMEL_THREADS=2");
  EXPECT_EQ(ok.exit_code, 0) << show(ok);
  const json summary = json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(summary["threads"], 2);  // the environment sets the default when the scenario and CLI do not
}

TEST_F(Cli, NoCommandPrintsUsage) {
  const Result r = domel({});
  EXPECT_EQ(r.exit_code, 64) << show(r);
  EXPECT_NE(r.err.find("usage: domel"), std::string::npos) << show(r);
}

TEST_F(Cli, VersionPrintsVersions) {
  const Result r = domel({"version"});
  EXPECT_EQ(r.exit_code, 0) << show(r);
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(^domel \S+ \(SDK ABI \d+\.\d+\))"))) << show(r);
}

}  // namespace

// ---- compare ------------------------------------------------------------------

// Guards `domel compare`: two variants of one scenario run with the same
// insertion and give a report with a table of final values (one column per
// variant) and each variant's own complete output.
TEST_F(Cli, CompareRunsVariantsAndWritesAReport) {
  const fs::path out = tmp_ / "cmp";
  const Result r = domel({"compare", kSettle.string(), "--vary",
                          R"(/subdomains/0/contact/rolling={"model":"sd_critical_angle","critical_angle":20})",
                          "--vary", R"(/subdomains/0/contact/rolling={"model":"dct","critical_angle":20})",
                          "--label", "sd", "--label", "dct", "--out", out.string(), "--max-steps", "40", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  const std::string report = read_file(out / "report.md");
  EXPECT_NE(report.find("| quantity | sd | dct |"), std::string::npos) << report;
  EXPECT_NE(report.find("column.median_angular_speed [rad/s]"), std::string::npos) << report;
  EXPECT_NE(report.find("column.ke_translational [J]"), std::string::npos) << report;
  EXPECT_NE(report.find("| time [s] |"), std::string::npos) << report;
  EXPECT_NE(report.find("Stopped early by --max-steps** (sd: 40 of 30000 macro steps; dct: 40 of 30000"),
            std::string::npos) << report;
  EXPECT_NE(r.err.find("variant 'sd' stops after 40 of its 30000 macro steps (--max-steps)"), std::string::npos)
      << show(r);
  for (const char* v : {"sd", "dct"}) {
    EXPECT_TRUE(fs::is_regular_file(out / v / "summary.json")) << v;
    const json s = json::parse(read_file(out / v / "summary.json"));
    EXPECT_EQ(s["steps"], 40);
    EXPECT_EQ(s["models"]["column"]["rolling"]["model"], std::string(v) == "sd" ? "sd_critical_angle" : "dct");
  }
  // same seeds and insertion: the t = 0 particle files are byte-identical
  const std::string first_sd = read_file(out / "sd" / "particles_000000.vtp");
  EXPECT_FALSE(first_sd.empty());
  EXPECT_EQ(first_sd, read_file(out / "dct" / "particles_000000.vtp"));
}

// Guards that a bad variant is refused before anything runs, naming the variant.
TEST_F(Cli, CompareRefusesABadVariantBeforeRunning) {
  const fs::path out = tmp_ / "cmp_bad";
  const Result r = domel({"compare", kSettle.string(), "--vary", "/subdomains/0/time_step=1e-5", "--vary",
                          R"(/subdomains/0/contact/rolling={"model":"dtc"})", "--out", out.string(), "--quiet"});
  EXPECT_EQ(r.exit_code, 2) << show(r);
  EXPECT_NE(r.err.find("did you mean 'dct'?"), std::string::npos) << show(r);
  EXPECT_NE(r.err.find("variant"), std::string::npos) << show(r);
  EXPECT_FALSE(fs::exists(out)) << "nothing may be written when a variant is refused";
}

// Guards `domel compare --runs`: the report of runs made before (here two
// short runs of settle.json) has the same table, one column per run, and
// names each run's folder; a folder that holds no finished run is refused,
// naming it, and no report is written.
TEST_F(Cli, CompareReportsFinishedRunsAndRefusesAFolderWithoutOne) {
  for (const char* v : {"a", "b"}) {
    const Result run = domel({"run", kSettle.string(), "--out", (tmp_ / v).string(), "--max-steps",
                              std::string(v) == "a" ? "30" : "60", "--quiet"});
    ASSERT_EQ(run.exit_code, 0) << show(run);
  }
  const fs::path out = tmp_ / "cmp_runs";
  const Result r = domel({"compare", "--runs", (tmp_ / "a").string(), "--runs", (tmp_ / "b").string(), "--label",
                          "short", "--label", "long", "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << show(r);
  const std::string report = read_file(out / "report.md");
  EXPECT_NE(report.find("| quantity | short | long |"), std::string::npos) << report;
  EXPECT_NE(report.find((tmp_ / "b").string()), std::string::npos) << report;
  EXPECT_NE(report.find("column.median_angular_speed"), std::string::npos) << report;

  fs::create_directories(tmp_ / "empty");
  const fs::path out2 = tmp_ / "cmp_runs_bad";
  const Result bad = domel({"compare", "--runs", (tmp_ / "a").string(), "--runs", (tmp_ / "empty").string(), "--out",
                            out2.string()});
  EXPECT_EQ(bad.exit_code, 2) << show(bad);
  EXPECT_NE(bad.err.find((tmp_ / "empty").string()), std::string::npos) << show(bad);
  EXPECT_NE(bad.err.find("summary.json"), std::string::npos) << show(bad);
  EXPECT_FALSE(fs::exists(out2 / "report.md"));
}
