// SPDX-License-Identifier: MIT
// The builders of the cell grids, the repose probe and the output settings,
// and the registration of the run's components in the order they act
// (build.hpp).
#include "scenario/build.hpp"

#include "coupling/level_couplings.hpp"
#include "outputs/contact_frames.hpp"
#include "outputs/output_kinds.hpp"
#include "outputs/particle_frames.hpp"
#include "outputs/probes.hpp"
#include "outputs/repose_angle.hpp"
#include "outputs/state_files.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace domel::platform::scenario_detail {

/// output.grids: the cell grids' specifications (their write interval, when
/// not given, waits for the duration in build_outputs()).
void build_grids(Build& b) {
  const json& out = b.doc["output"];
  if (!out.contains("grids")) return;
  const json& gs = out["grids"];
  for (std::size_t g = 0; g < gs.size(); ++g) {
    const json& gj = gs[g];
    GridSetup setup;
    setup.spec.name = gj["name"].get<std::string>();
    for (int a = 0; a < 3; ++a) {
      setup.spec.lo[a] = gj["min"][a].get<double>();
      setup.spec.hi[a] = gj["max"][a].get<double>();
      setup.spec.cells[a] = gj["cells"][a].get<int>();
    }
    setup.spec.every = gj["every"].get<int>();
    setup.spec.write_interval = -1.0;  // not given: duration / 20, set in build_outputs()
    if (gj.contains("write_interval")) setup.spec.write_interval = gj["write_interval"].get<double>();
    setup.spec.accessible_samples = gj["accessible_samples"].get<int>();
    setup.profile_axis = axis_index(&gj["profile_axis"]);
    if (gj.contains("subdomain")) {
      const std::string want = gj["subdomain"].get<std::string>();
      std::vector<std::string> names;
      bool found = false;
      for (std::size_t k = 0; k < b.sim.subdomains.size(); ++k) {
        names.push_back(b.sim.subdomains[k]->name());
        if (names.back() == want) {
          setup.subdomain = k;
          found = true;
        }
      }
      if (!found)
        b.ck.add(idx("/output/grids", g) + "/subdomain", "unknown subdomain '" + want + "'", suggest(want, names));
    } else if (b.sim.subdomains.size() > 1) {
      b.ck.add(idx("/output/grids", g), "missing required property 'subdomain'",
               "the scenario has more than one subdomain; name the one this grid averages");
    }
    bool corners = true;
    for (int a = 0; a < 3; ++a)
      if (setup.spec.hi[a] <= setup.spec.lo[a]) {
        corners = false;
        b.ck.add(idx("/output/grids", g) + "/max/" + std::to_string(a),
                 "expected max > min along " + std::string(1, "xyz"[a]) + ", found max " + fmt_num(setup.spec.hi[a]) +
                     " <= min " + fmt_num(setup.spec.lo[a]));
      }
    if (corners) try {
        CellGridSpec checked = setup.spec;
        checked.write_interval = std::max(0.0, checked.write_interval);  // -1: the default, filled in later
        CellGrid probe(checked);  // the grid's own checks
      } catch (const std::invalid_argument& e) {
        b.ck.add(idx("/output/grids", g), e.what());
      }
    for (std::size_t h = 0; h < g; ++h)
      if (gs[h]["name"] == gj["name"])
        b.ck.add(idx("/output/grids", g) + "/name", "duplicate grid name '" + setup.spec.name + "'");
    b.out.grids.push_back(setup);
  }
}

/// The run's length and the outputs. Intervals without a schema default are
/// fractions of the duration, so this runs once the macro step is known.
void build_repose_probe(Build& b) {
  const json& out = b.doc["output"];
  if (!out.contains("repose_angle")) return;
  const json& r = out["repose_angle"];
  const std::string where = "/output/repose_angle";
  ReposeProbeSettings rp;
  rp.base_height = r["base_height"].get<double>();
  rp.cell = r["cell"].get<double>();
  rp.band_lo = r["band"][0].get<double>();
  rp.band_hi = r["band"][1].get<double>();
  if (!(rp.band_lo < rp.band_hi))
    b.ck.add(where + "/band", "expected band[0] < band[1] (the fitted part of the heap's height), found [" +
                                  r["band"][0].dump() + ", " + r["band"][1].dump() + "]");
  rp.planar = r["shape"].get<std::string>() == "planar";
  rp.axis = axis_index(member(r, "axis"));
  if (const json* c = member(r, "crest")) {
    if (!rp.planar)
      b.ck.add(where + "/crest", "'crest' is the crest line of a planar heap, but shape is \"cone\"",
               "add \"shape\": \"planar\", or remove 'crest'");
    rp.crest = c->get<double>();
  }
  if (const json* reg = member(r, "region")) rp.region = make_region(*reg);
  if (const json* v = member(r, "max_speed")) rp.max_speed = v->get<double>();
  b.sim.repose_probe = rp;
}

/// The most macro steps a run may have: run.steps' schema maximum.
constexpr double kMaxMacroSteps = 1e15;

void build_duration(Build& b) {
  const json& run = b.doc["run"];
  if (run.contains("duration")) {
    b.sim.duration = run["duration"].get<double>();
    // the run counts its macro steps in 64 bits; run.steps' own limit holds
    // for a duration too (1e300 s made a count beyond any integer: the
    // run-time fuzzer)
    const double macro = b.sim.macro_step();
    if (macro > 0 && std::isfinite(macro) && !(b.sim.duration / macro <= kMaxMacroSteps))
      b.ck.add("/run/duration",
               "a run of " + fmt_num(b.sim.duration) + " s is " + fmt_num(b.sim.duration / macro) +
                   " macro steps of " + fmt_num(macro) + " s, more than the " + fmt_num(kMaxMacroSteps) +
                   " a run can count",
               "check the duration's units (run.steps accepts at most 1e15 too)");
  } else {
    b.sim.duration = static_cast<double>(run["steps"].get<std::uint64_t>()) * b.sim.macro_step();
  }
}

void build_outputs(Build& b) {
  Simulation& sim = b.sim;
  const json& out = b.doc["output"];
  sim.output_directory = out.contains("directory") ? out["directory"].get<std::string>() : sim.name + "_out";
  b.out.vtk_interval = out.contains("vtk_interval") ? out["vtk_interval"].get<double>() : sim.duration / 50.0;
  b.out.probe_interval = out.contains("probe_interval") ? out["probe_interval"].get<double>() : sim.duration / 500.0;
  b.out.state = out["state"].get<bool>();
  if (out.contains("contacts"))
    b.out.contact_interval = out["contacts"].contains("interval") ? out["contacts"]["interval"].get<double>()
                                                                  : b.out.vtk_interval;
  scene_bounds(b);
  for (auto& g : b.out.grids)
    if (g.spec.write_interval < 0) g.spec.write_interval = sim.duration / 20.0;
}

/// Every component of the run, in the order they act at each point of the
/// loop (loop/component.hpp): the particle flow, probes.csv, the particle
/// and wall frames, the contact frames, the output grids (and the accessible
/// volumes of every grid), the couplings, the fluid, the contact sample, the
/// servo walls, the state files and the registered output kinds. So before
/// a macro step: pours and deletions, the couplings' exchange, the fluid's;
/// at an output time: probes, frames, contacts, grid files, the couplings'
/// and the fluid's files. probes.csv's columns follow the subdomains'
/// statistics in the order repose angle, region masses, flow, wall loads,
/// servos.
void register_components(Build& b) {
  Simulation& sim = b.sim;
  sim.components.push_back(&sim.flow);
  std::vector<ProbeSource*> sources;
  if (sim.repose_probe) {
    auto& repose = sim.add(std::make_unique<ReposeAngleOutput>(*sim.repose_probe));
    std::vector<std::string> names;
    for (const auto& sd : sim.subdomains) names.push_back(sd->name());
    repose.set_subdomain_names(std::move(names));
    sources.push_back(&repose);
  }
  if (!b.out.region_mass.empty())
    sources.push_back(&sim.add(std::make_unique<RegionMassOutput>(std::move(b.out.region_mass))));
  sources.push_back(&sim.flow);
  sources.push_back(&sim.contact_sample);
  sources.push_back(&sim.servos);
  auto& probes = sim.add(std::make_unique<ProbesOutput>(b.out.probe_interval, std::move(sources)));
  std::vector<std::string> materials;
  for (const Material& m : sim.materials) materials.push_back(m.name);
  sim.add(std::make_unique<ParticleFrames>(b.out.vtk_interval, materials, b.out.wall_surfaces, b.out.scene_lo,
                                           b.out.scene_hi, &probes));
  auto& contact_frames = sim.add(std::make_unique<ContactFrames>(
      sim.contact_sample.wants_rows() ? b.out.contact_interval : 0.0, sim.contact_sample));
  if (probes.enabled() && sim.contact_sample.has_probes()) sim.contact_sample.wanted_at(&probes.cadence());
  sim.contact_sample.wanted_at(&contact_frames.cadence());
  sim.add(std::make_unique<GridFiles>(std::move(b.out.grids)));
  sim.add(std::make_unique<LevelCouplings>(sim.couplings, sim.control_macro, sim.flow));
  if (sim.fluid) sim.components.push_back(sim.fluid.get());
  sim.components.push_back(&sim.contact_sample);
  sim.components.push_back(&sim.servos);
  if (b.out.state) sim.add(std::make_unique<StateFiles>(materials));
  // the registered output kinds whose block the scenario has (outputs/output_kinds.hpp)
  const json& out = b.doc["output"];
  for (const OutputKind& kind : output_kinds()) {
    if (!out.contains(kind.key)) continue;
    OutputSetting setting{out[kind.key], "/output/" + kind.key, {}, materials, sim.duration, sim.macro_step()};
    for (const auto& sd : sim.subdomains) setting.subdomains.push_back(sd->name());
    try {
      sim.add(kind.make(setting));
    } catch (const ConfigError& e) {  // the factory's diagnostics, named after the scenario file
      std::vector<Diagnostic> diags = e.diagnostics();
      for (auto& d : diags)
        if (d.file.empty()) d.file = b.file.string();
      throw ConfigError(diags);
    }
  }
}

}  // namespace domel::platform::scenario_detail
