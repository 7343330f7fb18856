// SPDX-License-Identifier: MIT
// The builders of the materials and interactions, the walls and the run block (build.hpp).
#include "scenario/build.hpp"

#include "geometry/triangle_mesh.hpp"
#include "scenario/scenario.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace domel::platform::scenario_detail {

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

}  // namespace domel::platform::scenario_detail
