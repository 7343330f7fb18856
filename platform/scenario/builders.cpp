// SPDX-License-Identifier: MIT
// The construction of a Simulation from a validated scenario whose schema
// defaults have been filled in (scenario.cpp, fill_defaults): one builder per
// scenario block, run in the order the blocks depend on each other --
// materials and interactions, walls, the run settings, the subdomains (each:
// contact pipeline, initial state, insertions, pours, skin, time step), the
// particle flow, the cell grids and the outputs. Every value with a schema
// default is read from the document without a fallback here; a key without
// one is optional and tested with contains(). Every problem becomes a
// Diagnostic; build() throws them all at once, before anything is written.
#include "scenario/build.hpp"

#include "core/cadence.hpp"

#include "core/error.hpp"

namespace domel::platform::scenario_detail {

std::size_t subdomain_index(Build& b, const json& name, const std::string& pointer) {
  const std::string want = name.get<std::string>();
  std::vector<std::string> names;
  for (std::size_t k = 0; k < b.sim.subdomains.size(); ++k) {
    if (b.sim.subdomains[k]->name() == want) return k;
    names.push_back(b.sim.subdomains[k]->name());
  }
  b.ck.add(pointer, "unknown subdomain '" + want + "'", suggest(want, names));
  return kAllSubdomains;
}

std::unique_ptr<Simulation> build(const json& doc, const std::filesystem::path& file, PluginRegistry& registry) {
  auto sim = std::make_unique<Simulation>();
  sim->scenario_file = file;
  Build b{doc, file, registry, *sim, Checker{file, {}}, {}, {}, 1};
  build_materials(b);
  build_walls(b);
  build_run(b);
  scan_couplings(b);
  for (std::size_t k = 0; k < doc["subdomains"].size(); ++k) build_subdomain(b, k);
  const bool steps_counted = check_level_steps(b);
  build_rank_shares(b);
  if (steps_counted && b.sim.subdomains.size() == doc["subdomains"].size()) build_couplings(b);
  build_particle_flow(b);
  if (b.ck.diags.empty()) warn_shared_space(b);
  build_grids(b);
  build_repose_probe(b);
  build_contact_outputs(b);
  std::optional<FluidSpec> fluid = build_fluid(b);
  build_duration(b);
  check_schedules(b);
  if (!b.ck.diags.empty()) throw ConfigError(b.ck.diags);
  build_outputs(b);
  if (fluid) {
    if (fluid->write_interval < 0) fluid->write_interval = b.out.vtk_interval;
    fluid->run_macro_steps = static_cast<std::uint64_t>(std::ceil(sim->duration / sim->macro_step() - kTimeTolerance));
    sim->fluid = std::make_unique<FluidCoupling>(std::move(*fluid), sim->subdomains);
  }
  register_components(b);
  if (sim->checkpoint_interval > 0) {
    const std::string why = sim->why_no_checkpoint();
    if (!why.empty())
      throw ConfigError({Diagnostic{file.string(), "/run/checkpoint_interval", why,
                                    "remove run.checkpoint_interval, or rebuild the plugin against the SDK of ABI 2.3"}});
  }
  return sim;
}

}  // namespace domel::platform::scenario_detail

