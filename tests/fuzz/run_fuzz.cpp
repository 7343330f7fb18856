// SPDX-License-Identifier: MIT
// libFuzzer harness that runs what it is given (docs/reliability.md,
// "Run-time fuzzing"): each input is written as a scenario file and loaded
// the way `domel run` loads it (load_scenario: read, validate, build); an
// accepted scenario within the harness's ceilings (particles, sub-steps,
// fluid cells, and knobs that only cost time: see below) is then run for at
// most kMaxSteps macro steps on one thread, its files in a scratch folder,
// and the state after the run is checked:
//   - every particle's position, velocity and angular velocity finite, and
//     no two particles of a subdomain with one id;
//   - the mass books exact: per subdomain, inserted - removed == present,
//     in the particle flow's integer units (1e-18 kg), the counts alike, and
//     summary.json's balance marked exact; a run that nothing adds to or
//     removes from (no pour, deletion region or coupling) ends with the
//     particles, mass and ids it began with;
//   - no particle past a wall's surface unseen: a particle whose centre lies
//     beyond the surface of an active wall (WallClearance: the kernels' own
//     distances, the walls placed at the end time; fixed particles exempt)
//     must be in contact with that wall in the platform's last force
//     evaluation. Soft contacts overrun by speeds far above the time step's
//     impact_velocity do put particles there, with the contact acting (not a
//     finding, counted); one there without the contact is a missed contact.
// Outcomes that are not findings: a refusal (ConfigError, from the load or
// from run()), and a run stopped by the platform's own RuntimeError or
// PluginError (a blow-up it detected, a model that failed): clear messages,
// which are counted and kept, one line per kind, in run_errors_<pid>.txt for
// review. A finding aborts the process, so that libFuzzer keeps the input:
// any other exception escaping from load or run, a broken invariant, a crash,
// a sanitizer report, a hang (-timeout) or memory beyond -rss_limit_mb.
// The inputs are mutated as JSON documents (LLVMFuzzerCustomMutator below),
// mostly from inputs that ran. DOMEL_RUN_FUZZ_VERBOSE prints what became of
// each input.
#include "averaging/cell_grid.hpp"
#include "core/error.hpp"
#include "flow/particle_flow.hpp"
#include "geometry/wall_clearance.hpp"
#include "fuzz_support.hpp"
#include "loader/plugin_registry.hpp"
#include "loop/component.hpp"
#include "scenario/scenario.hpp"
#include "scheduler/simulation.hpp"

#include <sanitizer/lsan_interface.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

namespace dp = domel::platform;

namespace {

/// The most particles one insertion may place (set_particle_ceiling: a
/// larger one is refused at the build, as in a normal run), and the most an
/// accepted scenario may hold at the start to be run (state files and
/// several insertions can add up to more).
constexpr std::size_t kParticleCeiling = 300;
/// The run is stopped (not a finding) when pours or inflows grow it beyond this.
constexpr std::size_t kRunParticleCeiling = 1500;
/// Macro steps per run, at most.
constexpr std::uint64_t kMaxSteps = 200;
/// Particle-steps per input, at most: fewer macro steps when a level sub-cycles
/// many times per macro step; none when one macro step alone needs more.
constexpr double kStepBudget = 200.0 * 300.0;
/// A fluid: at most this many cells (a larger grid is not run), and this many
/// exchanges per run (fewer macro steps when the exchanges are frequent): a
/// fluid exchange costs more than a step of 300 particles.
constexpr double kFluidCells = 4096;
constexpr std::uint64_t kFluidExchanges = 10;
/// Wall time after which a run is stopped at the end of its macro step (not a
/// finding: the hangs are libFuzzer's -timeout, well above it).
constexpr double kWallSeconds = 3.0;

using domel::fuzz::registry;
using domel::fuzz::work_dir;

/// What happened to the inputs of this process (printed at exit and written
/// to run_stats_<pid>.txt in the work folder every 100 inputs).
struct Counts {
  std::uint64_t inputs = 0;
  std::uint64_t refused = 0;        ///< ConfigError from load_scenario
  std::uint64_t too_large = 0;      ///< not run: a cost knob, particles, sub-steps or fluid cells above the ceilings
  std::uint64_t stepped = 0;        ///< ran at least one macro step
  std::uint64_t completed = 0;      ///< run() returned; the invariants were checked
  std::uint64_t run_refused = 0;    ///< ConfigError from run() (checkpoints not possible, ...)
  std::uint64_t run_failed = 0;     ///< RuntimeError or PluginError from run()
  std::uint64_t cut = 0;            ///< stopped by the harness (particles or wall time)
  std::uint64_t past_wall = 0;      ///< completed with a particle past a wall's surface, its contact acting
  std::uint64_t macro_steps = 0;    ///< summed over the inputs
  std::uint64_t particle_steps = 0; ///< particles x macro steps, summed
  std::uint64_t load_ms = 0;        ///< wall time in load_scenario, summed
  std::uint64_t run_ms = 0;         ///< wall time in run() and the checks, summed
};
Counts g_counts;

std::string stats_line() {
  const Counts& c = g_counts;
  std::ostringstream os;
  os << "domel_run_fuzz: inputs " << c.inputs << " refused " << c.refused << " too_large " << c.too_large
     << " stepped " << c.stepped << " completed " << c.completed << " run_refused " << c.run_refused
     << " run_failed " << c.run_failed << " cut " << c.cut << " past_wall " << c.past_wall
     << " macro_steps " << c.macro_steps << " load_ms " << c.load_ms << " run_ms " << c.run_ms
     << " particle_steps " << c.particle_steps;
  return os.str();
}

void write_stats() {
  std::ofstream(work_dir() / ("run_stats_" + std::to_string(::getpid()) + ".txt"), std::ios::trunc)
      << stats_line() << "\n";
}

void print_stats_at_exit() {
  write_stats();
  std::fprintf(stderr, "%s\n", stats_line().c_str());
}

/// The kinds of run errors seen (numbers replaced by '#'), each written once
/// to run_errors_<pid>.txt, for review: an error message that betrays an
/// inconsistency rather than a bad scenario is a finding too.
void note_run_error(const char* kind, const std::string& what) {
  static std::set<std::string> seen;
  std::string key = std::string(kind) + ": ";
  for (std::size_t k = 0; k < what.size() && key.size() < 400;) {
    if (std::isdigit(static_cast<unsigned char>(what[k]))) {
      while (k < what.size() && (std::isdigit(static_cast<unsigned char>(what[k])) || what[k] == '.' ||
                                 what[k] == 'e' || what[k] == 'E' || what[k] == '+' || what[k] == '-'))
        ++k;
      key += '#';
    } else {
      key += what[k++];
    }
  }
  if (seen.size() >= 1000 || !seen.insert(key).second) return;
  std::ofstream(work_dir() / ("run_errors_" + std::to_string(::getpid()) + ".txt"), std::ios::app) << key << "\n";
}

/// Knobs that make a scenario slow to load or run, with the most the harness
/// runs: an input above one is not loaded (a jammed region with 10^9
/// insertion attempts per particle takes hours as the user asked; libFuzzer
/// would report it as a hang). Defaults: 1000, 1000, 16, 2000.
const std::vector<std::pair<std::string, double>>& cost_knobs() {
  static const std::vector<std::pair<std::string, double>> knobs = {{"max_attempts", 1e4},
                                                                    {"insertion_attempts", 1e4},
                                                                    {"max_substeps", 64},
                                                                    {"max_iterations", 1e4}};
  return knobs;
}

/// True when the document sets a cost knob above its limit, anywhere.
bool too_costly(const nlohmann::json& j) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      for (const auto& [key, most] : cost_knobs())
        if (it.key() == key && it->is_number() && !(it->get<double>() <= most)) return true;
      if (too_costly(*it)) return true;
    }
  } else if (j.is_array()) {
    for (const auto& e : j)
      if (too_costly(e)) return true;
  }
  return false;
}

/// Thrown by the harness's own component to stop a run that grew too large
/// or too slow; not a std::exception, so nothing in the platform catches it.
struct StopRun {};

/// DOMEL_RUN_FUZZ_VERBOSE set: one line per input on stderr (what became of
/// it), for checking seeds and tuning the ceilings.
bool verbose() {
  static const bool v = std::getenv("DOMEL_RUN_FUZZ_VERBOSE") != nullptr;
  return v;
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "domel_run_fuzz: invariant broken: %s\n", what.c_str());
  std::abort();
}

/// One subdomain before the run: its particles, mass and ids.
struct Before {
  std::size_t count = 0;
  dp::MassUnits mass = 0;
  std::vector<std::uint64_t> ids;
};

Before take_before(const dp::Subdomain& sd) {
  Before b;
  const dp::ParticleStore& s = sd.store();
  b.count = sd.owned();
  for (std::size_t q = 0; q < b.count; ++q) {
    b.mass += dp::mass_units(s.mass[q]);
    b.ids.push_back(s.id[q]);
  }
  std::sort(b.ids.begin(), b.ids.end());
  return b;
}

/// The harness's own component: counts the macro steps and the particles
/// stepped, stops a run grown beyond kRunParticleCeiling particles or
/// kWallSeconds (StopRun), and has every subdomain record its contacts in
/// its last step, so that the wall invariant can ask which wall contacts the
/// platform's last force evaluation computed.
class RunWatch final : public dp::Component {
 public:
  std::uint64_t steps = 0;

  unsigned points() const override { return kBeforeSteps | kStep | kAfterMacro; }
  void setup(dp::RunContext& ctx) override {
    stop_ = ctx.stop;
    t0_ = std::chrono::steady_clock::now();
  }
  void before_steps(dp::RunContext&, const dp::MacroStep& step) override { index_ = step.index; }
  bool records_contacts(std::size_t, bool last) const override { return last && index_ + 1 == stop_; }
  void after_macro(dp::RunContext& ctx, const dp::MacroStep&) override {
    ++steps;
    std::size_t n = 0;
    for (const auto& sd : ctx.subdomains) n += sd->size();
    g_counts.particle_steps += n;
    if (n > kRunParticleCeiling ||
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count() > kWallSeconds)
      throw StopRun{};
  }

 private:
  std::uint64_t stop_ = 0, index_ = 0;
  std::chrono::steady_clock::time_point t0_;
};

/// The wall invariant on subdomain sd at the end of its run: an owned, not
/// fixed particle whose centre is past the surface of an active wall
/// (WallClearance's overlap, the kernels' own distances, above the radius;
/// the walls placed at the end time) must be in contact with that wall in
/// the platform's last force evaluation (its contact records). Returns how
/// many particles were past a wall with the contact acting (a soft contact
/// overrun by a speed the time step was not made for: not a finding); a
/// particle past a wall without the contact is a finding.
std::size_t check_walls(dp::Subdomain& sd) {
  const auto& walls = sd.reference_walls();
  const dp::ParticleStore& s = sd.store();
  if (walls.empty() || sd.owned() == 0) return 0;
  std::set<std::pair<std::uint32_t, std::uint32_t>> touching;  // (particle index, wall primitive)
  for (const auto* list : sd.contact_records())
    for (const dp::ContactRecord& c : *list)
      if (c.j == dp::ContactRecord::kWall) touching.insert({c.i, c.wall});
  double r_max = 0;
  for (std::size_t q = 0; q < sd.owned(); ++q) r_max = std::max(r_max, s.radius[q]);
  const double t = sd.time();
  const dp::WallClearance clearance(walls, t, r_max);
  std::size_t acting = 0;
  for (std::size_t q = 0; q < sd.owned(); ++q) {
    if (s.fixed(q)) continue;  // walls leave fixed particles out
    const double p[3] = {s.x[q], s.y[q], s.z[q]};
    std::size_t w = 0;
    const double overlap = clearance.overlap(p, s.radius[q], &w);
    if (!(overlap > s.radius[q])) continue;
    if (touching.count({static_cast<std::uint32_t>(q), static_cast<std::uint32_t>(w)})) {
      ++acting;
      continue;
    }
    std::ostringstream os;
    os.precision(9);
    os << "subdomain '" << sd.name() << "': particle id " << s.id[q] << " (radius " << s.radius[q] << " m) at ("
       << s.x[q] << ", " << s.y[q] << ", " << s.z[q] << ") m, v = (" << s.vx[q] << ", " << s.vy[q] << ", " << s.vz[q]
       << ") m/s, is " << overlap << " m into wall primitive '" << walls[w].name << "' at t = " << t
       << " s (its centre past the surface), and the last force evaluation has no contact of it with that wall";
    finding(os.str());
  }
  return acting;
}

std::string units(dp::MassUnits u) {
  // a 128-bit integer in decimal
  const bool neg = u < 0;
  unsigned __int128 v = neg ? static_cast<unsigned __int128>(-(u + 1)) + 1 : static_cast<unsigned __int128>(u);
  std::string d;
  do {
    d.insert(d.begin(), static_cast<char>('0' + static_cast<int>(v % 10)));
    v /= 10;
  } while (v != 0);
  return (neg ? "-" : "") + d;
}

/// The invariants after a run that returned (see the file's comment).
void check_after(dp::Simulation& sim, const std::vector<Before>& before, const dp::RunResult& result) {
  const bool closed = sim.flow.pours.empty() && sim.flow.deletions.empty() && sim.couplings.empty();
  const auto& accounts = sim.flow.accounts();
  if (accounts.size() != sim.subdomains.size())
    finding("the particle flow keeps books of " + std::to_string(accounts.size()) + " subdomain(s), the run has " +
            std::to_string(sim.subdomains.size()));
  for (std::size_t k = 0; k < sim.subdomains.size(); ++k) {
    dp::Subdomain& sd = *sim.subdomains[k];
    const dp::ParticleStore& s = sd.store();
    const std::size_t n = sd.owned();
    // finite state
    for (std::size_t q = 0; q < n; ++q) {
      const double v[9] = {s.x[q], s.y[q], s.z[q], s.vx[q], s.vy[q], s.vz[q], s.wx[q], s.wy[q], s.wz[q]};
      for (double x : v)
        if (!std::isfinite(x))
          finding("subdomain '" + sd.name() + "': particle id " + std::to_string(s.id[q]) +
                  " has a non-finite position, velocity or angular velocity after a run that returned");
    }
    // unique ids
    std::vector<std::uint64_t> ids(s.id.begin(), s.id.begin() + static_cast<std::ptrdiff_t>(n));
    std::sort(ids.begin(), ids.end());
    if (std::adjacent_find(ids.begin(), ids.end()) != ids.end())
      finding("subdomain '" + sd.name() + "': two particles share an id");
    // the books: inserted - removed == present, exactly
    dp::MassUnits present = 0;
    for (std::size_t q = 0; q < n; ++q) present += dp::mass_units(s.mass[q]);
    const dp::MassAccount& a = accounts[k];
    if (a.inserted - a.removed != present)
      finding("subdomain '" + sd.name() + "': mass books do not close: inserted " + units(a.inserted) +
              " - removed " + units(a.removed) + " != present " + units(present) + " (units of 1e-18 kg)");
    if (a.n_inserted < a.n_removed || a.n_inserted - a.n_removed != n)
      finding("subdomain '" + sd.name() + "': particle books do not close: inserted " + std::to_string(a.n_inserted) +
              " - removed " + std::to_string(a.n_removed) + " != present " + std::to_string(n));
    // the summary's books say the same
    const auto& mb = result.summary.contains("mass_balance") ? result.summary["mass_balance"] : nlohmann::json();
    if (mb.is_object() && mb.contains(sd.name()) && !(mb[sd.name()]["exact"] == true))
      finding("subdomain '" + sd.name() + "': summary.json's mass balance is not exact: " + mb[sd.name()].dump());
    // nothing added or removed: the same particles
    if (closed && (n != before[k].count || present != before[k].mass || ids != before[k].ids))
      finding("subdomain '" + sd.name() + "': nothing adds or removes particles, yet " +
              std::to_string(before[k].count) + " particles of " + units(before[k].mass) + " units became " +
              std::to_string(n) + " of " + units(present) + (ids != before[k].ids ? " (other ids)" : ""));
    // walls
    if (check_walls(sd) > 0) ++g_counts.past_wall;
  }
}


// ---------------------------------------------------------------------------
// Structure-aware mutation. Byte mutations of a JSON scenario are refused by
// the reader or the schema in all but about 2 inputs in 1000 (a trial of
// 40,000 executions), so the harness mutates the parsed document instead:
// one value changed (a number scaled, negated, set to an edge value or
// nudged; an integer stepped; a boolean flipped; a string replaced by another
// of the document's or of the schema's names), an array element removed,
// duplicated or swapped, an object member removed, or a subtree replaced by
// another of the same type from the document; and crossover replaces a
// subtree by the one at the same place in another input. One mutation in
// five is libFuzzer's own byte mutation, so the reader and the validator
// keep being fuzzed; an input that is not JSON gets only those.

/// The inputs this process found refused (or too large to run), by hash, and
/// the last 256 inputs it ran: the mutator starts 9 in 10 mutations of a
/// refused input from one of those instead, so that the campaign keeps
/// running scenarios although most inputs that add coverage are refusals
/// (new diagnostics) and fill libFuzzer's corpus (this libFuzzer, LLVM 14,
/// has no way for the target to keep an input out of the corpus). Both are
/// allocated once: an input that allocates more than it frees makes
/// libFuzzer run it again and scan the heap for leaks (-detect_leaks), which
/// tripled the time per input.
constexpr std::size_t kRefusedBits = std::size_t{1} << 26;  // a bit per hash value: 8 MB
constexpr std::size_t kRanPool = 256;
constexpr std::size_t kMaxInput = 16384;  // bench/fuzz_scenarios.py's -max_len
std::vector<std::uint64_t> g_refused;
std::vector<std::string> g_ran;
std::size_t g_ran_count = 0, g_ran_next = 0;

void make_pools() {
  g_refused.assign(kRefusedBits / 64, 0);
  g_ran.resize(kRanPool);
  for (auto& r : g_ran) r.reserve(kMaxInput);
}

std::size_t input_hash(const std::uint8_t* data, std::size_t size) {
  return std::hash<std::string_view>()(std::string_view(reinterpret_cast<const char*>(data), size)) % kRefusedBits;
}

void note_refused(const std::uint8_t* data, std::size_t size) {
  const std::size_t h = input_hash(data, size);
  g_refused[h / 64] |= std::uint64_t{1} << (h % 64);
}

bool was_refused(const std::uint8_t* data, std::size_t size) {
  const std::size_t h = input_hash(data, size);
  return (g_refused[h / 64] >> (h % 64)) & 1u;
}

void note_ran(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInput) return;
  g_ran[g_ran_next].assign(reinterpret_cast<const char*>(data), size);  // within its capacity: no allocation
  g_ran_next = (g_ran_next + 1) % kRanPool;
  g_ran_count = std::min(g_ran_count + 1, kRanPool);
}

/// Every node of the document, as pointers from the root (the root excluded).
void collect(const nlohmann::json& j, const nlohmann::json::json_pointer& at,
             std::vector<nlohmann::json::json_pointer>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      out.push_back(at / it.key());
      collect(*it, at / it.key(), out);
    }
  } else if (j.is_array()) {
    for (std::size_t k = 0; k < j.size(); ++k) {
      out.push_back(at / k);
      collect(j[k], at / k, out);
    }
  }
}

/// Strings a mutation may put in place of another: the schema's enumerations
/// and the built-in models' names (the document's own strings are added).
const std::vector<std::string>& name_pool() {
  static const std::vector<std::string> names = {
      "x", "y", "z", "xmin", "xmax", "ymin", "ymax", "zmin", "zmax", "-x", "+x", "-y", "+y", "-z", "+z",
      "plane", "box", "cylinder", "cone", "disk", "mesh", "hertz", "linear", "restitution", "mindlin",
      "sd_critical_angle", "dct", "epsd", "none", "random", "lattice", "vans", "stress_pi", "velocity_p",
      "auto", "uniform", "normal", "lognormal", "table", "mixture", "mass", "volume", "number", "planar",
      "conical", "wall", "slip_wall", "velocity_inlet", "pressure_outlet", "schiller_naumann", "di_felice",
      "gidaspow", "beetstra", "cg", "pfmg", "two_way", "one_way", "simple_cubic", "chute.stl", "run_state.csv",
      "state_in_wall.csv", "", "a/../../b"};
  return names;
}

double pick_double(std::minstd_rand& rng, double v) {
  static const double edges[] = {0.0, 1.0, -1.0, 1e-12, 1e-6, 1e-3, 1e3, 1e6, 1e12, 1e300, -1e300, 5e-324};
  switch (rng() % 6) {
    case 0: {
      static const double factors[] = {0.5, 2.0, 0.1, 10.0, -1.0, 0.999, 1.001, 1e3, 1e-3, 0.0};
      return v * factors[rng() % (sizeof(factors) / sizeof(factors[0]))];
    }
    case 1: return edges[rng() % (sizeof(edges) / sizeof(edges[0]))];
    case 2: return v * (0.9 + 0.2 * static_cast<double>(rng() % 1001) / 1000.0);
    case 3: return v + (static_cast<double>(rng() % 2001) / 1000.0 - 1.0) * (v == 0.0 ? 0.01 : std::fabs(v));
    case 4: return std::round(v);
    default: return v * 1.5;
  }
}

void mutate_value(nlohmann::json& doc, nlohmann::json& v, const std::vector<nlohmann::json::json_pointer>& all,
                  std::minstd_rand& rng) {
  using json = nlohmann::json;
  if (rng() % 8 == 0) {  // a subtree of the same type from elsewhere in the document
    for (int tries = 0; tries < 8; ++tries) {
      const json& other = doc.at(all[rng() % all.size()]);
      if (other.type() == v.type() && &other != &v) {
        json copy = other;
        v = std::move(copy);
        return;
      }
    }
  }
  switch (v.type()) {
    case json::value_t::number_float: v = pick_double(rng, v.get<double>()); return;
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: {
      const long long n = v.is_number_unsigned() ? static_cast<long long>(std::min<std::uint64_t>(
                                                       v.get<std::uint64_t>(), 1ULL << 62))
                                                 : v.get<long long>();
      static const long long edges[] = {0, 1, -1, 2, 3, 1000, 1LL << 31, 4294967296LL, 1000000000000LL};
      switch (rng() % 6) {
        case 0: v = n + 1; return;
        case 1: v = n - 1; return;
        case 2: v = n * 2; return;
        case 3: v = n / 2; return;
        case 4: v = edges[rng() % (sizeof(edges) / sizeof(edges[0]))]; return;
        default: v = pick_double(rng, static_cast<double>(n)); return;  // a fraction where an integer belongs
      }
    }
    case json::value_t::boolean: v = !v.get<bool>(); return;
    case json::value_t::string: {
      std::vector<std::string> pool = name_pool();
      for (const auto& p : all)
        if (doc.at(p).is_string()) pool.push_back(doc.at(p).get<std::string>());
      v = pool[rng() % pool.size()];
      return;
    }
    case json::value_t::array:
      if (v.empty()) return;
      switch (rng() % 3) {
        case 0: v.erase(v.begin() + static_cast<std::ptrdiff_t>(rng() % v.size())); return;
        case 1: {
          json copy = v[rng() % v.size()];
          v.push_back(std::move(copy));
          return;
        }
        default: std::swap(v[rng() % v.size()], v[rng() % v.size()]); return;
      }
    case json::value_t::object:
      if (v.empty()) return;
      {
        auto it = v.begin();
        std::advance(it, static_cast<std::ptrdiff_t>(rng() % v.size()));
        v.erase(it);
      }
      return;
    default: return;
  }
}

std::size_t write_out(const nlohmann::json& doc, std::uint8_t* data, std::size_t max_size) {
  const std::string text = doc.dump();
  if (text.size() > max_size) return 0;
  std::copy(text.begin(), text.end(), data);
  return text.size();
}

nlohmann::json parse_or_discard(const std::uint8_t* data, std::size_t size) {
  return nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
}

}  // namespace

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  std::minstd_rand rng(seed);
  if (rng() % 5 == 0) return LLVMFuzzerMutate(data, size, max_size);
  if (g_ran_count > 0 && rng() % 10 != 0 && was_refused(data, size)) {
    const std::string& base = g_ran[rng() % g_ran_count];
    if (base.size() <= max_size) {
      std::copy(base.begin(), base.end(), data);
      size = base.size();
    }
  }
  try {
    nlohmann::json doc = parse_or_discard(data, size);
    if (doc.is_discarded() || !doc.is_object()) return LLVMFuzzerMutate(data, size, max_size);
    const int n = 1 + static_cast<int>(rng() % 3 == 0) + static_cast<int>(rng() % 9 == 0);  // mostly one change
    for (int k = 0; k < n; ++k) {
      std::vector<nlohmann::json::json_pointer> all;
      collect(doc, nlohmann::json::json_pointer(), all);
      if (all.empty()) break;
      mutate_value(doc, doc.at(all[rng() % all.size()]), all, rng);
    }
    const std::size_t written = write_out(doc, data, max_size);
    if (written) return written;
  } catch (const std::exception&) {
    // a pointer the document no longer holds: fall back to a byte mutation
  }
  return LLVMFuzzerMutate(data, size, max_size);
}

extern "C" std::size_t LLVMFuzzerCustomCrossOver(const std::uint8_t* data1, std::size_t size1,
                                                 const std::uint8_t* data2, std::size_t size2, std::uint8_t* out,
                                                 std::size_t max_out_size, unsigned int seed) {
  std::minstd_rand rng(seed);
  try {
    nlohmann::json a = parse_or_discard(data1, size1), b = parse_or_discard(data2, size2);
    if (a.is_discarded() || b.is_discarded() || !a.is_object() || !b.is_object()) return 0;
    std::vector<nlohmann::json::json_pointer> all;
    collect(a, nlohmann::json::json_pointer(), all);
    for (int tries = 0; tries < 16 && !all.empty(); ++tries) {
      const auto& at = all[rng() % all.size()];
      if (!b.contains(at) || b.at(at) == a.at(at)) continue;
      a.at(at) = b.at(at);
      return write_out(a, out, max_out_size);
    }
  } catch (const std::exception&) {
  }
  return 0;  // no crossover this time
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::off);  // 10^5 inputs: no log lines
  dp::set_particle_ceiling(kParticleCeiling);
  // OpenMPI (initialised by hypre at the first fluid solve) would install its
  // own handlers for SIGABRT and SIGSEGV, ahead of libFuzzer's, and a
  // finding would end the process without its input written out
  ::setenv("OMPI_MCA_opal_signal", "", 1);
  registry();
  make_pools();
  work_dir();  // made before the exit handler is registered, so destroyed after it ran
  std::atexit(print_stats_at_exit);
  // A warm-up run of the fluid seed, its allocations exempt from the leak
  // checks: the first fluid solve initialises OpenMPI (through hypre), whose
  // one-time allocations, some made in components it unloads again, would
  // otherwise be reported as leaks of whichever input first runs a fluid.
  {
    __lsan::ScopedDisabler no_leak_checks;
    try {
      auto sim = dp::load_scenario(std::filesystem::path(DOMEL_FUZZ_SEED_DIR) / "run_fluid.json", registry());
      dp::RunOptions opt;
      opt.output_directory = work_dir() / ("warm_up_" + std::to_string(::getpid()));
      opt.threads = 1;
      opt.progress = false;
      opt.checkpoint_on_signal = false;
      opt.max_steps = 5;
      sim->run(opt, registry());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "domel_run_fuzz: the warm-up run of run_fluid.json failed: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string pid = std::to_string(::getpid());
  const std::filesystem::path file = work_dir() / ("input_" + pid + ".json");
  const std::filesystem::path out = work_dir() / ("out_" + pid);
  {
    std::ofstream f(file, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  if (++g_counts.inputs % 100 == 0) write_stats();
  {
    const auto doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
    if (!doc.is_discarded() && too_costly(doc)) {
      ++g_counts.too_large;
      note_refused(data, size);
      return 0;
    }
  }
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t) {
    return static_cast<std::uint64_t>(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
  };
  const auto load_start = Clock::now();
  std::unique_ptr<dp::Simulation> sim;
  try {
    sim = dp::load_scenario(file, registry());
  } catch (const dp::ConfigError& e) {
    g_counts.load_ms += ms_since(load_start);
    ++g_counts.refused;
    if (verbose())
      for (const auto& d : e.diagnostics()) std::fprintf(stderr, "refused: %s\n", d.format().c_str());
    note_refused(data, size);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "load_scenario threw other than ConfigError: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "load_scenario threw a non-standard exception\n");
    std::abort();
  }

  g_counts.load_ms += ms_since(load_start);

  // The work of one macro step: each level's particles times its sub-steps.
  std::size_t particles = 0;
  double per_macro = 0;
  const double macro = sim->macro_step();
  for (const auto& sd : sim->subdomains) {
    particles += sd->owned();
    const double sub = sd->time_step() > 0 ? std::ceil(macro / sd->time_step() - 1e-9) : 1.0;
    per_macro += std::max(sub, 1.0) * static_cast<double>(std::max<std::size_t>(sd->owned(), 1));
  }
  double fluid_cells = 0;
  if (sim->fluid) {
    fluid_cells = 1;
    for (const auto& n : sim->document["fluid"]["grid"]["cells"]) fluid_cells *= n.get<double>();
  }
  if (particles > kParticleCeiling || !(per_macro <= kStepBudget) || fluid_cells > kFluidCells) {
    ++g_counts.too_large;
    if (verbose()) std::fprintf(stderr, "not run: %zu particles, %.3g particle-steps per macro step\n", particles, per_macro);
    note_refused(data, size);
    return 0;
  }
  dp::RunOptions opt;
  opt.output_directory = out;
  opt.threads = 1;
  opt.progress = false;
  opt.checkpoint_on_signal = false;
  opt.max_steps = std::min<std::uint64_t>(kMaxSteps, static_cast<std::uint64_t>(kStepBudget / per_macro));
  if (sim->fluid) opt.max_steps = std::min(opt.max_steps, kFluidExchanges * sim->fluid->spec().interval_macro);

  std::vector<Before> before;
  for (const auto& sd : sim->subdomains) before.push_back(take_before(*sd));

  auto& watch = sim->add(std::make_unique<RunWatch>());
  const auto t0 = Clock::now();

  std::error_code ec;
  std::filesystem::remove_all(out, ec);
  std::filesystem::create_directories(out, ec);
  dp::RunResult result;
  bool returned = false;
  try {
    result = sim->run(opt, registry());
    returned = true;
  } catch (const StopRun&) {
    ++g_counts.cut;
  } catch (const dp::ConfigError& e) {
    ++g_counts.run_refused;
    note_run_error("ConfigError", e.what());
    for (const auto& d : e.diagnostics()) note_run_error("ConfigError", d.format());
    if (verbose()) std::fprintf(stderr, "run refused: %s\n", e.what());
  } catch (const dp::RuntimeError& e) {
    ++g_counts.run_failed;
    note_run_error("RuntimeError", e.what());
    if (verbose()) std::fprintf(stderr, "RuntimeError: %s\n", e.what());
  } catch (const dp::PluginError& e) {
    ++g_counts.run_failed;
    note_run_error("PluginError", e.what());
    if (verbose()) std::fprintf(stderr, "PluginError: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "run() threw other than ConfigError, RuntimeError or PluginError: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "run() threw a non-standard exception\n");
    std::abort();
  }
  if (verbose())
    std::fprintf(stderr, "%s: %llu of %llu macro steps, %zu particles at the start, %.3g s\n",
                 returned ? "ran" : "stopped", static_cast<unsigned long long>(watch.steps),
                 static_cast<unsigned long long>(opt.max_steps), particles,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  g_counts.macro_steps += watch.steps;
  if (watch.steps > 0) {
    ++g_counts.stepped;
    note_ran(data, size);
  }
  if (returned) {
    ++g_counts.completed;
    check_after(*sim, before, result);
  }
  g_counts.run_ms += ms_since(t0);
  return 0;
}
