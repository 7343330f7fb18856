// SPDX-License-Identifier: MIT
// Internal to platform/scenario: what the builders share while they turn a
// validated document into a Simulation (builders.cpp runs them in order),
// and the builders of each scenario block, one file per block or group of
// blocks: build_materials.cpp (materials, interactions, walls, the run),
// build_subdomains.cpp (each subdomain: contact pipeline, initial state,
// insertions, pours, time step; rank shares), build_flow.cpp (deletion
// regions, mass-flow planes, region masses, wall loads and contacts),
// build_couplings.cpp (couplings between levels, the scene's bounds),
// build_fluid.cpp (the fluid block), build_outputs.cpp (grids, the repose
// probe, the output settings, the run's components), build_schedules.cpp
// (every interval in seconds against the macro step).
#pragma once

#include "outputs/grid_files.hpp"
#include "outputs/region_mass.hpp"
#include "scenario/scenario_detail.hpp"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace domel::platform::scenario_detail {

/// What the builders share while they work through the document.
struct Build {
  const json& doc;
  const std::filesystem::path& file;
  PluginRegistry& registry;
  Simulation& sim;
  Checker ck;
  std::map<std::string, std::size_t> mat_index;
  std::map<std::pair<std::string, std::string>, PairCoefficients> coeffs;
  std::uint64_t next_id = 1;  ///< id of the next particle made
  /// Smallest and largest parcel radius of each subdomain built so far
  /// (present particles and pours; a coupled fine level: its parent's scaled).
  std::map<std::string, std::array<double, 2>> radii;
  /// fine subdomain -> (coarse subdomain, coupling index) from /couplings
  std::map<std::string, std::pair<std::string, std::size_t>> parent;
  /// the interactions (indices) that name their own rolling model, in the
  /// order of PairCoefficients::rolling_model
  std::vector<std::size_t> pair_rolling;
  /// The output blocks as read, made components by register_components()
  struct Outputs {
    double vtk_interval = 0, probe_interval = 0, contact_interval = 0;
    bool state = false, wall_surfaces = true;
    std::array<double, 3> scene_lo{}, scene_hi{};  ///< where unbounded walls are drawn
    std::vector<RegionMassProbe> region_mass;
    std::vector<GridSetup> grids;
  } out;
};

// build_materials.cpp
void build_materials(Build& b);
void build_walls(Build& b);
void build_run(Build& b);
// build_subdomains.cpp
void build_subdomain(Build& b, std::size_t k);
/// False (and reported) when a level has more steps per macro step than an int counts.
bool check_level_steps(Build& b);
void build_rank_shares(Build& b);
// builders.cpp
/// The index of a subdomain named at `pointer`; an unknown name is reported
/// (with the nearest name) and gives kAllSubdomains.
std::size_t subdomain_index(Build& b, const json& name, const std::string& pointer);
// build_flow.cpp
void build_particle_flow(Build& b);
void build_contact_outputs(Build& b);
// build_couplings.cpp
void scan_couplings(Build& b);
void build_couplings(Build& b);
void warn_shared_space(Build& b);
void scene_bounds(Build& b);
/// Bounding box of a top-level domain (build_couplings.cpp says how); false
/// when the walls leave it unbounded.
bool domain_bounds(Build& b, double lo[3], double hi[3]);
// build_fluid.cpp
std::optional<FluidSpec> build_fluid(Build& b);
// build_outputs.cpp
void build_grids(Build& b);
/// The run's duration: run.duration, or run.steps macro steps (after the subdomains).
void build_duration(Build& b);
// build_schedules.cpp
/// Every interval given in seconds at least one macro step (refused at its
/// pointer otherwise); more than 1e5 actions in a run warned about.
void check_schedules(Build& b);
void build_repose_probe(Build& b);
void build_outputs(Build& b);
void register_components(Build& b);

}  // namespace domel::platform::scenario_detail
