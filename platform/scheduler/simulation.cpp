// SPDX-License-Identifier: MIT
// The run loop: for every macro step, the points at which the components act
// (loop/component.hpp) around the levels' sub-steps, checkpoints and
// progress. Its preparation and the summary are in run_setup.cpp.
#include "scheduler/simulation.hpp"

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/atomic_file.hpp"
#include "io/output_folder.hpp"
#include "scheduler/checkpoint.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <optional>
#include <unistd.h>

namespace domel::platform {

double Simulation::macro_step() const { return macro_step_of(subdomains); }

CheckpointWorld Simulation::world() {
  nlohmann::json stateful = nlohmann::json::object();
  auto entry = [](const ModelInstance& m) {
    return nlohmann::json{{"model", m.model().name}, {"version", m.model().version}, {"library", m.model().library_name}};
  };
  for (const auto& c : couplings) {
    if (c->spec().stress.enabled) stateful["coupling '" + c->spec().name + "', stress_control"] = entry(*c->spec().stress.model);
    if (c->spec().velocity.enabled)
      stateful["coupling '" + c->spec().name + "', velocity_control"] = entry(*c->spec().velocity.model);
  }
  if (fluid) stateful["fluid"] = entry(*fluid->spec().model);
  return CheckpointWorld{name, scenario_file, document, models_used, stateful, subdomains, servos, flow};
}

std::string Simulation::why_no_checkpoint() const {
  const ModelInstance* stateless = nullptr;
  for (const auto& c : couplings)
    for (const ControllerSetup* cs : {&c->spec().stress, &c->spec().velocity})
      if (!stateless && cs->enabled && !cs->model->has_state()) stateless = cs->model.get();
  if (!stateless && fluid && !fluid->spec().model->has_state()) stateless = fluid->spec().model.get();
  if (!stateless) return "";
  return stateless->context() + " cannot save its state (its library lacks ABI 2.3's save_state and load_state, "
                                "docs/sdk-guide.md), so this run cannot be checkpointed";
}

namespace {

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.0f s", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%.0f min %02.0f s", std::floor(s / 60), std::fmod(s, 60));
  else std::snprintf(buf, sizeof buf, "%.0f h %02.0f min", std::floor(s / 3600), std::fmod(s / 60, 60));
  return buf;
}

/// The progress line on stderr: every second on a terminal, every 10 s otherwise.
struct Progress {
  bool on;
  double macro;
  std::uint64_t stop;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last = start;
  bool tty = isatty(fileno(stderr));

  void report(std::uint64_t m, double particle_steps) {
    const auto now = std::chrono::steady_clock::now();
    if (!on || std::chrono::duration<double>(now - last).count() < (tty ? 1.0 : 10.0)) return;
    last = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    const double rate = static_cast<double>(m + 1) / elapsed;
    const double eta = static_cast<double>(stop - m - 1) / rate;
    std::fprintf(stderr, "%s[domel] t = %.4g / %.4g s (%3.0f%%) | %.0f steps/s | %.3g particle-steps/s | ETA %s%s",
                 tty ? "\r" : "", static_cast<double>(m + 1) * macro, static_cast<double>(stop) * macro,
                 100.0 * static_cast<double>(m + 1) / static_cast<double>(stop), rate, particle_steps / elapsed,
                 format_seconds(eta).c_str(), tty ? "   " : "\n");
    std::fflush(stderr);
  }
};

/// The components registered for one point of the loop, in registration order.
std::vector<Component*> at_point(const std::vector<Component*>& all, Component::Point p) {
  std::vector<Component*> out;
  for (Component* c : all)
    if (c->points() & p) out.push_back(c);
  return out;
}

/// One step of subdomain k (`last`: its last sub-step of the macro step):
/// its contacts recorded when a grid samples it or a component asks, then
/// the due grids sampled (on ranks: per-cell sums reduced over the ranks),
/// then the components' after_step.
void step_level(RunContext& ctx, std::size_t k, bool last, const std::vector<Component*>& at_step) {
  Subdomain& sd = *ctx.subdomains[k];
  bool record = false;
  for (const Component* c : at_step) record = record || c->records_contacts(k, last);
  for (const auto& s : ctx.samplers()) record = record || (s.subdomain == k && s.grid->due(sd.steps() + 1));
  sd.set_record_contacts(record);
  sd.step_deferred();  // finished by the next step or by the first observer (store(), stats())
  if (record) {
    const CellGrid::RankReduction reduce = [&](std::vector<double>& sums, std::vector<double>& maxima) {
      ctx.ranks.reduce_in_rank_order(sums, maxima);
    };
    for (const auto& s : ctx.samplers()) {
      if (s.subdomain != k || !s.grid->due(sd.steps())) continue;
      const auto t0 = std::chrono::steady_clock::now();
      s.grid->sample(sd.store(), sd.owned(), sd.contact_records(), sd.time(), reduce);
      if (s.seconds) *s.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  for (Component* c : at_step) c->after_step(ctx, k, last);
  if (record) sd.set_record_contacts(false);
}

}  // namespace

RunResult Simulation::run(const RunOptions& options, const PluginRegistry& registry) {
  RunResult result;
  // Spread over ranks: every rank runs this function on the same scenario;
  // rank 0 alone writes files and reports (loop/ranks.hpp).
  RunRanks& ranks = *options.ranks;
  const bool writer = ranks.rank() == 0;
  const std::vector<RankGroup> groups = rank_groups_checked(ranks);
  const std::filesystem::path out = options.output_directory.empty() ? output_directory : options.output_directory;
  result.output_directory = out;
  // A restart is checked against this scenario before anything is written.
  const std::string why_not = why_no_checkpoint();
  const bool checkpoints_possible = why_not.empty();
  std::optional<OpenedCheckpoint> ck;
  if (!options.restart.empty()) {
    if (!checkpoints_possible) throw ConfigError({Diagnostic{scenario_file.string(), "", "cannot restart: " + why_not, ""}});
    ck = open_checkpoint(options.restart, world());
    last_checkpoint_ = CheckpointMark{options.restart, ck->loop.time};
    for (const auto& c : ck->allowed_changes) spdlog::info("restart: scenario changed, allowed: {}", c);
  }
  if (checkpoint_interval > 0 && !checkpoints_possible)
    throw ConfigError({Diagnostic{scenario_file.string(), "/run/checkpoint_interval",
                                  why_not + "; remove run.checkpoint_interval", ""}});
  std::optional<io::ManifestScope> manifest;  // lists every file written below (io/output_folder.hpp)
  if (writer) {
    std::filesystem::create_directories(out);
    manifest.emplace(out);
  }
  const int threads_n = options.threads > 0 ? options.threads : (threads > 0 ? threads : default_thread_count());
  const double macro = macro_step();
  const std::vector<int> substeps = prepare_levels(ranks, groups, threads_n, writer);
  const auto total_macro = static_cast<std::uint64_t>(std::ceil(duration / macro - kTimeTolerance));
  const std::uint64_t stop = options.max_steps ? std::min(options.max_steps, total_macro) : total_macro;
  const std::uint64_t first = ck ? ck->loop.macro_index : 0;
  if (first > stop)
    throw ConfigError({Diagnostic{scenario_file.string(), "/run",
                                  "the checkpoint " + options.restart.string() + " is at t = " +
                                      std::to_string(static_cast<double>(first) * macro) +
                                      " s, after the end of this run (" + std::to_string(stop * macro) +
                                      " s); lengthen run.duration", ""}});

  // Set-up: components before and after the levels' own (or the world restored), then their checkpoint sections.
  RunContext ctx(subdomains, walls, out, ranks, macro, first, stop, ck.has_value());
  for (Component* c : components) c->init(ctx);
  if (ck) restore_world(*ck, ranks, threads_n, writer);
  else for (auto& sd : subdomains) sd->setup();
  for (Component* c : components) c->setup(ctx);
  if (ck)
    for (Component* c : components)
      if (!c->section().empty()) c->load(ctx, *ck->archive, c->section());
  Cadence checkpoints = Cadence::in_time(checkpoint_interval, checkpoint_interval, macro);
  if (ck) checkpoints.resume(ck->loop.checkpoints);
  auto save_checkpoint = [&](std::uint64_t at) {
    const auto t0 = std::chrono::steady_clock::now();
    const LoopState ls{at, static_cast<double>(at) * macro, checkpoints.index(), threads_n, 1};
    CheckpointWorld w0 = world();
    write_checkpoint(out / kCheckpointFile, w0, ls, registry, [&](ArchiveWriter& w) {
      for (Component* c : components)
        if (!c->section().empty()) c->save(w, c->section());
    }, ranks);
    last_checkpoint_ = CheckpointMark{out / kCheckpointFile, ls.time};
    spdlog::debug("checkpoint at t = {:.6g} s written in {:.3g} s", ls.time,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  };
  std::size_t particles = 0;
  for (const auto& sd : subdomains) particles += sd->owned();
  particles = ranks.sum_count(particles);
  if (writer)
    spdlog::info("running '{}': {} particles in {} subdomain(s), {:.6g} s simulated in {} macro steps of {:.4g} s, "
                 "{} thread(s){} -> {}",
                 name, particles, subdomains.size(), duration, total_macro, macro, threads_n,
                 ranks.on_each(), out.string());

  // The loop.
  const auto before_macro = at_point(components, Component::kBeforeMacro);
  const auto outputs = at_point(components, Component::kOutput);
  const auto before_steps = at_point(components, Component::kBeforeSteps);
  const auto at_step = at_point(components, Component::kStep);
  const auto after_macro = at_point(components, Component::kAfterMacro);
  MacroStep step;  // what the components see, updated in place
  step.macro = macro;
  step.subdomains = &subdomains;
  Progress progress{writer && options.progress, macro, stop};
  double particle_steps = 0, window_particle_steps = 0;
  auto window_start = progress.start;
  std::uint64_t m = first;
  for (;; ++m) {
    // at the start of a macro step, before its components: a restart
    // begins here, and the last one is at the end of the run
    if (m > first && checkpoints_possible && (checkpoints.take(m) || (m == stop && checkpoint_interval > 0)))
      save_checkpoint(m);
    result.interrupted_by = m < stop ? interrupt_requested() : 0;
    if (m < stop && ranks.sum_count(static_cast<std::size_t>(result.interrupted_by)) != 0 &&
        result.interrupted_by == 0)
      result.interrupted_by = SIGTERM;  // every rank stops at the same macro step: the first signal any rank saw
    if (result.interrupted_by != 0) {
      // a signal: the last step is complete; the checkpoint holds it, and
      // probes.csv and the other files end where the checkpoint does
      if (options.checkpoint_on_signal && checkpoints_possible) save_checkpoint(m);
      else if (options.checkpoint_on_signal) spdlog::warn("no checkpoint: {}", why_not);
      break;
    }
    step.t = static_cast<double>(m) * macro;
    step.index = m;
    step.last = m == stop;
    if (!step.last)
      for (Component* c : before_macro) c->before_macro(ctx, step);
    for (Component* c : outputs) c->output(ctx, step);
    if (step.last) break;
    if (options.time_after && m == options.time_after) window_start = std::chrono::steady_clock::now();
    for (Component* c : before_steps) c->before_steps(ctx, step);
    for (std::size_t k = 0; k < subdomains.size(); ++k) {
      for (int s = 0; s < substeps[k]; ++s) step_level(ctx, k, s == substeps[k] - 1, at_step);
      const double ps = static_cast<double>(substeps[k]) * static_cast<double>(subdomains[k]->owned());
      particle_steps += ps;
      if (options.time_after && m >= options.time_after) window_particle_steps += ps;
    }
    step.t = static_cast<double>(m + 1) * macro;
    for (Component* c : after_macro) c->after_macro(ctx, step);
    progress.report(m, particle_steps);
  }
  for (auto& sd : subdomains) sd->synchronize();  // the last step's pending half kick, inside the timing
  const auto end = std::chrono::steady_clock::now();
  const double wall = std::chrono::duration<double>(end - progress.start).count();
  if (progress.on && progress.tty) std::fprintf(stderr, "\n");
  // every rank's particle-steps (rank 0's progress line counted its own)
  particle_steps = static_cast<double>(ranks.sum_count(static_cast<std::size_t>(particle_steps)));
  window_particle_steps = static_cast<double>(ranks.sum_count(static_cast<std::size_t>(window_particle_steps)));
  result.macro_steps = m;
  result.simulated_time = static_cast<double>(m) * macro;
  result.wall_seconds = wall;
  result.particle_steps_per_second = wall > 0 ? particle_steps / wall : 0;

  // The end: the components' last files and their parts of summary.json.
  ctx.end_index = m;
  ctx.end_time = result.simulated_time;
  nlohmann::json summary = this->summary(ctx, result, options, registry, groups, threads_n, particles);
  if (result.interrupted_by && options.checkpoint_on_signal && checkpoints_possible)
    summary["checkpoint"] = kCheckpointFile;
  if (ck) summary["restarted_from"] = {{"checkpoint", options.restart.string()}, {"simulated_time_s", ck->loop.time}};
  if (options.time_after && m > options.time_after) {
    const double w = std::chrono::duration<double>(end - window_start).count();
    summary["timed_window"] = {{"from_step", options.time_after},
                               {"steps", m - options.time_after},
                               {"wall_time_s", w},
                               {"particle_steps_per_s", w > 0 ? window_particle_steps / w : 0.0}};
  }
  for (Component* c : components) c->finish(ctx, summary);
  if (writer) io::write_file_atomically(out / "summary.json", summary.dump(2) + "\n");
  result.summary = summary;
  if (writer)
    spdlog::info("done: {} steps, {:.6g} s simulated in {:.3g} s wall ({:.3g} particle-steps/s)", m,
                 result.simulated_time, wall, result.particle_steps_per_second);
  return result;
}

}  // namespace domel::platform
