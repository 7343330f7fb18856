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
#include "coupling/coupling.hpp"
#include "coupling/level_couplings.hpp"
#include "geometry/region.hpp"
#include "geometry/triangle_mesh.hpp"  // MeshError
#include "io/particle_state.hpp"
#include "outputs/contact_frames.hpp"
#include "outputs/grid_files.hpp"
#include "outputs/output_kinds.hpp"
#include "outputs/particle_frames.hpp"
#include "outputs/probes.hpp"
#include "outputs/region_mass.hpp"
#include "outputs/repose_angle.hpp"
#include "outputs/state_files.hpp"
#include "subdomain/diagnostics.hpp"
#include "scenario/scenario.hpp"
#include "scenario/scenario_detail.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

namespace domel::platform::scenario_detail {

namespace {


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

void build_materials(Build& b) {
  for (auto& [name, m] : b.doc["materials"].items()) {
    Material mat;
    mat.name = name;
    mat.density = m.contains("density") ? m["density"].get<double>() : 0.0;  // absent: a wall-only material
    mat.youngs_modulus = m["youngs_modulus"].get<double>();
    mat.poisson_ratio = m["poisson_ratio"].get<double>();
    b.mat_index[name] = b.sim.materials.size();
    b.sim.materials.push_back(mat);
  }
  for (std::size_t q = 0; q < b.doc["interactions"].size(); ++q) {
    const json& it = b.doc["interactions"][q];
    // std::minmax returns references: bind the names first (temporaries would dangle)
    const std::string x = it["materials"][0].get<std::string>(), y = it["materials"][1].get<std::string>();
    const std::pair<std::string, std::string> key = std::minmax(x, y);
    PairCoefficients& c = b.coeffs[key];
    c.restitution = it["restitution"].get<double>();
    c.friction = it["friction"].get<double>();
    c.has_rolling_friction = it.contains("rolling_friction");
    if (c.has_rolling_friction) c.rolling_friction = it["rolling_friction"].get<double>();
    // its own rolling model: every subdomain's pipeline makes one instance
    // of each, in this order (build_contact_pipeline)
    if (it.contains("rolling")) {
      if (it["rolling"]["model"] == "none") {
        c.rolling_model = ContactPipeline::kNoRolling;
      } else {
        c.rolling_model = static_cast<int>(b.pair_rolling.size());
        b.pair_rolling.push_back(q);
      }
    }
  }
}

void build_walls(Build& b) {
  if (!b.doc.contains("walls")) return;
  for (std::size_t k = 0; k < b.doc["walls"].size(); ++k) {
    const json& w = b.doc["walls"][k];
    b.sim.wall_names.push_back(w["name"].get<std::string>());
    try {
      auto prims = expand_wall(w, k, b.mat_index.at(w["material"].get<std::string>()), b.file);
      // a servo (one per wall, validated): its controller, and its wall's load summed
      const MotionItem* servo_item = nullptr;
      if (!prims.empty() && prims[0].moving)
        for (const MotionItem& it : prims[0].motion->items)
          if (it.kind == MotionItem::Kind::servo) servo_item = &it;
      if (servo_item) {
        const json& mo = w["motion"];
        for (const json& item : mo.is_array() ? mo : json::array({mo})) {
          const json* sv = member(item, "servo");
          if (!sv) continue;
          WallServo s;
          s.name = w["name"].get<std::string>();
          s.wall = k;
          for (int a = 0; a < 3; ++a) s.direction[a] = servo_item->vec[a];
          s.force = (*sv)["force"].get<double>();
          const double vmax = (*sv)["max_velocity"].get<double>();
          s.gain = sv->contains("gain") ? (*sv)["gain"].get<double>() : vmax / s.force;
          s.start = servo_item->start;
          s.end = servo_item->end;
          s.state = servo_item->servo;
          s.state->max_velocity = vmax;
          b.sim.servos.servos.push_back(std::move(s));
        }
        for (auto& p : prims) p.track_load = true;
      }
      b.sim.walls.insert(b.sim.walls.end(), prims.begin(), prims.end());
    } catch (const MeshError& e) {  // the file changed since validation
      b.ck.add("/walls", e.what());
    }
  }
}

/// The scenario's name, gravity, seed and thread count (the run's length is
/// read by build_outputs(), once the macro step is known).
void build_run(Build& b) {
  const json& run = b.doc["run"];
  b.sim.name = b.doc.contains("name") ? b.doc["name"].get<std::string>() : b.file.stem().string();
  const json& g = b.doc["gravity"];
  GravitySchedule schedule;
  if (g.is_array()) {
    double v[3];
    for (int a = 0; a < 3; ++a) v[a] = g[a].get<double>();
    schedule = GravitySchedule::constant(v);
  } else if (g.contains("table")) {
    std::vector<std::array<double, 4>> rows;
    for (const json& r : g["table"]) rows.push_back({r[0].get<double>(), r[1].get<double>(), r[2].get<double>(), r[3].get<double>()});
    schedule = GravitySchedule::table(std::move(rows));
  } else {
    const json& rot = g["rotation"];
    double v[3], axis[3];
    for (int a = 0; a < 3; ++a) {
      v[a] = g["vector"][a].get<double>();
      axis[a] = rot["axis"][a].get<double>();
    }
    schedule = GravitySchedule::rotating(v, axis, rot["rate"].get<double>(), rot["start"].get<double>(),
                                         rot.contains("end") ? rot["end"].get<double>()
                                                             : std::numeric_limits<double>::infinity());
  }
  schedule.at(0.0, b.sim.gravity);
  if (schedule.varies()) b.sim.gravity_schedule = std::make_shared<const GravitySchedule>(std::move(schedule));
  b.sim.seed = run["seed"].get<std::uint64_t>();
  // no schema default: absent means $DOMEL_THREADS, else 1, decided at run time (Simulation::run)
  b.sim.threads = run.contains("threads") ? run["threads"].get<int>() : 0;
  b.sim.checkpoint_interval = run["checkpoint_interval"].get<double>();
  b.sim.flow.max_particles = run["max_particles"].get<std::size_t>();
  if (particle_ceiling() != 0) b.sim.flow.max_particles = std::min(b.sim.flow.max_particles, particle_ceiling());
  b.sim.document = b.doc;
}

/// The models of a subdomain's five contact slots (every slot is in the
/// document: omitted ones were filled with the schema's default model).
/// Null when a model cannot be made (reported).
std::unique_ptr<ContactPipeline> build_contact_pipeline(Build& b, const json& sd, const std::string& base,
                                                        json& used) {
  std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots;
  bool ok = true;
  for (std::size_t s = 0; s < kSlotCount; ++s) {
    const json& block = sd["contact"][kSlotNames[s]];
    const std::string model = block["model"].get<std::string>();
    if (model == "none") continue;
    const RegisteredModel* m = b.registry.find(kSlotKinds[s], model);
    const std::string where = base + "/contact/" + kSlotNames[s];
    if (!m) {  // a default the loaded plugins do not provide
      b.ck.add(where, std::string("no ") + kSlotNames[s] + " model '" + model + "' is loaded",
               suggest(model, b.registry.names(kSlotKinds[s])));
      ok = false;
      continue;
    }
    try {
      slots[s] = std::make_unique<ModelInstance>(*m, plugin_params(block, kSlotKinds[s]),
                                                 "subdomain '" + sd["name"].get<std::string>() + "'");
    } catch (const PluginError& e) {
      b.ck.add(where, e.what());
      ok = false;
      continue;
    }
    used[kSlotNames[s]] = {{"model", model},
                           {"version", m->version},
                           {"library", b.registry.libraries()[m->library].name},
                           {"library_version", b.registry.libraries()[m->library].version}};
  }
  // the rolling models of the material pairs that name their own
  std::vector<std::unique_ptr<ModelInstance>> pair_rolling;
  for (std::size_t q : b.pair_rolling) {
    const json& it = b.doc["interactions"][q];
    const json& block = it["rolling"];
    const std::string where = idx("/interactions", q) + "/rolling";
    const std::string model = block["model"].get<std::string>();
    const RegisteredModel* m = b.registry.find(DOMEL_KIND_ROLLING, model);
    if (!m) {  // check_models() reported it
      ok = false;
      continue;
    }
    try {
      pair_rolling.push_back(std::make_unique<ModelInstance>(
          *m, plugin_params(block, DOMEL_KIND_ROLLING),
          "subdomain '" + sd["name"].get<std::string>() + "', pair (" + it["materials"][0].get<std::string>() + ", " +
              it["materials"][1].get<std::string>() + ")"));
    } catch (const PluginError& e) {
      if (&sd == &b.doc["subdomains"][0]) b.ck.add(where, e.what());  // once, not per subdomain
      ok = false;
      continue;
    }
    used["rolling (" + it["materials"][0].get<std::string>() + ", " + it["materials"][1].get<std::string>() + ")"] = {
        {"model", model},
        {"version", m->version},
        {"library", b.registry.libraries()[m->library].name},
        {"library_version", b.registry.libraries()[m->library].version}};
  }
  if (!ok) return nullptr;
  return std::make_unique<ContactPipeline>(std::move(slots), std::move(pair_rolling));
}

/// What can be known about a subdomain's starting particles before a step:
/// overlapping pairs (refused above run.max_initial_overlap, with the ids),
/// an empty subdomain that nothing fills, and sizes that suggest a scenario
/// written in millimetres or kilometres (warnings naming the keys).
void check_initial_particles(Build& b, const Subdomain& sub, const json& sd, const std::string& base) {
  const ParticleStore& s = const_cast<Subdomain&>(sub).store();
  const std::string name = sd["name"].get<std::string>();
  const std::string source = sd.contains("initial_state") ? base + "/initial_state" : base + "/insert";
  if (b.sim.flow.max_particles != 0 && s.size() > b.sim.flow.max_particles) {
    b.ck.add(source, "the subdomain starts with " + std::to_string(s.size()) + " particles, more than run.max_particles (" +
                         std::to_string(b.sim.flow.max_particles) + ")",
             "check the units of the regions and diameters, or raise /run/max_particles");
    return;
  }
  const double limit = b.doc["run"]["max_initial_overlap"].get<double>();
  const InitialOverlaps o = find_initial_overlaps(s, limit, sub.periodic());
  if (o.pairs > 0)
    spdlog::info("subdomain '{}': {} overlapping pair(s) at the start, the worst {:.3g} % of the pair's mean diameter "
                 "(ids {} and {})", name, o.pairs, 100.0 * o.worst, o.worst_ids[0], o.worst_ids[1]);
  if (o.above_count > 0) {
    std::string ids;
    for (const auto& p : o.above)
      ids += (ids.empty() ? "" : ", ") + std::to_string(p.a) + " and " + std::to_string(p.b) + " (" +
             fmt_num(100.0 * p.ratio) + " %)";
    b.ck.add(source,
             std::to_string(o.above_count) + " particle pair(s) overlap by more than run.max_initial_overlap (" +
                 fmt_num(100.0 * limit) + " % of the pair's mean diameter): ids " + ids +
                 (o.above_count > o.above.size() ? ", ..." : "") +
                 (sd.contains("initial_state") ? " in the state file '" + sd["initial_state"].get<std::string>() + "'"
                                               : "") +
                 "; their first contact forces would blow them apart",
             "separate or remove those particles, or raise /run/max_initial_overlap if the overlaps are intended");
  }
  bool fed = sd.contains("pour") && !sd["pour"].empty();
  fed = fed || b.parent.count(name) != 0;  // the fine level of a coupling is filled by its parent
  if (s.size() == 0 && !fed)
    spdlog::warn("subdomain '{}' ({}) is empty and nothing adds particles to it (no insert, initial_state, pour or "
                 "coupling)", name, base);
  double dmin = 0, dmax = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    dmin = k == 0 ? 2 * s.radius[k] : std::min(dmin, 2 * s.radius[k]);
    dmax = std::max(dmax, 2 * s.radius[k]);
  }
  if (dmax > 0.5)
    spdlog::warn("subdomain '{}' ({}): particles of {:.4g} m diameter; domel works in SI units (m, kg, s), so a "
                 "scenario written in millimetres looks like this", name, source, dmax);
  if (s.size() > 0 && dmin < 1e-6)
    spdlog::warn("subdomain '{}' ({}): particles of {:.4g} m diameter (below 1 µm); domel works in SI units, so a "
                 "scenario written in kilometres looks like this", name, source, dmin);
  // a container smaller than its particles
  static const json kNoWalls = json::array();
  const json& walls = b.doc.contains("walls") ? b.doc["walls"] : kNoWalls;
  for (std::size_t w = 0; w < walls.size() && dmax > 0; ++w) {
    const json& wj = walls[w];
    double extent = std::numeric_limits<double>::infinity();
    if (wj["type"] == "box")
      for (int a = 0; a < 3; ++a) extent = std::min(extent, wj["max"][a].get<double>() - wj["min"][a].get<double>());
    if (wj["type"] == "cylinder") extent = 2 * wj["radius"].get<double>();
    if (extent < dmax)
      spdlog::warn("subdomain '{}': particles of {:.4g} m diameter ({}) are larger than the wall at {} ({:.4g} m "
                   "across); check the units of both (domel works in m)", name, dmax, source, idx("/walls", w),
                   extent);
  }
  const double dt = sd["time_step"].is_number() ? sd["time_step"].get<double>() : 0.0;
  const json& mat = b.doc["materials"][sd["material"].get<std::string>()];
  if (dt > 1e-3 && mat["youngs_modulus"].get<double>() > 1e8)
    spdlog::warn("subdomain '{}': time step {:.3g} s ({}/time_step) with a Young's modulus of {:.3g} Pa "
                 "(/materials/{}/youngs_modulus): stiff particles need steps of microseconds; is the time in ms?",
                 name, dt, base, mat["youngs_modulus"].get<double>(), sd["material"].get<std::string>());
}

/// A subdomain's particles from its initial_state file.
void build_initial_state(Build& b, Subdomain& sub, const json& sd, const std::string& base) {
  if (!sd.contains("initial_state")) return;
  const std::filesystem::path f = scenario_path(b.file, sd["initial_state"].get<std::string>());
  try {
    ParticleStore& st = sub.store();
    // streamed into the store, which is sized from the file's line count
    // first (an upper bound): no copy of the rows, no doubling slack
    st.reserve(st.size() + io::count_lines(f));
    const std::size_t rows = io::for_each_particle_state_row(f, [&](const io::ParticleStateRow& p) {
      // a v2 file names each particle's material (registered by build_subdomain(), checked by validation)
      const std::size_t global = p.material.empty() ? sub.material() : b.mat_index.at(p.material);
      st.add(b.next_id++, p.x, p.y, p.z, p.radius, b.sim.materials[global].density, p.fixed,
             sub.local_material(global));
      if (p.fixed) return;  // a fixed particle stays at rest
      st.vx.back() = p.vx; st.vy.back() = p.vy; st.vz.back() = p.vz;
      st.wx.back() = p.wx; st.wy.back() = p.wy; st.wz.back() = p.wz;
    });
    spdlog::info("subdomain '{}': {} particles from {} (contact history starts at zero)", sub.name(), rows,
                 f.string());
    sub.set_initial_source("the state file '" + f.string() + "' (" + base + "/initial_state)");
  } catch (const std::exception& e) {
    b.ck.add(base + "/initial_state", e.what());
  }
}

/// An insertion block (subdomains[k].insert[q], subdomains[k].pour[q].insert)
/// read once: its model instance and the platform keys around the plugin's
/// parameters. Start-up insertion and pours both make theirs here and ask for
/// particles through request_insertion().
struct Inserter {
  const RegisteredModel* registered = nullptr;
  std::shared_ptr<ModelInstance> model;
  domel_region_v1 region{};
  double velocity[3] = {0, 0, 0};
  bool fixed = false;
  std::uint64_t seed = 0;
  InsertedMaterials materials;  ///< the particles' material(s), local to the subdomain
};

/// Throws PluginError when the plugin refuses its parameters. `derived_seed`
/// is used when the block gives no seed; the instance's messages name `subdomain`.
Inserter make_inserter(Build& b, const json& block, Subdomain& sub, std::uint64_t derived_seed) {
  Inserter ins;
  ins.registered = b.registry.find(DOMEL_KIND_INSERTION, block["model"].get<std::string>());
  json params = plugin_params(block, DOMEL_KIND_INSERTION);
  const std::size_t global = block.contains("material") ? b.mat_index.at(block["material"].get<std::string>())
                                                        : sub.material();
  auto add = [&](std::size_t g) {
    ins.materials.material.push_back(sub.local_material(g));  // registered by build_subdomain() already
    ins.materials.density.push_back(b.sim.materials[g].density);
  };
  if (insertion_mixture(block)) {
    // A mixture: each component's material (its own, else the block's). The
    // model samples one density, so mass fractions of materials of
    // different densities reach it as volume fractions f_i / rho_i.
    // A malformed mixture goes to the model as written, which names the problem.
    json& mix = params["distribution"];
    const json* comps = member(mix, "components");
    bool well_formed = comps && comps->is_array() && !comps->empty();
    double sum = 0;
    for (std::size_t k = 0; well_formed && k < comps->size(); ++k) {
      const json& c = (*comps)[k];
      const json* f = member(c, "fraction");
      const json* m = member(c, "material");
      well_formed = f && f->is_number() && (!m || (m->is_string() && b.mat_index.count(m->get<std::string>())));
      if (well_formed) sum += f->get<double>();
    }
    if (well_formed)
      for (const json& c : *comps) add(c.contains("material") ? b.mat_index.at(c["material"].get<std::string>()) : global);
    else
      add(global);
    const auto& rho = ins.materials.density;
    if (well_formed && std::fabs(sum - 1.0) <= 1e-6 && member(mix, "by") && mix["by"] == "mass" &&
        std::any_of(rho.begin(), rho.end(), [&](double r) { return r != rho[0]; })) {
      double total = 0;
      for (std::size_t k = 0; k < rho.size(); ++k) total += mix["components"][k]["fraction"].get<double>() / rho[k];
      for (std::size_t k = 0; k < rho.size(); ++k)
        mix["components"][k]["fraction"] = mix["components"][k]["fraction"].get<double>() / rho[k] / total;
      mix["by"] = "volume";
    }
  } else {
    add(global);
  }
  ins.model = std::make_shared<ModelInstance>(*ins.registered, params, "subdomain '" + sub.name() + "'");
  ins.region = make_region(block["region"]);
  for (int a = 0; a < 3; ++a) ins.velocity[a] = block["velocity"][a].get<double>();
  ins.fixed = block["fixed"].get<bool>();
  ins.seed = block.contains("seed") ? block["seed"].get<std::uint64_t>() : derived_seed;
  return ins;
}

/// Inserter seeds derive from the run seed, this hash of the subdomain's
/// name and the inserter's position, so adding or removing another subdomain
/// changes nothing here (FNV-1a).
std::uint64_t name_hash(const std::string& name) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : name) h = (h ^ ch) * 1099511628211ull;
  return h;
}

/// The start-up insertions, in order, after the initial state (whose
/// particles they avoid).
void build_insertions(Build& b, Subdomain& sub, const json& sd, const std::string& base) {
  if (!sd.contains("insert")) return;
  const std::uint64_t hash = name_hash(sub.name());
  for (std::size_t q = 0; q < sd["insert"].size(); ++q) {
    const json& block = sd["insert"][q];
    const std::string where = idx(base + "/insert", q);
    try {
      const Inserter ins = make_inserter(b, block, sub, b.sim.seed * 1000003ull + hash + q);
      ParticleStore& st = sub.store();
      const InsertionCandidates c = request_insertion(*ins.model, ins.region, ins.seed, sub.coarse_grain(), &st,
                                                      b.sim.flow.max_particles, sub.periodic(),
                                                      ins.materials.mixture());
      st.reserve(st.size() + c.size());
      for (std::size_t p = 0; p < c.size(); ++p) {
        st.add(b.next_id++, c.x[p], c.y[p], c.z[p], c.r[p], ins.materials.density_of(c, p), ins.fixed,
               ins.materials.material_of(c, p));
        st.vx.back() = ins.velocity[0]; st.vy.back() = ins.velocity[1]; st.vz.back() = ins.velocity[2];
      }
      spdlog::info("subdomain '{}': inserted {} particles with '{}' ({})", sub.name(), c.size(), ins.registered->name,
                   where);
      if (c.size() == 0) spdlog::warn("subdomain '{}': {} inserted no particles", sub.name(), where);
    } catch (const PluginError& e) {
      b.ck.add(where, e.what());
    }
  }
}

/// Particles a subdomain will get during the run (a pour's, a coupled fine
/// level's): their size range and material, for its skin and time step.
struct PourProbe {
  double r_min, r_max;  ///< [m]
  double density;       ///< [kg/m^3]
  std::uint8_t material;
};

/// The pours: their model instances live for the run; one dry event per pour
/// (no particle present) gives the radii it will insert, appended to
/// `pour_radii` for the skin and the time step of a subdomain that starts empty.
void build_pours(Build& b, Subdomain& sub, const json& sd, const std::string& base,
                 std::vector<PourProbe>& pour_radii) {
  if (!sd.contains("pour")) return;
  const std::uint64_t hash = name_hash(sub.name());
  const double* gravity = b.sim.gravity;
  for (std::size_t q = 0; q < sd["pour"].size(); ++q) {
    const json& pb = sd["pour"][q];
    const std::string where = idx(base + "/pour", q);
    try {
      const Inserter ins = make_inserter(b, pb["insert"], sub, b.sim.seed * 1000003ull + hash + 7919ull * (q + 1));
      Pour p;
      p.where = where;
      p.subdomain = b.sim.subdomains.size();
      p.model = ins.model;
      p.region = ins.region;
      for (int a = 0; a < 3; ++a) p.velocity[a] = ins.velocity[a];
      p.fixed = ins.fixed;
      p.seed = ins.seed;
      p.materials = ins.materials;
      p.alpha = sub.coarse_grain();
      p.mass_rate = pb["mass_rate"].get<double>();
      if (pb.contains("total_mass")) p.total_mass = pb["total_mass"].get<double>();
      p.start = pb["start"].get<double>();
      if (pb.contains("end")) p.end = pb["end"].get<double>();
      if (pb.contains("interval")) {
        p.interval = pb["interval"].get<double>();
      } else {
        // no schema default: the time the inserted particles need to leave the region
        const double speed = std::sqrt(p.velocity[0] * p.velocity[0] + p.velocity[1] * p.velocity[1] +
                                       p.velocity[2] * p.velocity[2]);
        const double g = std::sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]);
        if (speed > 0) {
          const double u[3] = {p.velocity[0] / speed, p.velocity[1] / speed, p.velocity[2] / speed};
          p.interval = region_extent(p.region, u) / speed;
        } else if (g > 0) {
          const double u[3] = {gravity[0] / g, gravity[1] / g, gravity[2] / g};
          p.interval = std::sqrt(2.0 * region_extent(p.region, u) / g);
        } else {
          p.interval = 0.01;
        }
      }
      const InsertionCandidates c = request_insertion(*p.model, p.region, p.seed, p.alpha, nullptr,
                                                      b.sim.flow.max_particles, {}, p.materials.mixture());
      if (c.size() == 0) {
        b.ck.add(where + "/insert", "the insertion model placed no particle in the pour region",
                 "enlarge the region or raise the model's volume_fraction / count");
        continue;
      }
      // each component's size range (one for a single material)
      std::vector<PourProbe> probes(p.materials.material.size(), PourProbe{HUGE_VAL, 0.0, 0.0, 0});
      double one_event = 0;
      for (std::size_t q = 0; q < c.size(); ++q) {
        PourProbe& pp = probes[c.component.empty() ? 0 : c.component[q]];
        pp.r_min = std::min(pp.r_min, c.r[q]);
        pp.r_max = std::max(pp.r_max, c.r[q]);
        one_event += p.materials.density_of(c, q) * 4.0 / 3.0 * M_PI * c.r[q] * c.r[q] * c.r[q];
      }
      for (std::size_t k = 0; k < probes.size(); ++k)
        if (probes[k].r_max > 0) {
          probes[k].density = p.materials.density[k];
          probes[k].material = p.materials.material[k];
          pour_radii.push_back(probes[k]);
        }
      spdlog::info("subdomain '{}': pour {} inserts {:.4g} kg/s with '{}' every {:.4g} s (one full region: {} "
                   "particles, {:.4g} kg)",
                   sub.name(), where, p.mass_rate, ins.registered->name, p.interval, c.size(), one_event);
      if (one_event < p.mass_rate * p.interval)
        spdlog::warn("{}: one filled pour region ({:.3g} kg) holds less than the mass of one interval ({:.3g} kg); "
                     "the pour will fall behind its rate", where, one_event, p.mass_rate * p.interval);
      b.sim.flow.pours.push_back(std::move(p));
    } catch (const PluginError& e) {
      b.ck.add(where + "/insert", e.what());
    }
  }
}

/// The subdomain's time step, estimated and chosen or checked by
/// contact/time_step (with a pour's smallest particle present for the
/// estimate). False when the subdomain cannot run (reported).
bool set_time_step(Build& b, Subdomain& sub, const json& sd, const std::string& base,
                   const std::vector<PourProbe>& pour_radii, TimeStepReport& rep) {
  Checker& ck = b.ck;
  const std::string& sd_name = sub.name();
  const double v_imp = sd["impact_velocity"].get<double>();
  // the smallest particle of each material still to come, present only for
  // the estimate (the smallest particle sets the Rayleigh time)
  std::vector<const PourProbe*> smallest(sub.materials().size(), nullptr);
  for (const PourProbe& p : pour_radii)
    if (!smallest[p.material] || p.r_min < smallest[p.material]->r_min) smallest[p.material] = &p;
  std::size_t probes = 0;
  for (const PourProbe* p : smallest)
    if (p) {
      sub.store().add(0, 0.0, 0.0, 0.0, p->r_min, p->density, false, p->material);
      ++probes;
    }
  const bool probe_particle = probes > 0;
  try {
    rep = sub.estimate_time_step(v_imp);
  } catch (const PluginError& e) {
    ck.add(base + "/contact", std::string("the contact model failed while estimating the time step: ") + e.what());
    return false;
  }
  for (std::size_t k = 0; k < probes; ++k) sub.store().swap_remove(sub.store().size() - 1);
  const json& ts = sd["time_step"];
  const std::optional<double> given = ts.is_number() ? std::optional<double>(ts.get<double>()) : std::nullopt;
  if (const TimeStepProblem p =
          choose_time_step(sd_name, rep, given, sub.store().size() > 0 || probe_particle, v_imp)) {
    ck.add(base + "/time_step", p.message, p.hint);
    return false;
  }
  sub.set_time_step(rep.chosen);
  spdlog::info("subdomain '{}': {} particles, time step {:.4g} s ({}); Rayleigh time {:.4g} s, contact time {:.4g} s "
               "at {:.3g} m/s, stability limit {:.4g} s ({})",
               sd_name, sub.store().size(), rep.chosen, rep.reason, rep.rayleigh, rep.contact_time, v_imp,
               rep.critical, rep.critical_of);
  return true;
}

/// One subdomain: contact pipeline, particles (state file, insertions),
/// pours, neighbour skin, time step.
void build_subdomain(Build& b, std::size_t k) {
  const json& sd = b.doc["subdomains"][k];
  const std::string base = idx("/subdomains", k);
  const std::string sd_name = sd["name"].get<std::string>();
  const std::string mat_name = sd["material"].get<std::string>();
  const double alpha = sd["coarse_grain"].get<double>();
  const double density = b.sim.materials[b.mat_index.at(mat_name)].density;
  auto coefficients_of = [](const void* table, std::size_t x, std::size_t y) {
    const Build& bb = *static_cast<const Build*>(table);
    const std::string nx = bb.sim.materials[x].name, ny = bb.sim.materials[y].name;  // minmax binds references
    return bb.coeffs.at(std::minmax(nx, ny));
  };

  json used = json::object();
  auto pipeline = build_contact_pipeline(b, sd, base, used);
  if (!pipeline) return;
  b.sim.models_used[sd_name] = used;
  auto sub = std::make_unique<Subdomain>(sd_name, alpha, b.mat_index.at(mat_name), std::move(pipeline));
  // its materials: its own, then those of its insertions and pours, in order (a mixture)
  auto add_material = [&](const json& block) {
    for (const auto& [name, at] : insertion_material_names(block)) sub->local_material(b.mat_index.at(name));
  };
  if (sd.contains("insert"))
    for (const auto& block : sd["insert"]) add_material(block);
  if (sd.contains("pour"))
    for (const auto& pb : sd["pour"]) add_material(pb["insert"]);
  if (sd.contains("initial_state")) {  // a mixture's state file (v2) names its materials
    try {
      std::set<std::string> names;
      io::for_each_particle_state_row(scenario_path(b.file, sd["initial_state"].get<std::string>()),
                                      [&](const io::ParticleStateRow& p) { names.insert(p.material); });
      for (const auto& n : names)
        if (!n.empty() && b.mat_index.count(n)) sub->local_material(b.mat_index.at(n));
    } catch (const std::exception&) {
      // reported with its line by validation and build_initial_state()
    }
  }
  sub->set_environment(b.sim.materials, &b, coefficients_of, &b.sim.walls, b.sim.gravity);
  if (b.sim.gravity_schedule) sub->set_gravity(b.sim.gravity_schedule);

  PeriodicBox box;
  if (const json* per = member(sd, "periodic")) {
    for (int a = 0; a < 3; ++a) {
      const std::string ax(1, static_cast<char>('x' + a));
      if (!per->contains(ax)) continue;
      box.axis[a] = true;
      box.lo[a] = (*per)[ax][0].get<double>();
      box.hi[a] = (*per)[ax][1].get<double>();
    }
    sub->set_periodic(box);  // before the insertions: they keep clear of the images
  }
  const std::size_t problems_before_insert = b.ck.diags.size();
  build_initial_state(b, *sub, sd, base);
  build_insertions(b, *sub, sd, base);
  std::vector<PourProbe> pour_radii;
  build_pours(b, *sub, sd, base, pour_radii);
  if (b.ck.diags.size() > problems_before_insert) return;  // no time step from a half-built subdomain
  box.wrap(sub->store());  // a state file's positions past a face: inside, as the first list build would have them
  check_initial_particles(b, *sub, sd, base);
  // The fine level of a coupling starts empty: its particles will be its
  // parent's parcels at its own ratio, which set its skin and time step.
  bool coarse_listed = false;  // a self-coupling or an unknown name is build_couplings()'s to report
  if (auto it = b.parent.find(sd_name); it != b.parent.end() && it->second.first != sd_name) {
    for (const auto& other : b.doc["subdomains"]) coarse_listed = coarse_listed || other["name"] == it->second.first;
  }
  if (auto it = b.parent.find(sd_name); coarse_listed) {
    const auto pr = b.radii.find(it->second.first);
    if (pr == b.radii.end()) {
      b.ck.add(idx("/couplings", it->second.second) + "/coarse",
               "the coarse subdomain '" + it->second.first + "' must come before its fine subdomain '" + sd_name +
                   "' in /subdomains (the fine level's particle size follows from the coarse one's)");
      return;
    }
    double alpha_c = 1;
    for (const auto& other : b.doc["subdomains"])
      if (other["name"] == it->second.first) alpha_c = other["coarse_grain"].get<double>();
    if (pr->second[0] > 0)
      pour_radii.push_back({pr->second[0] * alpha / alpha_c, pr->second[1] * alpha / alpha_c, density, 0});
  }

  // neighbour skin: fraction of the largest diameter
  double rmax = 0;
  for (double r : sub->store().radius) rmax = std::max(rmax, r);
  for (const PourProbe& p : pour_radii) rmax = std::max(rmax, p.r_max);
  sub->set_skin(sd["skin"].get<double>() * 2.0 * (rmax > 0 ? rmax : 1e-3));
  for (int a = 0; a < 3; ++a) {
    const double cut = 2.0 * rmax + sub->skin();
    if (box.axis[a] && box.length(a) < 2.0 * cut)
      b.ck.add(base + "/periodic/" + std::string(1, static_cast<char>('x' + a)),
               "expected a period of at least twice the neighbour-list cut-off (largest diameter + skin = " +
                   fmt_num(cut) + " m), found " + fmt_num(box.length(a)) + " m",
               "lengthen the periodic box to " + fmt_num(2.0 * cut) + " m or more");
    // a periodic pipe reaches past both faces by half a skin: between list
    // rebuilds a particle may stand that far outside the box
    if (box.axis[a])
      for (const WallPrimitive& w : b.sim.walls)
        if (w.shape == WallPrimitive::Shape::cylinder_inside && w.axis == a &&
            (w.lo > box.lo[a] - 0.5 * sub->skin() || w.hi < box.hi[a] + 0.5 * sub->skin()))
          b.ck.add(idx("/walls", w.wall),
                   "a cylinder along the periodic axis " + std::string(1, static_cast<char>('x' + a)) + " of subdomain '" +
                       sd_name + "' that ends within half a skin (" + fmt_num(0.5 * sub->skin()) +
                       " m) of the periodic box",
                   "extend its bottom and top past the box by at least " + fmt_num(0.5 * sub->skin()) + " m");
  }
  {
    double rmin = rmax;
    for (double r : sub->store().radius) rmin = std::min(rmin, r);
    for (const PourProbe& p : pour_radii) rmin = std::min(rmin, p.r_min);
    b.radii[sd_name] = {rmin, rmax};
  }
  sub->set_reorder_every(sd["reorder_every"].get<std::size_t>());

  TimeStepReport rep;
  if (!set_time_step(b, *sub, sd, base, pour_radii, rep)) return;
  b.sim.time_steps.push_back(rep);
  b.sim.subdomains.push_back(std::move(sub));
}

/// The index of a subdomain named at `pointer`; an unknown name is reported
/// (with the nearest name) and gives kAllSubdomains.
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

/// Deletion regions, mass-flow planes and the run's deletion interval; the
/// flow registers its per-macro-step work on the simulation's hooks.
void build_particle_flow(Build& b) {
  ParticleFlow& flow = b.sim.flow;
  flow.next_id = b.next_id;
  flow.deletion_interval = b.doc["run"]["deletion_interval"].get<double>();
  if (b.doc.contains("deletion_regions"))
    for (std::size_t i = 0; i < b.doc["deletion_regions"].size(); ++i) {
      const json& d = b.doc["deletion_regions"][i];
      DeletionRegion dr;
      dr.name = d["name"].get<std::string>();
      if (d.contains("subdomain"))
        dr.subdomain = subdomain_index(b, d["subdomain"], idx("/deletion_regions", i) + "/subdomain");
      dr.region = make_region(d["region"]);
      if (d.contains("rate_window"))
        for (int a = 0; a < 2; ++a) dr.rate_window[a] = d["rate_window"][a].get<double>();
      flow.deletions.push_back(dr);
    }
  const json& out = b.doc["output"];
  if (out.contains("mass_flow"))
    for (std::size_t i = 0; i < out["mass_flow"].size(); ++i) {
      const json& d = out["mass_flow"][i];
      MassFlowPlane pl;
      pl.name = d["name"].get<std::string>();
      if (d.contains("subdomain"))
        pl.subdomain = subdomain_index(b, d["subdomain"], idx("/output/mass_flow", i) + "/subdomain");
      double len = 0;
      for (int a = 0; a < 3; ++a) {
        pl.p[a] = d["point"][a].get<double>();
        pl.n[a] = d["normal"][a].get<double>();
        len += pl.n[a] * pl.n[a];
      }
      for (int a = 0; a < 3; ++a) pl.n[a] /= std::sqrt(len);
      if (d.contains("rate_window"))
        for (int a = 0; a < 2; ++a) pl.rate_window[a] = d["rate_window"][a].get<double>();
      flow.planes.push_back(pl);
    }
  if (out.contains("region_mass"))
    for (std::size_t i = 0; i < out["region_mass"].size(); ++i) {
      const json& d = out["region_mass"][i];
      RegionMassProbe rm;
      rm.name = d["name"].get<std::string>();
      if (d.contains("subdomain"))
        rm.subdomain = subdomain_index(b, d["subdomain"], idx("/output/region_mass", i) + "/subdomain");
      rm.region = make_region(d["region"]);
      if (d.contains("max_speed")) rm.max_speed = d["max_speed"].get<double>();
      rm.centre_of_mass = d["centre_of_mass"].get<bool>();
      if (d.contains("material")) {
        const std::string m = d["material"].get<std::string>();
        if (auto it = b.mat_index.find(m); it != b.mat_index.end()) rm.material = it->second;
        else {
          std::vector<std::string> names;
          for (const auto& [n, k] : b.mat_index) names.push_back(n);
          b.ck.add(idx("/output/region_mass", i) + "/material", "unknown material '" + m + "'", suggest(m, names));
        }
      }
      for (const auto& other : b.out.region_mass)
        if (other.name == rm.name)
          b.ck.add(idx("/output/region_mass", i) + "/name", "duplicate region_mass name '" + rm.name + "'");
      for (const auto& pl : flow.planes)
        if (pl.name == rm.name)
          b.ck.add(idx("/output/region_mass", i) + "/name",
                   "region_mass name '" + rm.name + "' is also a mass_flow plane's: both would write " + rm.name +
                       ".mass_kg to probes.csv",
                   "rename one of them");
      b.out.region_mass.push_back(rm);
    }
}

/// The first rotation of scenario wall `wall`'s motion (null if it does not rotate).
const MotionItem* first_rotation_of(const std::vector<WallPrimitive>& walls, std::size_t wall) {
  for (const WallPrimitive& q : walls)
    if (q.wall == wall) return q.moving ? q.motion->first_rotation() : nullptr;
  return nullptr;
}

/// output.wall_loads (the probes and their torque axes) and output.contacts;
/// the contact files' interval is resolved by build_outputs().
void build_contact_outputs(Build& b) {
  const json& out = b.doc["output"];
  std::vector<WallLoadProbe> probes;
  if (out.contains("wall_loads"))
    for (std::size_t i = 0; i < out["wall_loads"].size(); ++i) {
      const json& d = out["wall_loads"][i];
      const std::string base = idx("/output/wall_loads", i);
      const std::string want = d["wall"].get<std::string>();
      const auto it = std::find(b.sim.wall_names.begin(), b.sim.wall_names.end(), want);
      if (it == b.sim.wall_names.end()) {
        b.ck.add(base + "/wall",
                 b.sim.wall_names.empty() ? "unknown wall '" + want + "': the scenario has no walls"
                                          : "unknown wall '" + want + "'",
                 suggest(want, b.sim.wall_names));
        continue;
      }
      WallLoadProbe p;
      p.wall = static_cast<std::size_t>(it - b.sim.wall_names.begin());
      p.name = d.contains("name") ? d["name"].get<std::string>() : want;
      if (d.contains("subdomain")) p.subdomain = subdomain_index(b, d["subdomain"], base + "/subdomain");
      const json& w = b.doc["walls"][p.wall];
      const std::string type = w["type"].get<std::string>();
      auto set_axis = [&p](const json& point, const double dir[3]) {
        p.has_axis = true;
        const double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (int a = 0; a < 3; ++a) {
          p.point[a] = point[a].get<double>();
          p.axis[a] = dir[a] / len;
        }
      };
      double dir[3] = {0, 0, 0};
      if (const json* ax = member(d, "axis")) {
        for (int a = 0; a < 3; ++a) dir[a] = (*ax)["direction"][a].get<double>();
        if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0) {
          b.ck.add(base + "/axis/direction", "expected a non-zero direction, found [0, 0, 0]");
          continue;
        }
        set_axis((*ax)["point"], dir);
      } else if (const MotionItem* rot = first_rotation_of(b.sim.walls, p.wall)) {
        // the (first) rotation's axis, through its origin (the default origin as the motion has it)
        for (int a = 0; a < 3; ++a) dir[a] = rot->vec[a];
        const json origin = {rot->origin[0], rot->origin[1], rot->origin[2]};
        set_axis(origin, dir);
      } else if (type == "cylinder" || type == "cone") {
        dir[axis_index(&w["axis"])] = 1.0;
        set_axis(w["center"], dir);
      } else if (type == "disk") {
        for (int a = 0; a < 3; ++a) dir[a] = w["normal"][a].get<double>();
        set_axis(w["center"], dir);
      }
      for (const auto& other : probes)
        if (other.name == p.name)
          b.ck.add(base + "/name", "duplicate wall_loads name '" + p.name + "': both would write " + p.name +
                                       ".force_x to probes.csv",
                   "give one of them a \"name\"");
      probes.push_back(p);
    }
  if (out.contains("contacts") && !out["contacts"].contains("interval") && out.contains("vtk_interval") &&
      out["vtk_interval"].get<double>() == 0)
    b.ck.add("/output/contacts", "expected an interval, found none while output.vtk_interval is 0 (no particle "
                                 "frames to follow)",
             "give output.contacts.interval");
  b.sim.contact_sample.configure(std::move(probes), out.contains("contacts"));
  b.out.wall_surfaces = out["wall_surfaces"].get<bool>();
}

/// The parent map of /couplings (fine -> coarse), read before the subdomains
/// are built: a coupled fine level takes its particle size from its parent.
void scan_couplings(Build& b) {
  if (!b.doc.contains("couplings")) return;
  const json& cs = b.doc["couplings"];
  for (std::size_t c = 0; c < cs.size(); ++c) {
    const std::string fine = cs[c]["fine"].get<std::string>();
    if (b.parent.count(fine) != 0) {
      b.ck.add(idx("/couplings", c) + "/fine", "subdomain '" + fine + "' is already the fine level of " +
                                                   idx("/couplings", b.parent[fine].second) +
                                                   "; a level has one parent (nest a third level under it instead)");
      continue;
    }
    b.parent[fine] = {cs[c]["coarse"].get<std::string>(), c};
  }
}

/// True when `level` is a finer level of `ancestor` through the parent map
/// of /couplings (a loop in the map ends the walk).
bool descends_from(const Build& b, const std::string& level, const std::string& ancestor) {
  std::string up = level;
  for (std::size_t hops = 0; hops <= b.parent.size(); ++hops) {
    const auto it = b.parent.find(up);
    if (it == b.parent.end()) return false;
    up = it->second.first;
    if (up == ancestor) return true;
  }
  return false;
}

bool walls_and_regions_bounds(Build& b, double lo[3], double hi[3], bool all);

/// Bounding box of a top-level domain: when the walls enclose a finite
/// region (a cylinder, a cone or a mesh), their bounding box together with
/// the pour, insertion and deletion regions (particles fall out of an outlet
/// into a deletion region). False with planes alone: the domain is unbounded.
bool domain_bounds(Build& b, double lo[3], double hi[3]) {
  bool enclosed = false;
  for (const auto& w : b.sim.walls)
    enclosed = enclosed || w.shape == WallPrimitive::Shape::cylinder_inside ||
               w.shape == WallPrimitive::Shape::cone_inside || w.shape == WallPrimitive::Shape::mesh;
  if (!enclosed) return false;
  return walls_and_regions_bounds(b, lo, hi, false);
}

/// The box of the enclosing walls (mantles, meshes) and of every region
/// (deletion, pour, insertion); with `all`, also of every other finite wall
/// (disks, a box's faces, a container's bottom) and a plane's point.
bool walls_and_regions_bounds(Build& b, double lo[3], double hi[3], bool all) {
  bool any = false;
  auto grow = [&](const double a[3], const double z[3]) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = any ? std::min(lo[k], a[k]) : a[k];
      hi[k] = any ? std::max(hi[k], z[k]) : z[k];
    }
    any = true;
  };
  auto grow_region = [&](const domel_region_v1& r) {
    double a[3], z[3];
    region_box(r, a, z);
    grow(a, z);
  };
  for (const auto& w : b.sim.walls) {
    double a[3], z[3];
    if (w.shape == WallPrimitive::Shape::cylinder_inside || w.shape == WallPrimitive::Shape::cone_inside) {
      const double r = std::max(w.radius, w.radius_hi);
      for (int k = 0; k < 3; ++k) {
        a[k] = k == w.axis ? w.lo : w.c[k] - r;
        z[k] = k == w.axis ? w.hi : w.c[k] + r;
      }
      grow(a, z);
    } else if (w.shape == WallPrimitive::Shape::mesh && w.verts.size() >= 3) {
      for (int k = 0; k < 3; ++k) a[k] = z[k] = w.verts[k];
      for (std::size_t v = 0; v + 2 < w.verts.size(); v += 3)
        for (int k = 0; k < 3; ++k) a[k] = std::min(a[k], w.verts[v + k]), z[k] = std::max(z[k], w.verts[v + k]);
      grow(a, z);
    } else if (all && w.shape == WallPrimitive::Shape::plane && w.draw_in_box) {
      grow(w.draw_lo, w.draw_hi);
    } else if (all) {  // a plane's point; a disk or a container's bottom as far as it is drawn
      const double r = w.shape == WallPrimitive::Shape::annulus && std::isfinite(w.r_outer) ? w.r_outer
                                                                                             : w.draw_radius;
      for (int k = 0; k < 3; ++k) {
        a[k] = w.p[k] - r;
        z[k] = w.p[k] + r;
      }
      grow(a, z);
    }
  }
  if (b.doc.contains("deletion_regions"))
    for (const auto& d : b.doc["deletion_regions"]) grow_region(make_region(d["region"]));
  for (const auto& p : b.sim.flow.pours) grow_region(p.region);
  for (const auto& sd : b.doc["subdomains"])
    if (sd.contains("insert"))
      for (const auto& ins : sd["insert"])
        if (ins.contains("region")) grow_region(make_region(ins["region"]));
  return any;
}

/// Subdomains never touch each other's particles: two that share space
/// without a coupling between them (directly or through other levels) are
/// most likely a mixture written as two subdomains, whose particles pass
/// through each other. Warned, not refused: overlaid independent runs (a
/// parameter study in one file) are legitimate.
void warn_shared_space(Build& b) {
  const auto& sds = b.sim.subdomains;
  const std::size_t n = sds.size();
  // coupled families (union-find over the couplings' levels)
  std::vector<std::size_t> root(n);
  for (std::size_t k = 0; k < n; ++k) root[k] = k;
  auto find = [&](std::size_t k) {
    while (root[k] != k) k = root[k] = root[root[k]];
    return k;
  };
  auto index_of = [&](const json& name) {
    for (std::size_t k = 0; k < n; ++k)
      if (sds[k]->name() == name.get<std::string>()) return k;
    return n;
  };
  if (b.doc.contains("couplings"))
    for (const auto& c : b.doc["couplings"]) {
      const std::size_t x = index_of(c["coarse"]), y = index_of(c["fine"]);
      if (x < n && y < n) root[find(x)] = find(y);
    }
  // each subdomain's box: its particles at the start and its pour regions
  std::vector<std::array<double, 6>> box(n);
  std::vector<bool> any(n, false);
  auto grow = [&](std::size_t k, const double lo[3], const double hi[3]) {
    for (int a = 0; a < 3; ++a) {
      box[k][a] = any[k] ? std::min(box[k][a], lo[a]) : lo[a];
      box[k][3 + a] = any[k] ? std::max(box[k][3 + a], hi[a]) : hi[a];
    }
    any[k] = true;
  };
  for (std::size_t k = 0; k < n; ++k) {
    const ParticleStore& s = sds[k]->store();
    for (std::size_t q = 0; q < s.size(); ++q) {
      const double lo[3] = {s.x[q] - s.radius[q], s.y[q] - s.radius[q], s.z[q] - s.radius[q]};
      const double hi[3] = {s.x[q] + s.radius[q], s.y[q] + s.radius[q], s.z[q] + s.radius[q]};
      grow(k, lo, hi);
    }
  }
  for (const auto& p : b.sim.flow.pours) {
    double lo[3], hi[3];
    region_box(p.region, lo, hi);
    if (p.subdomain < n) grow(p.subdomain, lo, hi);
  }
  for (std::size_t x = 0; x < n; ++x)
    for (std::size_t y = x + 1; y < n; ++y) {
      if (!any[x] || !any[y] || find(x) == find(y)) continue;
      bool overlap = true;
      for (int a = 0; a < 3; ++a)
        overlap = overlap && box[x][a] < box[y][3 + a] && box[y][a] < box[x][3 + a];
      if (overlap)
        spdlog::warn("subdomains '{}' and '{}' share space but no coupling joins them: subdomains never touch, so "
                     "their particles pass through each other; for a mixture use several materials in one subdomain "
                     "(an insertion's \"material\", docs/getting-started.md, \"Mixtures\")",
                     sds[x]->name(), sds[y]->name());
    }
}

/// The scene's box for drawing walls (output.wall_surfaces): the walls, the
/// regions and the particles at the start, padded by 5 % of its diagonal (a
/// plane alone: 1 m about its point).
void scene_bounds(Build& b) {
  Simulation& sim = b.sim;
  double lo[3], hi[3];
  bool any = walls_and_regions_bounds(b, lo, hi, true);
  for (const auto& sd : sim.subdomains) {
    const ParticleStore& s = sd->store();
    for (std::size_t k = 0; k < s.size(); ++k) {
      const double x[3] = {s.x[k], s.y[k], s.z[k]};
      for (int a = 0; a < 3; ++a) {
        lo[a] = any ? std::min(lo[a], x[a] - s.radius[k]) : x[a] - s.radius[k];
        hi[a] = any ? std::max(hi[a], x[a] + s.radius[k]) : x[a] + s.radius[k];
      }
      any = true;
    }
  }
  if (!any)
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = 0.0;
  double diag = 0;
  for (int a = 0; a < 3; ++a) diag += (hi[a] - lo[a]) * (hi[a] - lo[a]);
  const double pad = diag > 0 ? 0.05 * std::sqrt(diag) : 0.5;
  for (int a = 0; a < 3; ++a) {
    b.out.scene_lo[a] = lo[a] - pad;
    b.out.scene_hi[a] = hi[a] + pad;
  }
}

/// /couplings: levels, region and cells, faces, timing, controllers.
void build_couplings(Build& b) {
  if (!b.doc.contains("couplings")) return;
  const json& cs = b.doc["couplings"];
  Simulation& sim = b.sim;
  const double macro = sim.macro_step();
  std::vector<std::string> names;
  for (const auto& sd : sim.subdomains) names.push_back(sd->name());
  std::vector<CouplingSpec> specs;
  std::vector<int> requested;  // control_steps of each
  std::vector<const json*> blocks;
  for (std::size_t c = 0; c < cs.size(); ++c) {
    const json& cj = cs[c];
    const std::string base = idx("/couplings", c);
    const std::size_t before = b.ck.diags.size();
    CouplingSpec s;
    s.name = cj["name"].get<std::string>();
    s.where = base;
    for (std::size_t h = 0; h < c; ++h)
      if (cs[h]["name"] == cj["name"]) b.ck.add(base + "/name", "duplicate coupling name '" + s.name + "'");
    if (s.name.find('/') != std::string::npos) b.ck.add(base + "/name", "a coupling name names files: no '/'");
    s.coarse = subdomain_index(b, cj["coarse"], base + "/coarse");
    s.fine = subdomain_index(b, cj["fine"], base + "/fine");
    if (b.ck.diags.size() > before) continue;
    if (b.parent.at(names[s.fine]).second != c) continue;  // a second parent, refused by scan_couplings
    if (s.coarse == s.fine) {
      b.ck.add(base + "/fine", "subdomain '" + names[s.fine] + "' is coupled to itself",
               "a coupling joins a coarse subdomain and a finer one");
      continue;
    }
    // the coupling inserts, counts and controls one material: a mixture's levels are not coupled (yet)
    bool mixture = false;
    for (std::size_t k : {s.coarse, s.fine})
      if (sim.subdomains[k]->materials().size() > 1) {
        b.ck.add(base + (k == s.coarse ? "/coarse" : "/fine"),
                 "subdomain '" + names[k] + "' holds several materials (a mixture); a coupling joins levels of "
                 "one material each",
                 "couple levels of one material, or run the mixture in one subdomain without a coupling");
        mixture = true;
      }
    if (mixture) continue;
    Subdomain& coarse = *sim.subdomains[s.coarse];
    Subdomain& fine = *sim.subdomains[s.fine];
    if (fine.coarse_grain() >= coarse.coarse_grain()) {
      b.ck.add(base + "/fine", "expected a fine level with a smaller coarse-grain ratio than the coarse level's " +
                                   fmt_num(coarse.coarse_grain()) + ", found '" + names[s.fine] + "' at " +
                                   fmt_num(fine.coarse_grain()));
      continue;
    }
    // a cycle: the coarse level descends from the fine one
    if (descends_from(b, names[s.coarse], names[s.fine]))
      b.ck.add(base + "/coarse", "the couplings form a loop: '" + names[s.coarse] + "' is itself a finer level of '" +
                                     names[s.fine] + "'");
    if (b.ck.diags.size() > before) continue;
    // region and cells
    const json& rj = cj["region"];
    const double d_coarse = 2 * b.radii.at(names[s.coarse])[1];
    s.grid.name = s.name;
    bool box = true;
    bool cells_ok = true;
    for (int a = 0; a < 3; ++a) {
      s.grid.lo[a] = rj["min"][a].get<double>();
      s.grid.hi[a] = rj["max"][a].get<double>();
      s.grid.cells[a] = rj["cells"][a].get<int>();
      if (s.grid.hi[a] <= s.grid.lo[a]) {
        box = false;
        b.ck.add(base + "/region/max/" + std::to_string(a), "expected max > min along " + std::string(1, "xyz"[a]) +
                                                                ", found max " + fmt_num(s.grid.hi[a]) + " <= min " +
                                                                fmt_num(s.grid.lo[a]));
        continue;
      }
      const double edge = (s.grid.hi[a] - s.grid.lo[a]) / s.grid.cells[a];
      if (edge < 2 * d_coarse * (1 - 1e-9)) {
        cells_ok = false;
        b.ck.add(base + "/region/cells/" + std::to_string(a),
                 "expected cells of at least 2 coarse parcel diameters (" + fmt_num(2 * d_coarse) + " m) along " +
                     std::string(1, "xyz"[a]) + ", found " + fmt_num(edge) + " m",
                 "use at most " + std::to_string(std::max(1, static_cast<int>((s.grid.hi[a] - s.grid.lo[a]) /
                                                                               (2 * d_coarse)))) +
                     " cells along " + std::string(1, "xyz"[a]));
      }
    }
    if (!box || !cells_ok) continue;
    const double n_region_cells = static_cast<double>(s.grid.cells[0]) * s.grid.cells[1] * s.grid.cells[2];
    if (n_region_cells > static_cast<double>(kMaxGridCells)) {
      b.ck.add(base + "/region/cells", "the region has " + fmt_num(n_region_cells) + " cells, more than the " +
                                           std::to_string(kMaxGridCells) + " a grid may have",
               "use fewer, larger cells");
      continue;
    }
    // inside the coarse level's domain
    if (auto it = b.parent.find(names[s.coarse]); it != b.parent.end()) {
      const json& pr = cs[it->second.second]["region"];
      for (int a = 0; a < 3; ++a)
        if (s.grid.lo[a] < pr["min"][a].get<double>() - 1e-12 || s.grid.hi[a] > pr["max"][a].get<double>() + 1e-12) {
          b.ck.add(base + "/region", "the fine region lies outside the coarse level's domain: '" + names[s.coarse] +
                                         "' lives only in the region of " + idx("/couplings", it->second.second) +
                                         ", and this region leaves it along " + std::string(1, "xyz"[a]));
          break;
        }
    } else {
      double lo[3], hi[3];
      if (domain_bounds(b, lo, hi))
        for (int a = 0; a < 3; ++a)
          if (s.grid.lo[a] < lo[a] - 1e-12 || s.grid.hi[a] > hi[a] + 1e-12) {
            b.ck.add(base + "/region", "the fine region lies outside the coarse level's domain along " +
                                           std::string(1, "xyz"[a]) + ": [" + fmt_num(s.grid.lo[a]) + ", " +
                                           fmt_num(s.grid.hi[a]) + "] m against [" + fmt_num(lo[a]) + ", " +
                                           fmt_num(hi[a]) + "] m (the walls, pour, insertion and deletion regions)");
            break;
          }
    }
    // two fine regions that overlap (a nested region lies inside its parent's, which is fine)
    for (std::size_t h = 0; h < specs.size(); ++h) {
      const CouplingSpec& o = specs[h];
      const bool nested = descends_from(b, names[s.fine], names[o.fine]) || descends_from(b, names[o.fine], names[s.fine]);
      bool overlap = true;
      for (int a = 0; a < 3; ++a) overlap = overlap && s.grid.lo[a] < o.grid.hi[a] && o.grid.lo[a] < s.grid.hi[a];
      if (overlap && !nested)
        b.ck.add(base + "/region", "this fine region overlaps the one of " + o.where +
                                       "; fine regions side by side must not overlap (nest one inside the other's "
                                       "level instead)");
    }
    // faces
    for (const auto& f : cj["inflow_faces"]) s.inflow[face_from_name(f.get<std::string>())] = true;
    s.shell_depth = cj.contains("shell_depth") ? cj["shell_depth"].get<double>() : 2 * d_coarse;
    for (int face = 0; face < kFaces; ++face)
      if (s.inflow[face] && s.shell_depth > s.grid.hi[face / 2] - s.grid.lo[face / 2])
        b.ck.add(base + (cj.contains("shell_depth") ? "/shell_depth" : "/region"),
                 "the insertion shell (" + fmt_num(s.shell_depth) + " m) is deeper than the region along " +
                     std::string(1, "xyz"[face / 2]));
    s.fill_target = cj["fill_target"].get<double>();
    s.attempts = cj["insertion_attempts"].get<int>();
    s.grid_interval = cj["grid_interval"].get<double>();
    s.match_outflow = cj["match_outflow"].get<bool>();
    s.fine_density = sim.materials[fine.material()].density;
    s.alpha_ratio = fine.coarse_grain() / coarse.coarse_grain();
    // one seed per coupling: the run's seed and the coupling's index mixed as the pours' seeds are
    s.seed = sim.seed * 6364136223846793005ull + (c + 1) * 1442695040888963407ull;
    requested.push_back(cj["control_steps"].get<int>());
    specs.push_back(std::move(s));
    blocks.push_back(&cj);
  }
  if (specs.size() != cs.size()) return;
  // One control clock for every coupling (several couplings add their forces
  // into the same level): the most frequent request, in whole macro steps.
  std::uint64_t control_macro = std::numeric_limits<std::uint64_t>::max();
  for (std::size_t c = 0; c < specs.size(); ++c) {
    const int n_f = substeps_of(macro, sim.subdomains[specs[c].fine]->time_step());
    control_macro = std::min<std::uint64_t>(control_macro, (requested[c] + n_f - 1) / n_f);
  }
  sim.control_macro = control_macro;
  for (std::size_t c = 0; c < specs.size(); ++c) {
    CouplingSpec& s = specs[c];
    const json& cj = *blocks[c];
    const std::string base = s.where;
    const int n_f = substeps_of(macro, sim.subdomains[s.fine]->time_step());
    const int n_c = substeps_of(macro, sim.subdomains[s.coarse]->time_step());
    s.control_macro = control_macro;
    s.fine_steps = static_cast<int>(control_macro) * n_f;
    s.coarse_steps = static_cast<int>(control_macro) * n_c;
    if (s.fine_steps != requested[c])
      spdlog::info("{}: control interval {} fine steps (asked {}): {} macro step(s) of {:.4g} s, the coarsest level's "
                   "step, so that every exchange falls on a step of every level",
                   base, s.fine_steps, requested[c], control_macro, macro);
    const int tmax = cj["transfer_max_steps"].get<int>();
    s.transfer_controls = std::max<std::uint64_t>(1, (tmax + s.fine_steps - 1) / s.fine_steps);
    const double dt_f = macro / n_f, dt_c = macro / n_c;
    const std::size_t n_cells = static_cast<std::size_t>(s.grid.cells[0]) * s.grid.cells[1] * s.grid.cells[2];
    std::size_t block_before = b.ck.diags.size();
    auto controller = [&](const char* key, ControllerSetup& setup, json params) {
      const json& blk = cj[key];
      setup.enabled = blk["enabled"].get<bool>();
      if (!setup.enabled) return;
      const std::string model = blk["model"].get<std::string>();
      const RegisteredModel* m = b.registry.find(DOMEL_KIND_CONTROLLER, model);
      if (m == nullptr) {
        b.ck.add(base + "/" + key + "/model", "unknown controller model '" + model + "'",
                 suggest(model, b.registry.names(DOMEL_KIND_CONTROLLER)));
        setup.enabled = false;
        return;
      }
      if (b.ck.diags.size() > block_before) {  // the block's own problems are reported; the model is not asked
        setup.enabled = false;
        return;
      }
      for (const auto& c : params["cells"])
        if (c.get<std::size_t>() >= n_cells)
          b.ck.add(base + "/" + key + "/cells", "expected cell indices below " + std::to_string(n_cells) +
                                                    " (the region's cells), found " + std::to_string(c.get<std::size_t>()));
      try {
        setup.model = std::make_shared<ModelInstance>(*m, params, base + "/" + key);
        setup.params = params;
      } catch (const PluginError& e) {
        b.ck.add(base + "/" + key, e.what());
        setup.enabled = false;
      }
    };
    // stress control: default cells touch an inflow face; direction: the inward normals
    {
      block_before = b.ck.diags.size();
      const json& blk = cj["stress_control"];
      json cells = json::array(), dirs = json::array();
      if (blk.contains("cells")) {
        cells = blk["cells"];
        if (blk.contains("directions")) dirs = blk["directions"];
        if (dirs.size() != cells.size())
          b.ck.add(base + "/stress_control/directions",
                   "expected one direction per controlled cell (" + std::to_string(cells.size()) + "), found " +
                       std::to_string(dirs.size()));
      } else {
        for (int iz = 0; iz < s.grid.cells[2]; ++iz)
          for (int iy = 0; iy < s.grid.cells[1]; ++iy)
            for (int ix = 0; ix < s.grid.cells[0]; ++ix) {
              const int i3[3] = {ix, iy, iz};
              int dir[3] = {0, 0, 0};
              bool touches = false;
              for (int face = 0; face < kFaces; ++face) {
                const int a = face / 2;
                const bool at = face % 2 == 0 ? i3[a] == 0 : i3[a] == s.grid.cells[a] - 1;
                if (!s.inflow[face] || !at) continue;
                touches = true;
                dir[a] += face % 2 == 0 ? 1 : -1;  // inward: away from the face
              }
              if (!touches) continue;
              cells.push_back(ix + s.grid.cells[0] * (iy + s.grid.cells[1] * iz));
              dirs.push_back({dir[0], dir[1], dir[2]});
            }
      }
      for (std::size_t k = 0; k < dirs.size(); ++k)
        for (int a = 0; a < 3; ++a) {
          const double v = dirs[k][a].get<double>();
          if (v != -1 && v != 0 && v != 1)
            b.ck.add(base + "/stress_control/directions/" + std::to_string(k) + "/" + std::to_string(a),
                     "expected -1, 0 or 1, found " + fmt_num(v));
        }
      json p = {{"cells", cells},
                {"directions", dirs},
                {"kp", blk.contains("kp") ? blk["kp"].get<double>() : 1.0 / s.fine_steps},
                {"ki", blk.contains("ki") ? blk["ki"].get<double>() : 1.0 / (s.fine_steps * dt_f)},
                {"layer_diameters", blk["layer_diameters"]},
                {"fade_fraction", blk["fade_fraction"]},
                {"velocity_limit", blk["velocity_limit"]},
                // one fine step ahead: the reference's per-step prediction, without the contact force the view lacks
                {"limit_horizon", dt_f}};
      controller("stress_control", s.stress, p);
    }
    {
      block_before = b.ck.diags.size();
      const json& blk = cj["velocity_control"];
      json cells = json::array();
      if (blk.contains("cells")) cells = blk["cells"];
      else
        for (std::size_t k = 0; k < n_cells; ++k) cells.push_back(k);
      json p = {{"cells", cells},
                {"kp", blk.contains("kp") ? blk["kp"].get<double>() : 1.0 / s.coarse_steps},
                {"ki", blk["ki"]},
                {"time_step", dt_c},
                {"mass_flow_correction", json::array()},
                {"velocity_limit", blk["velocity_limit"]}};
      for (std::size_t k = 0; k < cells.size(); ++k) p["mass_flow_correction"].push_back(blk["mass_flow_correction"]);
      controller("velocity_control", s.velocity, p);
    }
    sim.subdomains[s.fine]->store().enable_external_force();
    sim.subdomains[s.coarse]->store().enable_external_force();
    sim.couplings.push_back(std::make_unique<Coupling>(std::move(s)));
  }
  sim.flow.expect_external();
}

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

/// fluid: the fluid_coupler instance, the levels that share the fluid and
/// the coupling interval in whole macro steps. The FluidCoupling itself is
/// made once the outputs are known (its default write interval).
std::optional<FluidSpec> build_fluid(Build& b) {
  if (!b.doc.contains("fluid")) return std::nullopt;
  const json& fj = b.doc["fluid"];
  Simulation& sim = b.sim;
  FluidSpec spec;
  const std::string model = fj["model"].get<std::string>();
  const RegisteredModel* m = b.registry.find(DOMEL_KIND_FLUID_COUPLER, model);
  if (m == nullptr) return std::nullopt;  // check_models reported it
  std::vector<std::string> names;
  for (const auto& sd : sim.subdomains) names.push_back(sd->name());
  if (fj.contains("subdomains")) {
    const json& list = fj["subdomains"];
    for (std::size_t q = 0; q < list.size(); ++q) {
      const std::string want = list[q].get<std::string>();
      const auto it = std::find(names.begin(), names.end(), want);
      if (it == names.end()) {
        b.ck.add(idx("/fluid/subdomains", q), "unknown subdomain '" + want + "'", suggest(want, names));
        continue;
      }
      const std::size_t k = static_cast<std::size_t>(it - names.begin());
      if (std::find(spec.levels.begin(), spec.levels.end(), k) != spec.levels.end())
        b.ck.add(idx("/fluid/subdomains", q), "subdomain '" + want + "' is listed twice");
      else
        spec.levels.push_back(k);
    }
  } else {
    for (std::size_t k = 0; k < names.size(); ++k) spec.levels.push_back(k);
  }
  const double macro = sim.macro_step();
  const double asked = fj["interval"].get<double>();
  spec.interval_macro = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(asked / macro)));
  spec.interval = static_cast<double>(spec.interval_macro) * macro;
  if (std::abs(spec.interval - asked) > 1e-9 * asked)
    spdlog::info("/fluid/interval: coupling interval {:.6g} s (asked {:.6g} s): {} macro step(s) of {:.4g} s, so "
                 "that every exchange falls on a step of every level",
                 spec.interval, asked, spec.interval_macro, macro);
  spec.write_interval = fj.contains("write_interval") ? fj["write_interval"].get<double>() : -1.0;
  for (int d = 0; d < 3; ++d) spec.gravity[d] = sim.gravity[d];
  try {
    spec.model = std::make_shared<ModelInstance>(*m, plugin_params(fj, DOMEL_KIND_FLUID_COUPLER), "/fluid");
  } catch (const PluginError& e) {
    b.ck.add("/fluid", e.what());
    return std::nullopt;
  }
  // The coupler's limit from its initial state (inlet velocities, grid): an
  // interval above it is refused before anything runs.
  try {
    domel_fluid_limits_v1 lim{};
    if (spec.model->fluid_limits(lim) && lim.max_interval > 0 && spec.interval > lim.max_interval * (1 + 1e-9))
      b.ck.add("/fluid/interval",
               "expected a coupling interval of at most " + fmt_num(lim.max_interval) + " s (" +
                   (lim.limit ? lim.limit : "the coupler's stability limit") + "), found " + fmt_num(spec.interval) +
                   " s",
               "shorten the interval, or let the coupler sub-step its fluid if it can");
  } catch (const PluginError& e) {
    b.ck.add("/fluid", e.what());
  }
  // The coupler's grid (from its fields, when it reports them) must hold
  // where the particles start: every insertion and pour region of its
  // levels, and the walls' box when they enclose the domain.
  try {
    domel_fluid_fields_v1 f{};
    if (spec.model->fluid_fields(f) && f.nx > 0 && f.ny > 0 && f.nz > 0) {
      const double glo[3] = {f.origin[0], f.origin[1], f.origin[2]};
      const double ghi[3] = {f.origin[0] + f.nx * f.spacing[0], f.origin[1] + f.ny * f.spacing[1],
                             f.origin[2] + f.nz * f.spacing[2]};
      auto check = [&](const double lo[3], const double hi[3], const std::string& what) {
        for (int a = 0; a < 3; ++a)
          if (lo[a] < glo[a] - 1e-12 || hi[a] > ghi[a] + 1e-12) {
            b.ck.add("/fluid", "the fluid grid [" + fmt_num(glo[a]) + ", " + fmt_num(ghi[a]) + "] m along " +
                                   std::string(1, "xyz"[a]) + " does not cover " + what + " ([" + fmt_num(lo[a]) +
                                   ", " + fmt_num(hi[a]) + "] m)",
                     "enlarge the coupler's grid to the particles' whole domain");
            return;
          }
      };
      for (std::size_t k : spec.levels) {
        const json& sd = b.doc["subdomains"][k];
        const std::string base = idx("/subdomains", k);
        double lo[3], hi[3];
        if (sd.contains("insert"))
          for (std::size_t q = 0; q < sd["insert"].size(); ++q)
            if (sd["insert"][q].contains("region")) {
              region_box(make_region(sd["insert"][q]["region"]), lo, hi);
              check(lo, hi, "the insertion region " + idx(base + "/insert", q));
            }
        if (sd.contains("pour"))
          for (std::size_t q = 0; q < sd["pour"].size(); ++q) {
            region_box(make_region(sd["pour"][q]["insert"]["region"]), lo, hi);
            check(lo, hi, "the pour region " + idx(base + "/pour", q));
          }
      }
      bool enclosed = false;
      for (const auto& w : sim.walls)
        enclosed = enclosed || w.shape == WallPrimitive::Shape::cylinder_inside ||
                   w.shape == WallPrimitive::Shape::cone_inside || w.shape == WallPrimitive::Shape::mesh;
      double lo[3], hi[3];
      const bool deletions = b.doc.contains("deletion_regions") && !b.doc["deletion_regions"].empty();
      if (enclosed && !deletions && domain_bounds(b, lo, hi))
        check(lo, hi, "the walls' domain");
    }
  } catch (const PluginError& e) {
    b.ck.add("/fluid", e.what());
  }
  spec.one_level_per_call = b.registry.libraries()[m->library].abi_minor < 2;
  spec.used = {{"model", model},
               {"version", m->version},
               {"library", b.registry.libraries()[m->library].name},
               {"library_version", b.registry.libraries()[m->library].version}};
  return spec;
}

void build_outputs(Build& b) {
  Simulation& sim = b.sim;
  const json& run = b.doc["run"];
  if (run.contains("duration")) {
    sim.duration = run["duration"].get<double>();
  } else {
    sim.duration = static_cast<double>(run["steps"].get<std::uint64_t>()) * sim.macro_step();
  }
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

/// subdomains[].rank_share: on every subdomain or on none.
void build_rank_shares(Build& b) {
  const json& sds = b.doc["subdomains"];
  std::size_t given = 0, first_given = 0, first_missing = 0;
  for (std::size_t k = sds.size(); k-- > 0;) {
    if (member(sds[k], "rank_share")) ++given, first_given = k;
    else first_missing = k;
  }
  if (given == 0) return;
  if (given != sds.size()) {
    b.ck.add(idx("/subdomains", first_missing),
             "has no rank_share, while subdomain '" + sds[first_given]["name"].get<std::string>() + "' (" +
                 idx("/subdomains", first_given) + "/rank_share) has one: the levels' rank groups need a share "
                 "for every subdomain",
             "give every subdomain a rank_share, or remove them all (every subdomain spread over all ranks)");
    return;
  }
  for (const json& sd : sds) b.sim.rank_shares.push_back(sd["rank_share"].get<double>());
}

}  // namespace

std::unique_ptr<Simulation> build(const json& doc, const std::filesystem::path& file, PluginRegistry& registry) {
  auto sim = std::make_unique<Simulation>();
  sim->scenario_file = file;
  Build b{doc, file, registry, *sim, Checker{file, {}}, {}, {}, 1};
  build_materials(b);
  build_walls(b);
  build_run(b);
  scan_couplings(b);
  for (std::size_t k = 0; k < doc["subdomains"].size(); ++k) build_subdomain(b, k);
  build_rank_shares(b);
  if (b.sim.subdomains.size() == doc["subdomains"].size()) build_couplings(b);
  build_particle_flow(b);
  if (b.ck.diags.empty()) warn_shared_space(b);
  build_grids(b);
  build_repose_probe(b);
  build_contact_outputs(b);
  std::optional<FluidSpec> fluid = build_fluid(b);
  if (!b.ck.diags.empty()) throw ConfigError(b.ck.diags);
  build_outputs(b);
  if (fluid) {
    if (fluid->write_interval < 0) fluid->write_interval = b.out.vtk_interval;
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
