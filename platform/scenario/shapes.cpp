// SPDX-License-Identifier: MIT
// Scenario shapes as the runtime sees them: a region block as the ABI's
// domel_region_v1 (insertion, pours, deletion regions) and a wall block as
// its wall primitives (a box is six planes, a cylinder a mantle plus its
// bottom, lid and outlet plug, ...). Reads a validated document with its
// schema defaults filled in.
#include "geometry/triangle_mesh.hpp"
#include "scenario/scenario_detail.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace domel::platform::scenario_detail {

domel_region_v1 make_region(const json& region) {
  domel_region_v1 r{};
  r.struct_size = sizeof(domel_region_v1);
  if (region.contains("box")) {
    r.shape = 1;
    for (int a = 0; a < 3; ++a) {
      r.lo[a] = region["box"]["min"][a].get<double>();
      r.hi[a] = region["box"]["max"][a].get<double>();
      r.center[a] = 0.5 * (r.lo[a] + r.hi[a]);
    }
  } else {
    const json& c = region["cylinder"];
    r.shape = 2;
    r.axis = static_cast<uint32_t>(axis_index(&c["axis"]));
    r.radius = c["radius"].get<double>();
    for (int a = 0; a < 3; ++a) {
      r.center[a] = c["center"][a].get<double>();
      r.lo[a] = r.center[a] - r.radius;
      r.hi[a] = r.center[a] + r.radius;
    }
    r.lo[r.axis] = c["bottom"].get<double>();
    r.hi[r.axis] = c["top"].get<double>();
  }
  return r;
}

void region_box(const domel_region_v1& r, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) {
    const bool along = r.shape == 1 || k == static_cast<int>(r.axis);
    lo[k] = along ? r.lo[k] : r.center[k] - r.radius;
    hi[k] = along ? r.hi[k] : r.center[k] + r.radius;
  }
}

namespace {

std::vector<WallPrimitive> expand_wall_shape(const json& w, std::size_t material,
                                             const std::filesystem::path& scenario_file) {
  std::vector<WallPrimitive> out;
  const std::string name = w["name"].get<std::string>();
  const std::string type = w["type"].get<std::string>();
  auto plane = [&](const std::string& n, const double p[3], const double nrm[3]) {
    WallPrimitive prim;
    prim.shape = WallPrimitive::Shape::plane;
    prim.name = n;
    prim.material = material;
    const double len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    for (int a = 0; a < 3; ++a) { prim.p[a] = p[a]; prim.n[a] = nrm[a] / len; }
    out.push_back(prim);
  };
  // the axis, centre and extent an axis-aligned mantle (cylinder, cone) shares
  auto mantle = [&](WallPrimitive::Shape shape) {
    WallPrimitive m;
    m.shape = shape;
    m.name = name + ".mantle";
    m.material = material;
    m.axis = axis_index(&w["axis"]);
    for (int a = 0; a < 3; ++a) m.c[a] = w["center"][a].get<double>();
    m.lo = w["bottom"].get<double>();
    m.hi = w["top"].get<double>();
    return m;
  };
  if (type == "plane") {
    const double p[3] = {w["point"][0].get<double>(), w["point"][1].get<double>(), w["point"][2].get<double>()};
    const double n[3] = {w["normal"][0].get<double>(), w["normal"][1].get<double>(), w["normal"][2].get<double>()};
    plane(name, p, n);
  } else if (type == "box") {
    std::set<std::string> open;
    if (w.contains("open"))
      for (const auto& f : w["open"]) open.insert(f.get<std::string>());
    const char* faces[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
    for (int f = 0; f < 6; ++f) {
      if (open.count(faces[f])) continue;
      const int a = f / 2;
      const bool is_min = f % 2 == 0;
      double p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
      p[a] = (is_min ? w["min"] : w["max"])[a].get<double>();
      n[a] = is_min ? 1.0 : -1.0;
      plane(name + "." + faces[f], p, n);
      out.back().draw_in_box = true;
      for (int k = 0; k < 3; ++k) {
        out.back().draw_lo[k] = w["min"][k].get<double>();
        out.back().draw_hi[k] = w["max"][k].get<double>();
      }
    }
  } else if (type == "cylinder") {
    WallPrimitive m = mantle(WallPrimitive::Shape::cylinder_inside);
    m.radius = w["radius"].get<double>();
    out.push_back(m);
    double p[3] = {m.c[0], m.c[1], m.c[2]}, n[3] = {0, 0, 0};
    // closed_bottom has no schema default: true for a cylinder, false for a cone
    if (!w.contains("closed_bottom") || w["closed_bottom"].get<bool>()) {
      p[m.axis] = m.lo; n[m.axis] = 1.0;
      if (w.contains("outlet_radius")) {
        // a plate with a round hole; until outlet_open_at a full plane plugs
        // it (never both at once: the plug's remove_at is the annulus'
        // active_from, so no particle feels two bottoms)
        WallPrimitive a;
        a.shape = WallPrimitive::Shape::annulus;
        a.name = name + ".bottom";
        a.material = material;
        for (int k = 0; k < 3; ++k) { a.p[k] = p[k]; a.n[k] = n[k]; a.c[k] = p[k]; }
        a.r_inner = w["outlet_radius"].get<double>();
        if (w.contains("outlet_open_at")) {
          const double t_open = w["outlet_open_at"].get<double>();
          plane(name + ".plug", p, n);
          out.back().remove_at = t_open;
          a.active_from = t_open;
        }
        out.push_back(a);
      } else {
        plane(name + ".bottom", p, n);
      }
    }
    if (w["closed_top"].get<bool>()) {
      p[m.axis] = m.hi; n[m.axis] = -1.0;
      plane(name + ".top", p, n);
    }
    for (std::size_t k = 1; k < out.size(); ++k) out[k].draw_radius = m.radius;  // bottom, plug, top
  } else if (type == "cone") {
    WallPrimitive m = mantle(WallPrimitive::Shape::cone_inside);
    m.radius = w["radius_bottom"].get<double>();
    m.radius_hi = w["radius_top"].get<double>();
    out.push_back(m);
    if (w.contains("closed_bottom") && w["closed_bottom"].get<bool>()) {
      WallPrimitive d;
      d.shape = WallPrimitive::Shape::annulus;
      d.name = name + ".plug";
      d.material = material;
      for (int k = 0; k < 3; ++k) { d.p[k] = m.c[k]; d.c[k] = m.c[k]; d.n[k] = 0.0; }
      d.p[m.axis] = m.lo;
      d.c[m.axis] = m.lo;
      d.n[m.axis] = 1.0;
      d.r_inner = 0.0;
      d.r_outer = m.radius;
      if (w.contains("outlet_open_at")) d.remove_at = w["outlet_open_at"].get<double>();
      out.push_back(d);
    }
  } else if (type == "disk") {
    WallPrimitive d;
    d.shape = WallPrimitive::Shape::annulus;
    d.name = name;
    d.material = material;
    double len = 0;
    for (int a = 0; a < 3; ++a) len += w["normal"][a].get<double>() * w["normal"][a].get<double>();
    len = std::sqrt(len);
    for (int a = 0; a < 3; ++a) {
      d.p[a] = d.c[a] = w["center"][a].get<double>();
      d.n[a] = w["normal"][a].get<double>() / len;
    }
    d.r_inner = w["inner_radius"].get<double>();
    d.r_outer = w["radius"].get<double>();
    out.push_back(d);
  } else {  // mesh
    const std::filesystem::path f = scenario_path(scenario_file, w["file"].get<std::string>());
    double tr[3];
    for (int a = 0; a < 3; ++a) tr[a] = w["translate"][a].get<double>();
    auto mesh = std::make_shared<TriangleMesh>(load_stl_mesh(f, w["scale"].get<double>(), tr));
    spdlog::info("wall '{}': {} triangles, {} vertices, {} edges from {} ({} corners welded{})", name,
                 mesh->triangle_count(), mesh->vertex_count(), mesh->edge_count(), f.string(), mesh->welded,
                 mesh->dropped_degenerate ? ", " + std::to_string(mesh->dropped_degenerate) + " degenerate triangles dropped"
                                          : std::string());
    WallPrimitive m;
    m.shape = WallPrimitive::Shape::mesh;
    m.name = name;
    m.material = material;
    m.verts = mesh->vertices;
    triangle_bounds(*mesh, m.verts, m.tri_bounds);
    m.mesh = std::move(mesh);
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace

std::vector<WallPrimitive> expand_wall(const json& w, std::size_t wall_index, std::size_t material,
                                       const std::filesystem::path& scenario_file) {
  std::vector<WallPrimitive> out = expand_wall_shape(w, material, scenario_file);
  for (auto& p : out) p.wall = wall_index;
  if (w.contains("remove_at"))
    for (auto& p : out) p.remove_at = std::min(p.remove_at, w["remove_at"].get<double>());
  if (const json* mo = member(w, "motion")) {
    const std::string type = w["type"].get<std::string>();
    auto motion = std::make_shared<WallMotion>();
    auto vec = [](const json& v, double out[3]) {
      for (int a = 0; a < 3; ++a) out[a] = v[a].get<double>();
    };
    auto unit = [](double v[3]) {
      const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int a = 0; a < 3; ++a) v[a] /= l;
    };
    const json items = mo->is_array() ? *mo : json::array({*mo});
    for (const json& m : items) {
      MotionItem base;
      base.start = m["start"].get<double>();
      if (m.contains("end")) base.end = m["end"].get<double>();
      // within one item: the rotation, then the translation, the vibration, the servo
      MotionItem rot = base;
      rot.kind = MotionItem::Kind::rotation;
      vec(m["angular_velocity"], rot.vec);
      for (int a = 0; a < 3; ++a)
        // default origin: the wall's own centre or point (on its rotation axis), 0 for a mesh
        rot.origin[a] = m.contains("origin")     ? m["origin"][a].get<double>()
                        : type == "plane"        ? w["point"][a].get<double>()
                        : w.contains("center")   ? w["center"][a].get<double>()
                                                 : 0.0;
      if (rot.vec[0] != 0 || rot.vec[1] != 0 || rot.vec[2] != 0) motion->items.push_back(rot);
      MotionItem tr = base;
      tr.kind = MotionItem::Kind::translation;
      vec(m["velocity"], tr.vec);
      if (tr.vec[0] != 0 || tr.vec[1] != 0 || tr.vec[2] != 0) motion->items.push_back(tr);
      if (const json* vib = member(m, "vibration")) {
        MotionItem v = base;
        v.kind = MotionItem::Kind::vibration;
        vec((*vib)["amplitude"], v.vec);
        v.omega_f = 2.0 * M_PI * (*vib)["frequency"].get<double>();
        v.phase = (*vib)["phase"].get<double>();
        motion->items.push_back(v);
      }
      if (const json* sv = member(m, "servo")) {
        MotionItem v = base;
        v.kind = MotionItem::Kind::servo;
        vec((*sv)["direction"], v.vec);
        unit(v.vec);
        v.servo = std::make_shared<ServoState>();
        v.servo->t_ref = base.start;
        motion->items.push_back(v);
      }
    }
    for (auto& p : out) p.set_motion(motion);
  }
  return out;
}


}  // namespace domel::platform::scenario_detail
