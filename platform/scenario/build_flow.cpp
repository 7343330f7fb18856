// SPDX-License-Identifier: MIT
// The builders of the particle flow (deletion regions, mass-flow planes,
// region masses) and of the contact outputs (wall loads, contact frames)
// (build.hpp).
#include "scenario/build.hpp"

#include "geometry/region.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace domel::platform::scenario_detail {

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

}  // namespace domel::platform::scenario_detail
