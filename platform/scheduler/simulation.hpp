// SPDX-License-Identifier: MIT
// A built, validated scenario and the loop that runs it: subdomains advance
// at their own time steps inside a common macro step (a coarse subdomain
// takes one large step while a finer one sub-cycles), and everything else
// that acts during a run is a component (loop/component.hpp) at the points
// of the loop it registered for: the particle flow, couplings between
// levels, the fluid coupling, servo walls, the contact sample and every
// output. run() is the loop of those points; the summary and the levels'
// preparation are its helpers (run_setup.cpp).
#pragma once

#include "core/material.hpp"
#include "coupling/coupling.hpp"
#include "flow/particle_flow.hpp"
#include "fluid/fluid_coupling.hpp"
#include "geometry/wall.hpp"
#include "loader/plugin_registry.hpp"
#include "loop/component.hpp"
#include "loop/macro_step.hpp"
#include "loop/ranks.hpp"
#include "outputs/contact_sample.hpp"
#include "scheduler/servo.hpp"
#include "subdomain/repose_probe.hpp"
#include "subdomain/subdomain.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace domel::platform {

struct OpenedCheckpoint;
struct CheckpointWorld;

struct RunOptions {
  std::filesystem::path output_directory;  ///< empty: the scenario's choice
  int threads = 0;                         ///< 0: the scenario's choice
  bool progress = true;
  std::uint64_t max_steps = 0;             ///< 0: run to the end; otherwise stop early (smoke tests)
  std::uint64_t time_after = 0;            ///< benchmarks: also time the steps after this many (warm-up excluded)
  std::filesystem::path restart;           ///< a checkpoint to continue from (docs/checkpoint.md)
  bool checkpoint_on_signal = true;        ///< on SIGINT/SIGTERM (core/interrupt.hpp), write a checkpoint
  /// The processes the run is spread over (loop/ranks.hpp), never null:
  /// this process alone unless the launcher runs under mpirun.
  RunRanks* ranks = &one_process();
};

struct RunResult {
  std::uint64_t macro_steps = 0;
  double simulated_time = 0;
  double wall_seconds = 0;
  double particle_steps_per_second = 0;
  std::filesystem::path output_directory;
  nlohmann::json summary;
  int interrupted_by = 0;  ///< the signal that stopped the run early (core/interrupt.hpp), 0 if none
};

class Simulation {
 public:
  Simulation() = default;
  // components point into this object (its flow, couplings, contact
  // sample): it stays where it was built
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  std::string name;
  std::filesystem::path scenario_file;
  std::vector<Material> materials;
  std::vector<WallPrimitive> walls;    ///< the scenario walls' primitives at time 0
  std::vector<std::string> wall_names;  ///< the scenario walls (WallPrimitive::wall indexes it)
  std::vector<std::unique_ptr<Subdomain>> subdomains;
  /// subdomains[].rank_share, one per subdomain, or empty: every subdomain
  /// spread over all ranks (rank_groups()).
  std::vector<double> rank_shares;
  std::vector<TimeStepReport> time_steps;  ///< per subdomain
  double gravity[3] = {0, 0, 0};  ///< [m/s^2] the scenario's at t = 0 (its schema default when omitted)
  std::shared_ptr<const GravitySchedule> gravity_schedule;  ///< the scenario's gravity over time (core/gravity.hpp)
  double duration = 0;
  double checkpoint_interval = 0;  ///< [s] run.checkpoint_interval; 0: none
  nlohmann::json document;         ///< the validated scenario, defaults filled (checkpoints compare it)
  std::uint64_t seed = 1;
  int threads = 0;  ///< the scenario's run.threads; 0: not given (DOMEL_THREADS, else 1)
  std::filesystem::path output_directory;
  nlohmann::json models_used;  ///< per subdomain: slot -> {model, version, library}

  // The built-in components the builder wires (each also in `components`):
  ParticleFlow flow;           ///< pours, deletion regions, mass-flow planes, mass balance
  WallServos servos;           ///< walls[].motion[].servo: updated after every macro step
  ContactSample contact_sample;  ///< output.wall_loads and output.contacts (outputs/contact_sample.hpp)
  /// Couplings between levels (coupling/coupling.hpp), all on one control
  /// clock: every control_macro macro steps (coupling/level_couplings.hpp).
  std::vector<std::unique_ptr<Coupling>> couplings;
  std::uint64_t control_macro = 0;
  /// The fluid coupling (the scenario's `fluid` block), if any: an exchange
  /// every spec().interval_macro macro steps.
  std::unique_ptr<FluidCoupling> fluid;
  std::optional<ReposeProbeSettings> repose_probe;  ///< output.repose_angle

  /// Every component of the run in registration order: the order in which
  /// they act at each point of the loop (loop/component.hpp).
  std::vector<Component*> components;
  /// Register a component the simulation owns, after every one so far;
  /// returns it.
  template <class T>
  T& add(std::unique_ptr<T> c) {
    T& ref = *c;
    components.push_back(c.get());
    owned_.push_back(std::move(c));
    return ref;
  }
  /// The first registered component of type T, or null.
  template <class T>
  T* find() const {
    for (Component* c : components)
      if (auto* t = dynamic_cast<T*>(c)) return t;
    return nullptr;
  }

  /// Run to the end. Throws RuntimeError or PluginError on failure; every
  /// file written up to then is complete (written to a temporary name and renamed).
  RunResult run(const RunOptions& options, const PluginRegistry& registry);

  /// A checkpoint a run can go on from: where, and the time it holds.
  struct CheckpointMark {
    std::filesystem::path file;
    double time = 0;  ///< [s]
  };
  /// The newest checkpoint run() wrote, or the one it restarted from: after
  /// a failure (a full disk, a blow-up) the run can go on from it.
  const std::optional<CheckpointMark>& last_checkpoint() const { return last_checkpoint_; }

  /// Why this run cannot be checkpointed ("" if it can): a controller or
  /// fluid coupler whose library lacks ABI 2.3's save_state and load_state.
  std::string why_no_checkpoint() const;

  /// The macro step and each subdomain's number of sub-steps within it.
  double macro_step() const;

  /// What a checkpoint holds besides the components' sections, and what a
  /// restart's scenario is compared with (scheduler/checkpoint.hpp).
  CheckpointWorld world();

 private:
  /// run()'s helpers (run_setup.cpp): the rank groups, checked; the levels'
  /// time steps, threads and ranks (the sub-steps of each); the world
  /// restored from a checkpoint; the summary.
  std::vector<RankGroup> rank_groups_checked(RunRanks& ranks) const;
  std::vector<int> prepare_levels(RunRanks& ranks, const std::vector<RankGroup>& groups, int threads, bool writer);
  void restore_world(const OpenedCheckpoint& ck, RunRanks& ranks, int threads, bool writer);
  nlohmann::json summary(RunContext& ctx, const RunResult& result, const RunOptions& options,
                         const PluginRegistry& registry, const std::vector<RankGroup>& groups, int threads,
                         std::size_t particles_at_start) const;
  std::vector<std::unique_ptr<Component>> owned_;
  std::optional<CheckpointMark> last_checkpoint_;
};

}  // namespace domel::platform
