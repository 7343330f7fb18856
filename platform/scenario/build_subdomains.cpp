// SPDX-License-Identifier: MIT
// The builder of each subdomain: its contact pipeline, initial state (a
// state file or particles), start-up insertions, pours, skin and time step;
// and the subdomains' rank shares (build.hpp).
#include "scenario/build.hpp"

#include "geometry/region.hpp"
#include "loop/macro_step.hpp"
#include "geometry/wall_clearance.hpp"
#include "io/particle_state.hpp"
#include "subdomain/diagnostics.hpp"
#include "scenario/scenario.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace domel::platform::scenario_detail {

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

/// The starting particles (but the fixed ones) against the walls at the start: overlaps
/// delta / R above `limit` (run.max_initial_overlap) refused naming the
/// particle and the wall, smaller ones reported (a settled state file rests
/// on its walls).
void check_initial_wall_overlaps(Build& b, const ParticleStore& s, const json& sd, const std::string& name,
                                 const std::string& source, double limit) {
  if (b.sim.walls.empty() || s.size() == 0) return;
  double r_max = 0;
  for (double r : s.radius) r_max = std::max(r_max, r);
  const WallClearance clearance(b.sim.walls, 0.0, r_max);
  struct Hit {
    std::uint64_t id;
    std::size_t wall;
    double ratio;
  };
  std::vector<Hit> above;
  std::size_t touching = 0;
  Hit worst{0, 0, 0.0};
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (s.fixed(k)) continue;  // never moved, no wall force: a rough floor may stand in a wall
    const double p[3] = {s.x[k], s.y[k], s.z[k]};
    std::size_t w = 0;
    const double delta = clearance.overlap(p, s.radius[k], &w);
    if (delta <= 0) continue;
    ++touching;
    const Hit h{s.id[k], w, delta / s.radius[k]};
    if (h.ratio > worst.ratio) worst = h;
    if (h.ratio > limit) above.push_back(h);
  }
  auto wall_name = [&](std::size_t w) {
    return "'" + b.sim.walls[w].name + "' (" + idx("/walls", b.sim.walls[w].wall) + ")";
  };
  if (touching > 0)
    spdlog::info("subdomain '{}': {} particle(s) touch a wall at the start, the worst {:.3g} % of its radius (id {}, "
                 "wall {})", name, touching, 100.0 * worst.ratio, worst.id, wall_name(worst.wall));
  if (above.empty()) return;
  std::sort(above.begin(), above.end(), [](const Hit& a, const Hit& c) { return a.ratio > c.ratio; });
  std::string list;
  for (std::size_t k = 0; k < above.size() && k < 5; ++k)
    list += (k ? ", " : "") + std::string("id ") + std::to_string(above[k].id) + " into " + wall_name(above[k].wall) +
            " by " + fmt_num(100.0 * above[k].ratio) + " % of its radius";
  b.ck.add(source,
           std::to_string(above.size()) + " particle(s) overlap a wall by more than run.max_initial_overlap (" +
               fmt_num(100.0 * limit) + " % of the particle's radius) at the start: " + list +
               (above.size() > 5 ? ", ..." : "") +
               (sd.contains("initial_state") ? " in the state file '" + sd["initial_state"].get<std::string>() + "'"
                                             : "") +
               "; their first contact forces would blow them away",
           "move or remove those particles (or the wall), or raise /run/max_initial_overlap if the overlaps are "
           "intended");
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
  check_initial_wall_overlaps(b, s, sd, name, source, limit);
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

/// True (and reported at `where`) when the region lies wholly inside the
/// walls as they stand at time t: nothing can be placed in it.
bool region_inside_walls(Build& b, const domel_region_v1& region, double t, const std::string& where) {
  const WallClearance clearance(b.sim.walls, t, 0.0);
  std::size_t w = 0;
  if (!clearance.covers(region, &w)) return false;
  b.ck.add(where, "the region lies wholly inside the wall '" + b.sim.walls[w].name + "' (" +
                      idx("/walls", b.sim.walls[w].wall) + "): no particle can be placed in it",
           "move the region to the particles' side of the wall");
  return true;
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
      // fixed particles (a rough floor) feel no wall and may stand in one
      if (!ins.fixed && region_inside_walls(b, ins.region, 0.0, where + "/region")) continue;
      ParticleStore& st = sub.store();
      InsertionCandidates c = request_insertion(*ins.model, ins.region, ins.seed, sub.coarse_grain(), &st,
                                                b.sim.flow.max_particles, sub.periodic(), ins.materials.mixture());
      if (const std::size_t dropped = ins.fixed ? 0 : drop_wall_overlaps(c, b.sim.walls, 0.0))
        spdlog::info("subdomain '{}': {} of the places {} chose overlap a wall and are left empty", sub.name(),
                     dropped, where);
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
      if (!ins.fixed && region_inside_walls(b, ins.region, pb["start"].get<double>(), where + "/insert/region")) continue;
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
      InsertionCandidates c = request_insertion(*p.model, p.region, p.seed, p.alpha, nullptr,
                                                b.sim.flow.max_particles, {}, p.materials.mixture());
      if (c.size() == 0) {
        b.ck.add(where + "/insert", "the insertion model placed no particle in the pour region",
                 "enlarge the region or raise the model's volume_fraction / count");
        continue;
      }
      // each component's size range (one for a single material), from every size the model draws
      std::vector<PourProbe> probes(p.materials.material.size(), PourProbe{HUGE_VAL, 0.0, 0.0, 0});
      for (std::size_t q = 0; q < c.size(); ++q) {
        PourProbe& pp = probes[c.component.empty() ? 0 : c.component[q]];
        pp.r_min = std::min(pp.r_min, c.r[q]);
        pp.r_max = std::max(pp.r_max, c.r[q]);
      }
      // what one event can place: the places clear of the walls
      if (!p.fixed) drop_wall_overlaps(c, b.sim.walls, p.start);
      double one_event = 0;
      for (std::size_t q = 0; q < c.size(); ++q)
        one_event += p.materials.density_of(c, q) * 4.0 / 3.0 * M_PI * c.r[q] * c.r[q] * c.r[q];
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
  double d_min = 0;  // the smallest diameter the estimate collides, for its messages
  for (std::size_t k = 0; k < sub.store().size(); ++k)
    if (k == 0 || 2 * sub.store().radius[k] < d_min) d_min = 2 * sub.store().radius[k];
  auto drop_probes = [&] {
    for (std::size_t k = 0; k < probes; ++k) sub.store().swap_remove(sub.store().size() - 1);
    probes = 0;
  };
  try {
    rep = sub.estimate_time_step(v_imp);
  } catch (const PluginError& e) {
    drop_probes();
    ck.add(base + "/contact",
           fmt::format("the contact model failed while estimating the time step (smallest particle {:.6g} m across, "
                       "impact velocity {:.6g} m/s): {}",
                       d_min, v_imp, e.what()));
    return false;
  }
  drop_probes();
  if (!rep.passes_through.empty())
    spdlog::warn("subdomain '{}': the {} does not stop an impact at {:.3g} m/s (impact_velocity) within the "
                 "particles' size ({:.3g} m, the smallest): a contact too soft for that speed; the estimate's contact "
                 "time is the time to pass through ({:.3g} s)",
                 sd_name, rep.passes_through, v_imp, d_min, rep.contact_time);
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

/// A level sub-cycles macro step / its time step steps per macro step,
/// counted in an int (substeps_of): a level whose step is more than that many
/// times shorter than the longest (an empty level given 5e-324 s beside one
/// of 2e-6 s: the run-time fuzzer) would have its step silently lengthened
/// to fit, by hundreds of orders of magnitude. Refused at its time step.
bool check_level_steps(Build& b) {
  const auto& sds = b.sim.subdomains;
  if (sds.size() < 2 || sds.size() != b.doc["subdomains"].size()) return true;
  const double macro = macro_step_of(sds);
  std::size_t longest = 0;
  for (std::size_t k = 1; k < sds.size(); ++k)
    if (sds[k]->time_step() > sds[longest]->time_step()) longest = k;
  bool ok = true;
  for (std::size_t k = 0; k < sds.size(); ++k) {
    if (substeps_of(macro, sds[k]->time_step()) < std::numeric_limits<int>::max()) continue;  // it saturates
    ok = false;
    const json& sd = b.doc["subdomains"][k];
    b.ck.add(idx("/subdomains", k) + (member(sd, "time_step") ? "/time_step" : ""),
             "the time step " + fmt_num(sds[k]->time_step()) + " s of subdomain '" + sds[k]->name() +
                 "' goes more than " + std::to_string(std::numeric_limits<int>::max()) +
                 " times (the most a level can count) into the macro step, " + fmt_num(macro) + " s (subdomain '" +
                 sds[longest]->name() + "''s)",
             "give the levels time steps within a factor of 1e9 of each other (coarse-graining by alpha changes the "
             "step by about alpha)");
  }
  return ok;
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

}  // namespace domel::platform::scenario_detail
