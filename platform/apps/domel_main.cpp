// SPDX-License-Identifier: MIT
// The domel executable: run, validate, plugins, schema, docs, version.
// Command-line parsing is a few lines by hand: a handful of --key value
// options per sub-command does not justify another dependency.
// Exit codes: 0 success, 1 the run failed, 2 the scenario (or a plugin) was
// refused, 64 wrong command-line usage.
#include "apps/compare.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "distributed/communicator.hpp"
#include "distributed/mpi_ranks.hpp"
#include "io/atomic_file.hpp"
#include "io/output_folder.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/reference.hpp"
#include "scenario/scenario.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include <unistd.h>

namespace dp = domel::platform;

namespace {

constexpr int kExitRunFailed = 1;
constexpr int kExitRefused = 2;
constexpr int kExitUsage = 64;

/// The ranks of a run under mpirun (one rank otherwise): rank 0 reports, and
/// the others say only what failed on them.
dp::Communicator& world() {
  static dp::Communicator c;
  return c;
}

const char* kUsage = R"(usage: domel <command> [options]

commands:
  run FILE [--out DIR] [--overwrite] [--threads N] [--max-steps N] [--time-after N]
      [--restart CHECKPOINT] [--checkpoint-on-signal on|off] [--quiet] [--verbose]
      (under mpirun -np N: the run spread over N processes, docs/distributed.md)
                      validate and run a scenario; writes particles_*.vtp + particles.pvd
                      (ParaView), probes.csv and summary.json into the output folder.
                      --max-steps stops early; --time-after N also reports the speed of
                      the steps after the first N (benchmarks, in summary.json);
                      --restart continues the run that wrote CHECKPOINT (run.checkpoint_interval)
                      in its folder, bit-identically on the same thread count; a folder that
                      holds an earlier run's output is refused unless --overwrite, which
                      removes the files that run listed in domel_manifest.txt. SIGINT/SIGTERM
                      finish the step and write a checkpoint (unless --checkpoint-on-signal off)
  compare FILE --vary POINTER=VALUE[;POINTER=VALUE...] [--vary ...] [--label NAME ...]
          [--out DIR] [--threads N] [--max-steps N]
                      run variants of one scenario (same seeds and insertion) and write
                      DIR/report.md with a table of final values and PNG plots, e.g.
                      --vary '/subdomains/0/contact/rolling={"model":"dct","rolling_friction":0.1}'
  compare --runs DIR --runs DIR [--runs ...] [--label NAME ...] [--out DIR]
                      the same report of finished runs (their output folders), made
                      by any scenarios, e.g. runs made side by side on several cores
  validate FILE...    check scenarios without running them; lists every problem
  plugins [--json]    list loaded plugin models with versions, ABI and parameters
  schema [--out FILE] print the complete scenario JSON Schema (for editors, via "$schema")
  docs [--out FILE]   print the scenario reference (Markdown) generated from the schemas
  version             print versions

plugins are loaded from the built-in folder, then from each folder in
$DOMEL_PLUGIN_PATH (':'-separated), then from the scenario's "plugins" list.
$DOMEL_THREADS (1..256) sets the thread count where neither --threads nor the
scenario's run.threads does.
)";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string> options;  // --key value
  std::vector<std::string> flags;              // --flag
  bool flag(const std::string& f) const { return std::find(flags.begin(), flags.end(), f) != flags.end(); }
  std::optional<std::string> option(const std::string& o) const {
    auto it = options.find(o);
    return it == options.end() ? std::nullopt : std::optional<std::string>(it->second);
  }
};

Args parse(int argc, char** argv, int first, const std::vector<std::string>& with_value,
           const std::vector<std::string>& flags) {
  Args a;
  for (int k = first; k < argc; ++k) {
    const std::string s = argv[k];
    if (s.rfind("--", 0) == 0) {
      if (std::find(with_value.begin(), with_value.end(), s) != with_value.end()) {
        if (k + 1 >= argc) throw UsageError("option " + s + " needs a value");
        a.options[s] = argv[++k];
      } else if (std::find(flags.begin(), flags.end(), s) != flags.end()) {
        a.flags.push_back(s);
      } else {
        std::vector<std::string> all = with_value;
        all.insert(all.end(), flags.begin(), flags.end());
        const std::string hint = dp::suggest(s, all);
        throw UsageError("unknown option " + s + (hint.empty() ? "" : " (" + hint + ")"));
      }
    } else {
      a.positional.push_back(s);
    }
  }
  return a;
}

long parse_count(const std::string& option, const std::string& value) {
  try {
    std::size_t used = 0;
    const long v = std::stol(value, &used);
    if (used != value.size() || v < 1) throw std::invalid_argument("");
    return v;
  } catch (const std::exception&) {
    throw UsageError(option + " expects a positive integer, found '" + value + "'");
  }
}

/// DOMEL_THREADS, checked before anything is read or written so that a bad
/// value is a usage error, not a failure half-way through building a run.
void check_thread_environment() {
  try {
    (void)dp::default_thread_count();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

int parse_threads(const std::string& value) {
  const long n = parse_count("--threads", value);
  if (n > 256) throw UsageError("--threads expects at most 256, found " + value);
  const unsigned cores = std::thread::hardware_concurrency();
  if (cores > 0 && n > static_cast<long>(cores))
    spdlog::warn("--threads {} exceeds the {} hardware threads of this machine; expect a slowdown", n, cores);
  return static_cast<int>(n);
}

void load_default_plugins(dp::PluginRegistry& registry) {
  for (const auto& dir : dp::default_plugin_directories()) {
    const std::size_t n = registry.load_directory(dir);
    if (n) spdlog::debug("plugins: {} librar{} from {}", n, n == 1 ? "y" : "ies", dir.string());
  }
  for (const auto& r : registry.refused()) spdlog::warn("{}", r);
}

/// The problems a rank other than 0 found (main() prints them when rank 0
/// did not end the run first: a problem of that rank alone, such as its part
/// of a checkpoint).
std::string g_deferred_problems;

/// True when every rank of the run ended with the same code by agreement
/// (agree_on_scenario()): main() ends them normally, without MPI_Abort.
bool g_ranks_agreed = false;
/// True when a stop request ended the run inside a macro step (the ranks
/// did not stop together): main() ends the others with MPI_Abort.
bool g_stopped_mid_step = false;

std::string diagnostics_text(const std::string& what, const std::vector<dp::Diagnostic>& diags) {
  std::string text = "domel: " + what + " has " + std::to_string(diags.size()) + " problem" +
                     (diags.size() == 1 ? "" : "s") + ":\n";
  for (const auto& d : diags) {
    // a problem in another file (a checkpoint, a state file) names it
    const std::string in = !d.file.empty() && d.file != what ? d.file + ", " : "";
    std::string line = !in.empty() && d.pointer.empty()
                           ? "  - " + d.file + ": " + d.message
                           : "  - " + in + "at " + (d.pointer.empty() ? std::string("/") : d.pointer) + ": " + d.message;
    if (!d.hint.empty()) line += " (" + d.hint + ")";
    text += line + "\n";
  }
  return text;
}

void print_diagnostics(const std::string& what, const std::vector<dp::Diagnostic>& diags) {
  const std::string text = diagnostics_text(what, diags);
  // every rank read the same scenario: rank 0 says it once
  if (world().rank() == 0) std::fputs(text.c_str(), stderr);
  else g_deferred_problems = "(rank " + std::to_string(world().rank()) + ") " + text;
}

/// The plugins a rank loaded (name, version, ABI of each library, sorted)
/// and the libraries it refused: what must be the same on every rank.
std::string plugin_view(const dp::PluginRegistry& registry) {
  std::vector<std::string> lines;
  for (const auto& lib : registry.libraries())
    lines.push_back(lib.name + " " + lib.version + " (ABI " + std::to_string(lib.abi_major) + "." +
                    std::to_string(lib.abi_minor) + ")");
  for (const auto& r : registry.refused()) lines.push_back(r);
  std::sort(lines.begin(), lines.end());
  std::string view;
  for (const auto& l : lines) view += "    " + l + "\n";
  return view;
}

/// "0, 2" for the ranks in `ranks`.
std::string rank_list(const std::vector<int>& ranks) {
  std::string s;
  for (std::size_t k = 0; k < ranks.size(); ++k) s += (k ? ", " : "") + std::to_string(ranks[k]);
  return s;
}

/// Under mpirun, before anything is run or written: every rank must have
/// loaded the same plugins and come to the same verdict on the scenario (a
/// plugin or state file that one node's file system holds damaged, another
/// version of a plugin on one node). Every rank learns what every rank
/// found; rank 0 reports where they differ. Returns 0 when every rank may
/// run, else kExitRefused on every rank alike.
int agree_on_scenario(const std::string& scenario, const dp::PluginRegistry& registry,
                      const std::vector<dp::Diagnostic>& problems) {
  const std::string mine = plugin_view(registry) + "\x1f" +
                           (problems.empty() ? std::string() : diagnostics_text(scenario, problems));
  const auto all = world().all_gather(std::vector<char>(mine.begin(), mine.end()));
  std::map<std::string, std::vector<int>> views, verdicts;  // text -> ranks
  bool any_refused = false;
  for (int r = 0; r < static_cast<int>(all.size()); ++r) {
    const std::string text(all[r].begin(), all[r].end());
    const std::size_t cut = text.find('\x1f');
    views[text.substr(0, cut)].push_back(r);
    const std::string verdict = cut == std::string::npos ? "" : text.substr(cut + 1);
    verdicts[verdict].push_back(r);
    any_refused = any_refused || !verdict.empty();
  }
  if (views.size() == 1 && !any_refused) return 0;
  g_ranks_agreed = true;
  if (world().rank() != 0) return kExitRefused;
  std::string text;
  if (views.size() > 1) {
    // each view's lines that not every rank has
    auto lines_of = [](const std::string& view) {
      std::vector<std::string> lines;
      std::istringstream in(view);
      for (std::string l; std::getline(in, l);) lines.push_back(l);
      return lines;
    };
    std::map<std::string, std::size_t> seen;
    for (const auto& v : views)
      for (const auto& l : lines_of(v.first)) ++seen[l];
    std::size_t common = 0;
    for (const auto& [l, n] : seen) common += n == views.size();
    text += "domel: the ranks do not load the same plugins, so they would not run the same models (besides the " +
            std::to_string(common) + " every rank loaded):\n";
    for (const auto& [view, ranks] : views) {
      text += "  rank" + std::string(ranks.size() > 1 ? "s " : " ") + rank_list(ranks) + ":\n";
      std::size_t own = 0;
      for (const auto& l : lines_of(view))
        if (seen[l] < views.size()) text += l + "\n", ++own;
      if (own == 0) text += "    (nothing else)\n";
    }
    text += "  (the same plugin folders, $DOMEL_PLUGIN_PATH and plugin files on every node)\n";
  }
  if (verdicts.size() == 1) {
    text += verdicts.begin()->first;  // every rank refused the scenario alike
  } else {
    for (const auto& [verdict, ranks] : verdicts) {
      if (verdict.empty()) continue;
      text += "on rank" + std::string(ranks.size() > 1 ? "s " : " ") + rank_list(ranks) + " (the others accepted it: " +
              "a file the scenario names differs between the ranks' views) " + verdict;
    }
  }
  std::fputs(text.c_str(), stderr);
  std::fprintf(stderr, "nothing was run and nothing was written.\n");
  return kExitRefused;
}

/// SIGINT and SIGTERM ask the run to stop after its current step
/// (core/interrupt.hpp); a second one ends the process at once (the handler
/// resets itself).
volatile std::sig_atomic_t g_announce_stop = 1;  ///< 0 on the ranks other than 0 (rank 0 speaks for the run)

extern "C" void on_stop_signal(int sig) {
  dp::request_interrupt(sig);
  if (!g_announce_stop) return;
  const char msg[] = "\ndomel: stopping after this step, writing a checkpoint and the outputs (again to quit at once)\n";
  const ssize_t ignored = ::write(2, msg, sizeof msg - 1);
  (void)ignored;
}

void install_stop_handlers() {
  g_announce_stop = world().rank() == 0 ? 1 : 0;
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int cmd_run(int argc, char** argv) {
  const Args a = parse(argc, argv, 2,
                       {"--out", "--threads", "--max-steps", "--time-after", "--restart", "--checkpoint-on-signal"},
                       {"--quiet", "--verbose", "--overwrite"});
  if (a.positional.size() != 1) throw UsageError("run expects one scenario file");
  if (a.flag("--overwrite") && a.option("--restart"))
    throw UsageError("--overwrite and --restart exclude each other: a restart continues its folder's files");
  check_thread_environment();
  if (a.flag("--quiet")) spdlog::set_level(spdlog::level::warn);
  if (a.flag("--verbose")) spdlog::set_level(spdlog::level::debug);
  // every rank computes what rank 0 does (warnings included): rank 0 speaks for the run
  if (world().rank() != 0) spdlog::set_level(spdlog::level::err);
  dp::RunOptions opt;
  std::unique_ptr<dp::MpiRunRanks> ranks;
  if (world().size() > 1) {  // under mpirun; one process runs alone (RunOptions' default)
    ranks = std::make_unique<dp::MpiRunRanks>(world());
    opt.ranks = ranks.get();
  }
  if (auto o = a.option("--out")) opt.output_directory = *o;
  if (auto t = a.option("--threads")) opt.threads = parse_threads(*t);
  if (auto s = a.option("--max-steps")) opt.max_steps = static_cast<std::uint64_t>(parse_count("--max-steps", *s));
  if (auto s = a.option("--time-after")) opt.time_after = static_cast<std::uint64_t>(parse_count("--time-after", *s));
  if (auto r = a.option("--restart")) {
    opt.restart = *r;
    // a restart continues the checkpointed run's files, in its folder
    if (opt.output_directory.empty()) opt.output_directory = opt.restart.parent_path().empty() ? "." : opt.restart.parent_path();
  }
  if (auto c = a.option("--checkpoint-on-signal")) {
    if (*c != "on" && *c != "off") throw UsageError("--checkpoint-on-signal expects on or off, found '" + *c + "'");
    opt.checkpoint_on_signal = *c == "on";
  }
  opt.progress = !a.flag("--quiet");

  dp::PluginRegistry registry;
  load_default_plugins(registry);
  std::unique_ptr<dp::Simulation> sim;
  std::vector<dp::Diagnostic> problems;
  try {
    sim = dp::load_scenario(a.positional[0], registry);
  } catch (const dp::ConfigError& e) {
    problems = e.diagnostics();
  }
  if (world().size() > 1) {
    if (const int code = agree_on_scenario(a.positional[0], registry, problems)) return code;
  } else if (!problems.empty()) {
    print_diagnostics(a.positional[0], problems);
    std::fprintf(stderr, "nothing was run and nothing was written.\n");
    return kExitRefused;
  }
  try {
    dp::RunResult result;
    try {
      // an earlier run's files are neither mixed with this run's nor removed unasked
      if (world().rank() == 0)
        dp::io::prepare_output_folder(opt.output_directory.empty() ? sim->output_directory : opt.output_directory,
                                    !opt.restart.empty()   ? dp::io::OutputPolicy::restart
                                    : a.flag("--overwrite") ? dp::io::OutputPolicy::overwrite
                                                            : dp::io::OutputPolicy::fresh);
      install_stop_handlers();
      result = sim->run(opt, registry);
    } catch (const dp::ConfigError& e) {
      print_diagnostics(a.positional[0], e.diagnostics());
      if (world().rank() == 0) std::fprintf(stderr, "nothing was run.\n");
      return kExitRefused;
    }
    if (world().rank() == 0)
      std::printf("%s: %llu steps, %.6g s simulated, %.3g s wall, %.3g particle-steps/s; output in %s\n",
                sim->name.c_str(), static_cast<unsigned long long>(result.macro_steps), result.simulated_time,
                result.wall_seconds, result.particle_steps_per_second, result.output_directory.string().c_str());
    if (result.interrupted_by) {
      const bool ck = result.summary.contains("checkpoint");
      if (world().rank() == 0)
        std::fprintf(stderr, "domel: interrupted at t = %.6g s; %s\n", result.simulated_time,
                   ck ? ("continue with: domel run " + a.positional[0] + " --restart " +
                         (result.output_directory / result.summary["checkpoint"].get<std::string>()).string())
                            .c_str()
                      : "no checkpoint was written");
      return 128 + result.interrupted_by;  // the shell's convention: 130 for SIGINT, 143 for SIGTERM
    }
  } catch (const std::exception& e) {
    const std::string where = world().size() > 1 ? " on rank " + std::to_string(world().rank()) : "";
    // what the run can go on from
    const auto& ck = sim->last_checkpoint();
    const std::string resume = ck ? "the last checkpoint, of t = " + fmt::format("{:.6g}", ck->time) +
                                        " s, is intact; continue with: domel run " + a.positional[0] + " --restart " +
                                        ck->file.string()
                                  : std::string("no checkpoint was written");
    if (const int sig = dp::interrupt_requested(); sig != 0 && dp::stop_overdue()) {
      // a loop inside the step gave up on the stop request (core/interrupt.hpp), or failed while it waited
      std::fprintf(stderr, "domel: interrupted%s in the middle of a macro step that did not end within %.0f s of "
                           "the request: %s\nnothing of the unfinished step was written; %s; summary.json was not "
                           "written\n",
                   where.c_str(), dp::kStopGraceSeconds, e.what(), resume.c_str());
      g_stopped_mid_step = true;
      return 128 + sig;
    }
    std::fprintf(stderr, "domel: the run of %s failed%s: %s\nFiles written before the failure are complete; "
                         "summary.json was not written; %s%s\n", a.positional[0].c_str(), where.c_str(), e.what(),
                 resume.c_str(), ck ? "" : " (run.checkpoint_interval)");
    return kExitRunFailed;
  }
  return 0;
}

int cmd_compare(int argc, char** argv) {
  check_thread_environment();
  // --vary and --label repeat, so they are collected here rather than by parse()
  dp::CompareOptions opt;
  std::vector<std::string> varies, labels, runs;
  std::vector<std::string> rest_args;
  for (int k = 2; k < argc; ++k) {
    const std::string s = argv[k];
    if ((s == "--vary" || s == "--label" || s == "--runs") && k + 1 < argc) {
      (s == "--vary" ? varies : s == "--label" ? labels : runs).push_back(argv[++k]);
    } else if (s == "--vary" || s == "--label" || s == "--runs") {
      throw UsageError("option " + s + " needs a value");
    } else {
      rest_args.push_back(s);
    }
  }
  std::vector<char*> rest = {argv[0], argv[1]};
  for (auto& s : rest_args) rest.push_back(s.data());
  const Args a = parse(static_cast<int>(rest.size()), rest.data(), 2, {"--out", "--threads", "--max-steps"}, {"--quiet"});
  if (!runs.empty()) {
    // the report of finished runs: nothing is run
    if (!a.positional.empty() || !varies.empty())
      throw UsageError("compare --runs takes output folders of finished runs, not a scenario or --vary");
    if (runs.size() < 2) throw UsageError("compare --runs needs at least two run folders");
    if (!labels.empty() && labels.size() != runs.size()) throw UsageError("give one --label per --runs (or none)");
    if (a.option("--threads") || a.option("--max-steps"))
      throw UsageError("--threads and --max-steps are for runs; compare --runs runs nothing");
    const std::filesystem::path out = a.option("--out").value_or("runs_compare");
    std::vector<std::filesystem::path> dirs(runs.begin(), runs.end());
    try {
      const auto report = dp::report_runs(out, dirs, labels);
      std::printf("report: %s\n", report.string().c_str());
    } catch (const dp::ConfigError& e) {
      print_diagnostics("compare --runs", e.diagnostics());
      std::fprintf(stderr, "no report was written.\n");
      return kExitRefused;
    }
    return 0;
  }
  if (a.positional.size() != 1) throw UsageError("compare expects one scenario file");
  if (varies.size() < 2) throw UsageError("compare needs at least two --vary variants");
  if (!labels.empty() && labels.size() != varies.size())
    throw UsageError("give one --label per --vary (or none)");
  if (a.flag("--quiet")) spdlog::set_level(spdlog::level::warn);
  opt.progress = !a.flag("--quiet");
  opt.scenario = a.positional[0];
  opt.output_directory = a.option("--out").value_or(std::filesystem::path(opt.scenario).stem().string() + "_compare");
  if (auto t = a.option("--threads")) opt.threads = parse_threads(*t);
  if (auto s = a.option("--max-steps")) opt.max_steps = static_cast<std::uint64_t>(parse_count("--max-steps", *s));
  dp::PluginRegistry registry;
  load_default_plugins(registry);
  try {
    for (std::size_t k = 0; k < varies.size(); ++k)
      opt.variants.push_back(dp::parse_variant(varies[k], labels.empty() ? "" : labels[k]));
    const auto report = dp::run_compare(opt, registry);
    std::printf("report: %s\n", report.string().c_str());
  } catch (const dp::ConfigError& e) {
    print_diagnostics(opt.scenario.string(), e.diagnostics());
    std::fprintf(stderr, "nothing was run.\n");
    return kExitRefused;
  }
  return 0;
}

int cmd_validate(int argc, char** argv) {
  const Args a = parse(argc, argv, 2, {}, {});
  if (a.positional.empty()) throw UsageError("validate expects at least one scenario file");
  dp::PluginRegistry registry;
  load_default_plugins(registry);
  int rc = 0;
  for (const auto& file : a.positional) {
    const auto diags = dp::validate_scenario_file(file, registry);
    if (diags.empty()) {
      std::printf("%s: valid\n", file.c_str());
    } else {
      print_diagnostics(file, diags);
      rc = kExitRefused;
    }
  }
  return rc;
}

int cmd_plugins(int argc, char** argv) {
  const Args a = parse(argc, argv, 2, {}, {"--json"});
  dp::PluginRegistry registry;
  load_default_plugins(registry);
  if (a.flag("--json")) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& m : registry.models()) {
      const auto& lib = registry.libraries()[m.library];
      out.push_back({{"name", m.name}, {"kind", dp::kind_name(m.desc.kind)}, {"version", m.version},
                     {"summary", m.summary}, {"history_slots", m.contact.history_slots},
                     {"library", lib.name}, {"library_version", lib.version}, {"path", lib.path.string()},
                     {"abi", std::to_string(lib.abi_major) + "." + std::to_string(lib.abi_minor)},
                     {"parameters", m.schema}});
    }
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  const nlohmann::json root = dp::composed_scenario_schema(registry);
  for (const auto& lib : registry.libraries()) {
    std::printf("library %s %s (ABI %u.%u) %s\n", lib.name.c_str(), lib.version.c_str(), lib.abi_major,
                lib.abi_minor, lib.path.string().c_str());
    for (const auto& m : registry.models()) {
      if (&registry.libraries()[m.library] != &lib) continue;
      std::printf("  %-10s %-14s %-7s %s\n", dp::kind_name(m.desc.kind), m.name.c_str(), m.version.c_str(),
                  m.summary.c_str());
      for (const auto& r : dp::parameter_rows(m.schema, root)) {
        std::string detail = r.type;
        if (!r.unit.empty()) detail += ", " + r.unit;
        if (!r.constraint.empty()) detail += ", " + r.constraint;
        if (r.required) detail += ", required";
        if (!r.default_value.empty()) detail += ", default " + r.default_value;
        std::printf("      %-18s %s — %s\n", r.name.c_str(), detail.c_str(), r.description.c_str());
      }
    }
  }
  if (registry.libraries().empty()) std::printf("no plugin libraries found\n");
  return 0;
}

int write_or_print(const Args& a, const std::string& text) {
  if (auto out = a.option("--out")) {
    domel::platform::io::write_file_atomically(*out, text);
  } else {
    std::fwrite(text.data(), 1, text.size(), stdout);
  }
  return 0;
}

int cmd_schema(int argc, char** argv) {
  const Args a = parse(argc, argv, 2, {"--out"}, {});
  dp::PluginRegistry registry;
  load_default_plugins(registry);
  return write_or_print(a, dp::composed_scenario_schema(registry).dump(2) + "\n");
}

int cmd_docs(int argc, char** argv) {
  const Args a = parse(argc, argv, 2, {"--out"}, {});
  dp::PluginRegistry registry;
  load_default_plugins(registry);
  return write_or_print(a, dp::scenario_reference_markdown(registry));
}

int dispatch(int argc, char** argv);

}  // namespace

int main(int argc, char** argv) {
  // A file size limit (ulimit -f, a batch system's quota) would end the
  // process with SIGXFSZ in the middle of a write; ignored, the write fails
  // with EFBIG and the run ends with the file's name and the last checkpoint.
  std::signal(SIGXFSZ, SIG_IGN);
  auto logger = spdlog::stderr_color_mt("domel");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%^[%l]%$ %v");
  // under mpirun a run is spread over the ranks; everything else is one process
  const bool spread = argc >= 2 && std::string(argv[1]) == "run" && dp::Communicator::launched_by_mpirun();
  dp::MpiSession mpi(&argc, &argv, spread);
  world() = dp::Communicator::world();
  if (world().rank() != 0) spdlog::set_level(spdlog::level::err);
  const int code = dispatch(argc, argv);
  // a failure on one rank ends every rank (the others may wait in a
  // collective). A scenario or a plugin refused on any rank was refused on
  // every rank together (agree_on_scenario): they end normally. A refusal
  // later (while the run is set up) is refused alike on every rank, and rank
  // 0 reports it: the others give it a second to do so before ending the run.
  // A run stopped by a signal stopped on every rank at the same macro step
  // and wrote its checkpoint together: the ranks end normally.
  const bool stopped = (code == 128 + SIGINT || code == 128 + SIGTERM) && !g_stopped_mid_step;
  if (code != 0 && world().size() > 1 && !stopped && !g_ranks_agreed) {
    if (code == kExitRefused && world().rank() != 0) {
      std::this_thread::sleep_for(std::chrono::seconds(1));
      // still here: rank 0 did not refuse the run, so the problem is this rank's own
      if (!g_deferred_problems.empty()) std::fputs(g_deferred_problems.c_str(), stderr);
    }
    world().abort(code);
  }
  return code;
}

namespace {

int dispatch(int argc, char** argv) {
  if (argc < 2) {
    std::fputs(kUsage, stderr);
    return kExitUsage;
  }
  const std::string cmd = argv[1];
  try {
    if (cmd == "run") return cmd_run(argc, argv);
    if (cmd == "validate") return cmd_validate(argc, argv);
    if (cmd == "compare") return cmd_compare(argc, argv);
    if (cmd == "plugins") return cmd_plugins(argc, argv);
    if (cmd == "schema") return cmd_schema(argc, argv);
    if (cmd == "docs") return cmd_docs(argc, argv);
    if (cmd == "version" || cmd == "--version") {
      std::printf("domel %s (SDK ABI %d.%d)\n", DOMEL_VERSION, DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR);
      return 0;
    }
    if (cmd == "help" || cmd == "--help" || cmd == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    const std::string hint = dp::suggest(cmd, {"run", "compare", "validate", "plugins", "schema", "docs", "version", "help"});
    throw UsageError("unknown command '" + cmd + "'" + (hint.empty() ? "" : " (" + hint + ")"));
  } catch (const UsageError& e) {
    std::fprintf(stderr, "domel: %s\n\n%s", e.what(), kUsage);
    return kExitUsage;
  } catch (const dp::ConfigError& e) {
    print_diagnostics("the input", e.diagnostics());
    return kExitRefused;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "domel: %s\n", e.what());
    return kExitRunFailed;
  }
}

}  // namespace
