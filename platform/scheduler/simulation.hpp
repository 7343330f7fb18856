// SPDX-License-Identifier: MIT
// A built, validated scenario and the loop that runs it: subdomains advance
// at their own time steps inside a common macro step (a coarse subdomain
// takes one large step while a finer one sub-cycles), outputs are written
// at fixed simulated-time intervals, and progress is reported.
#pragma once

#include "averaging/cell_grid.hpp"
#include "coupling/coupling.hpp"
#include "core/material.hpp"
#include "fluid/fluid_coupling.hpp"
#include "geometry/wall.hpp"
#include "loader/plugin_registry.hpp"
#include "scheduler/contact_sample.hpp"
#include "scheduler/particle_flow.hpp"
#include "scheduler/run_ranks.hpp"
#include "scheduler/schedule.hpp"
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

struct RunOptions {
  std::filesystem::path output_directory;  ///< empty: the scenario's choice
  int threads = 0;                         ///< 0: the scenario's choice
  bool progress = true;
  std::uint64_t max_steps = 0;             ///< 0: run to the end; otherwise stop early (smoke tests)
  std::uint64_t time_after = 0;            ///< benchmarks: also time the steps after this many (warm-up excluded)
  std::filesystem::path restart;           ///< a checkpoint to continue from (docs/checkpoint.md)
  bool checkpoint_on_signal = true;        ///< on SIGINT/SIGTERM (core/interrupt.hpp), write a checkpoint
  /// A run spread over several processes (scheduler/run_ranks.hpp); null or
  /// one rank: this process alone.
  RunRanks* ranks = nullptr;
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

/// output.region_mass: the mass of the particles inside a region (a heap on
/// a plate), as <name>.mass_kg and <name>.particles in probes.csv.
struct RegionMassProbe {
  std::string name;
  std::size_t subdomain = kAllSubdomains;  ///< the only subdomain counted, or all
  domel_region_v1 region{};
  std::optional<double> max_speed;  ///< [m/s] only particles slower than this
  std::optional<std::size_t> material;  ///< only particles of this scenario material
  bool centre_of_mass = false;          ///< also <name>.com_x, .com_y, .com_z
};

/// The unit of a probes.csv column ("s", "J", "rad/s", "kg", "1" for counts
/// and ratios ...), "" for a column it does not know.
std::string probe_column_unit(const std::string& column);

class Simulation {
 public:
  Simulation() = default;
  // hooks hold pointers into this object (the particle flow registers its
  // own member): it stays where it was built
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
  WallServos servos;  ///< walls[].motion[].servo (scheduler/servo.hpp): updated after every macro step
  double duration = 0;
  double checkpoint_interval = 0;  ///< [s] run.checkpoint_interval; 0: none
  nlohmann::json document;         ///< the validated scenario, defaults filled (checkpoints compare it)
  std::uint64_t seed = 1;
  int threads = 0;  ///< the scenario's run.threads; 0: not given (DOMEL_THREADS, else 1)
  double vtk_interval = 0;
  double probe_interval = 0;
  bool write_state = false;  ///< output.state: <subdomain>_state.csv at the end (io/particle_state.hpp)
  std::optional<ReposeProbeSettings> repose_probe;  ///< adds <subdomain>.repose_angle_deg to probes.csv
  std::vector<RegionMassProbe> region_mass;         ///< output.region_mass
  ContactSample contact_sample;  ///< output.wall_loads and output.contacts (scheduler/contact_sample.hpp)
  double contact_interval = 0;   ///< [s] between contact files (output.contacts); 0: none
  bool wall_surfaces = true;     ///< output.wall_surfaces: walls.pvd with the particle frames
  double scene_lo[3] = {0, 0, 0}, scene_hi[3] = {0, 0, 0};  ///< where unbounded walls are drawn
  std::filesystem::path output_directory;
  nlohmann::json models_used;  ///< per subdomain: slot -> {model, version, library}
  ParticleFlow flow;           ///< pours, deletion regions, mass-flow planes, mass balance
  /// Run before and after every macro step (schedule.hpp): the particle flow
  /// registers here when the scenario has pours, deletions or planes, and so
  /// will couplings between levels.
  MacroHooks hooks;
  /// Eulerian cell grids (output.grids): each averages one subdomain's
  /// particles every `every` of its steps; the latest fields are readable by
  /// controllers and couplers during the run (CellGrid::latest()).
  struct GridSetup {
    CellGridSpec spec;
    std::size_t subdomain = 0;
    int profile_axis = 2;
  };
  std::vector<GridSetup> grid_setups;
  std::vector<std::unique_ptr<CellGrid>> grids;  ///< built by run(), same order as grid_setups
  /// Couplings between levels (coupling/coupling.hpp), all on one control
  /// clock: every control_macro macro steps, after the flow's hooks.
  std::vector<std::unique_ptr<Coupling>> couplings;
  std::uint64_t control_macro = 0;
  /// The fluid coupling (the scenario's `fluid` block), if any: an exchange
  /// every spec().interval_macro macro steps, after the couplings' hook.
  std::unique_ptr<FluidCoupling> fluid;

  /// Run to the end. Throws RuntimeError or PluginError on failure; every
  /// file written up to then is complete (written to a temporary name and renamed).
  RunResult run(const RunOptions& options, const PluginRegistry& registry);

  /// Why this run cannot be checkpointed ("" if it can): a controller or
  /// fluid coupler whose library lacks ABI 2.3's save_state and load_state.
  std::string why_no_checkpoint() const;

  /// The macro step and each subdomain's number of sub-steps within it.
  double macro_step() const;
};

}  // namespace domel::platform
