// SPDX-License-Identifier: MIT
// Scenario validation passes and the construction of a Simulation.
#include "scenario/scenario.hpp"

#include "geometry/region.hpp"
#include "geometry/triangle_mesh.hpp"
#include "io/particle_state.hpp"
#include "scenario/json_schema.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace domel::platform {

extern const char* const kScenarioSchemaText;

namespace {

using nlohmann::json;

constexpr uint32_t kSlotKinds[kSlotCount] = {DOMEL_KIND_NORMAL, DOMEL_KIND_DAMPING, DOMEL_KIND_TANGENTIAL,
                                             DOMEL_KIND_ROLLING, DOMEL_KIND_TWISTING};
constexpr const char* kDefaultSlotModel[kSlotCount] = {"hertz", "restitution", "mindlin", "none", "none"};

std::string idx(const std::string& base, std::size_t k) { return base + "/" + std::to_string(k); }

std::string escape_pointer_token(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '~') out += "~0";
    else if (ch == '/') out += "~1";
    else out += ch;
  }
  return out;
}

std::string fmt_num(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

/// A file named in the scenario (mesh, plugin, state file): a relative path
/// is relative to the scenario's folder.
std::filesystem::path scenario_path(const std::filesystem::path& scenario_file, const std::string& named) {
  std::filesystem::path p = named;
  return p.is_relative() ? scenario_file.parent_path() / p : p;
}

/// Validation state shared by the passes.
struct Checker {
  std::filesystem::path file;
  std::vector<Diagnostic> diags;
  void add(const std::string& pointer, const std::string& message, const std::string& hint = {}) {
    diags.push_back({file.string(), pointer, message, hint});
  }
};

const json* member(const json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

bool is_vec3(const json* j) {
  return j && j->is_array() && j->size() == 3 && (*j)[0].is_number() && (*j)[1].is_number() && (*j)[2].is_number();
}

int axis_index(const json* j) {
  if (!j || !j->is_string()) return 2;
  const std::string a = j->get<std::string>();
  return a == "x" ? 0 : a == "y" ? 1 : 2;
}

/// Platform keys of a model block that are not the plugin's parameters.
std::vector<std::string> platform_keys(uint32_t kind) {
  if (kind == DOMEL_KIND_INSERTION) return {"model", "region", "seed", "velocity", "fixed"};
  return {"model"};
}

json plugin_params(const json& block, uint32_t kind) {
  json p = block;
  for (const auto& k : platform_keys(kind)) p.erase(k);
  return p;
}

json platform_block_properties(uint32_t kind) {
  const json& defs = platform_scenario_schema()["$defs"];
  if (kind == DOMEL_KIND_INSERTION) return defs["insertion_model"]["properties"];
  return json::object();
}

}  // namespace

const json& platform_scenario_schema() {
  static const json schema = json::parse(kScenarioSchemaText);
  return schema;
}

json model_block_schema(const RegisteredModel& model) {
  json s = model.schema.is_object() ? model.schema : json::object();
  if (!s.contains("type")) s["type"] = "object";
  json props = s.contains("properties") && s["properties"].is_object() ? s["properties"] : json::object();
  const json platform_props = platform_block_properties(model.desc.kind);
  for (auto& [k, v] : platform_props.items()) props[k] = v;
  props["model"] = json{{"const", model.name}, {"description", model.summary}};
  s["properties"] = props;
  json req = s.contains("required") && s["required"].is_array() ? s["required"] : json::array();
  auto add_req = [&](const char* k) {
    if (std::find(req.begin(), req.end(), json(k)) == req.end()) req.push_back(k);
  };
  add_req("model");
  if (model.desc.kind == DOMEL_KIND_INSERTION) add_req("region");
  s["required"] = req;
  s.erase("$schema");
  return s;
}

json composed_scenario_schema(const PluginRegistry& registry) {
  json schema = platform_scenario_schema();
  auto fill = [&](const char* def, uint32_t kind, bool allow_none) {
    json alternatives = json::array();
    for (const auto& m : registry.models())
      if (m.desc.kind == kind) alternatives.push_back(model_block_schema(m));
    if (allow_none)
      alternatives.push_back(json{{"type", "object"},
                                  {"properties", {{"model", {{"const", "none"}, {"description", "empty slot"}}}}},
                                  {"required", {"model"}},
                                  {"additionalProperties", false}});
    if (alternatives.empty()) return;
    schema["$defs"][def] = json{{"oneOf", alternatives}};
  };
  fill("normal_model", DOMEL_KIND_NORMAL, false);
  fill("damping_model", DOMEL_KIND_DAMPING, false);
  fill("tangential_model", DOMEL_KIND_TANGENTIAL, false);
  fill("rolling_model", DOMEL_KIND_ROLLING, true);
  fill("twisting_model", DOMEL_KIND_TWISTING, true);
  fill("insertion_model", DOMEL_KIND_INSERTION, false);
  return schema;
}

namespace {

/// Validate one model block (contact slot or inserter). Returns the model or null.
const RegisteredModel* check_model_block(Checker& ck, const PluginRegistry& registry, const json& block,
                                         const std::string& pointer, uint32_t kind, bool allow_none) {
  if (!block.is_object()) return nullptr;  // the platform schema already said so
  const json* name = member(block, "model");
  if (!name || !name->is_string()) return nullptr;
  const std::string model = name->get<std::string>();
  if (allow_none && model == "none") {
    if (block.size() > 1) ck.add(pointer, "an empty slot (\"none\") takes no parameters");
    return nullptr;
  }
  const RegisteredModel* m = registry.find(kind, model);
  if (!m) {
    auto names = registry.names(kind);
    if (allow_none) names.push_back("none");
    ck.add(pointer + "/model", std::string("unknown ") + kind_name(kind) + " model '" + model + "'",
           names.empty() ? std::string("no ") + kind_name(kind) + " models are loaded" : suggest(model, names));
    return nullptr;
  }
  json schema = model_block_schema(*m);
  schema["$defs"] = platform_scenario_schema()["$defs"];
  try {
    SchemaValidator(schema).validate(block, ck.diags, pointer);
  } catch (const std::exception& e) {
    ck.add(pointer, std::string(kind_name(kind)) + " model '" + model + "' has a parameter schema domel cannot use: " + e.what());
  }
  for (auto& d : ck.diags)
    if (d.file.empty()) d.file = ck.file.string();
  return m;
}

void check_models(Checker& ck, const json& doc, const PluginRegistry& registry) {
  const json* sds = member(doc, "subdomains");
  if (!sds || !sds->is_array()) return;
  for (std::size_t k = 0; k < sds->size(); ++k) {
    const json& sd = (*sds)[k];
    const std::string base = idx("/subdomains", k);
    if (const json* contact = member(sd, "contact"); contact && contact->is_object()) {
      for (std::size_t s = 0; s < kSlotCount; ++s) {
        const json* block = member(*contact, kSlotNames[s]);
        if (!block) continue;
        const bool optional = s >= static_cast<std::size_t>(Slot::rolling);
        if (!optional && block->is_object() && member(*block, "model") && (*block)["model"] == "none")
          ck.add(base + "/contact/" + kSlotNames[s] + "/model",
                 std::string("the ") + kSlotNames[s] + " slot cannot be empty",
                 suggest("none", registry.names(kSlotKinds[s])));
        else
          check_model_block(ck, registry, *block, base + "/contact/" + kSlotNames[s], kSlotKinds[s], optional);
      }
    }
    if (const json* ins = member(sd, "insert"); ins && ins->is_array())
      for (std::size_t q = 0; q < ins->size(); ++q)
        check_model_block(ck, registry, (*ins)[q], idx(base + "/insert", q), DOMEL_KIND_INSERTION, false);
    if (const json* pours = member(sd, "pour"); pours && pours->is_array())
      for (std::size_t q = 0; q < pours->size(); ++q)
        if (const json* ins = member((*pours)[q], "insert"))
          check_model_block(ck, registry, *ins, idx(base + "/pour", q) + "/insert", DOMEL_KIND_INSERTION, false);
  }
}

void check_references(Checker& ck, const json& doc) {
  std::vector<std::string> materials;
  std::map<std::string, bool> has_density;
  if (const json* mats = member(doc, "materials"); mats && mats->is_object()) {
    for (auto& [name, m] : mats->items()) {
      materials.push_back(name);
      has_density[name] = m.is_object() && m.contains("density");
    }
    if (mats->empty()) ck.add("/materials", "expected at least one material, found none");
  }
  auto check_material = [&](const json* j, const std::string& pointer) -> std::string {
    if (!j || !j->is_string()) return {};
    const std::string name = j->get<std::string>();
    if (std::find(materials.begin(), materials.end(), name) == materials.end()) {
      ck.add(pointer, "unknown material '" + name + "'", suggest(name, materials));
      return {};
    }
    return name;
  };

  // walls
  std::vector<std::pair<std::string, std::string>> wall_materials;  // (wall name, material)
  std::set<std::string> wall_names;
  if (const json* walls = member(doc, "walls"); walls && walls->is_array()) {
    static const std::map<std::string, std::set<std::string>> kAllowed = {
        {"plane", {"name", "type", "material", "point", "normal", "remove_at", "motion"}},
        {"box", {"name", "type", "material", "min", "max", "open", "remove_at", "motion"}},
        {"cylinder",
         {"name", "type", "material", "axis", "center", "radius", "bottom", "top", "closed_bottom", "closed_top",
          "outlet_radius", "outlet_open_at", "remove_at", "motion"}},
        {"cone",
         {"name", "type", "material", "axis", "center", "bottom", "top", "radius_bottom", "radius_top",
          "closed_bottom", "outlet_open_at", "remove_at", "motion"}},
        {"disk", {"name", "type", "material", "center", "normal", "radius", "inner_radius", "remove_at", "motion"}},
        {"mesh", {"name", "type", "material", "file", "scale", "translate", "remove_at", "motion"}}};
    static const std::map<std::string, std::vector<std::string>> kRequired = {
        {"plane", {"point", "normal"}},
        {"box", {"min", "max"}},
        {"cylinder", {"center", "radius", "bottom", "top"}},
        {"cone", {"center", "bottom", "top", "radius_bottom", "radius_top"}},
        {"disk", {"center", "normal", "radius"}},
        {"mesh", {"file"}}};
    for (std::size_t k = 0; k < walls->size(); ++k) {
      const json& w = (*walls)[k];
      const std::string base = idx("/walls", k);
      if (!w.is_object()) continue;
      const json* name = member(w, "name");
      const json* type = member(w, "type");
      if (name && name->is_string() && !wall_names.insert(name->get<std::string>()).second)
        ck.add(base + "/name", "duplicate wall name '" + name->get<std::string>() + "'");
      const std::string mat = check_material(member(w, "material"), base + "/material");
      if (!mat.empty() && name && name->is_string()) wall_materials.emplace_back(name->get<std::string>(), mat);
      if (!type || !type->is_string() || !kAllowed.count(type->get<std::string>())) continue;
      const std::string t = type->get<std::string>();
      for (auto& [key, v] : w.items())
        if (!kAllowed.at(t).count(key) && key != "$comment")
          ck.add(base + "/" + escape_pointer_token(key), "'" + key + "' does not apply to a " + t + " wall",
                 "a " + t + " wall takes: " + [&] {
                   std::string s;
                   for (const auto& a : kAllowed.at(t)) s += (s.empty() ? "" : ", ") + a;
                   return s;
                 }());
      for (const auto& req : kRequired.at(t))
        if (!w.contains(req)) ck.add(base, "missing required property '" + req + "' of a " + t + " wall");
      auto number = [&](const char* key) -> const json* {
        const json* j = member(w, key);
        return j && j->is_number() ? j : nullptr;
      };
      if ((t == "plane" || t == "disk") && is_vec3(member(w, "normal"))) {
        const json& n = w["normal"];
        const double len = std::sqrt(n[0].get<double>() * n[0].get<double>() + n[1].get<double>() * n[1].get<double>() +
                                     n[2].get<double>() * n[2].get<double>());
        if (len <= 0) ck.add(base + "/normal", "expected a non-zero normal vector, found [0, 0, 0]");
      }
      if (t == "box" && is_vec3(member(w, "min")) && is_vec3(member(w, "max")))
        for (int a = 0; a < 3; ++a)
          if (w["min"][a].get<double>() >= w["max"][a].get<double>())
            ck.add(base + "/max/" + std::to_string(a),
                   "expected max > min along " + std::string(1, "xyz"[a]) + ", found max " +
                       fmt_num(w["max"][a].get<double>()) + " <= min " + fmt_num(w["min"][a].get<double>()));
      if (t == "cylinder" || t == "cone") {
        const json* lo = number("bottom");
        const json* hi = number("top");
        if (lo && hi && lo->get<double>() >= hi->get<double>())
          ck.add(base + "/top", "expected top > bottom, found top " + fmt_num(hi->get<double>()) + " <= bottom " +
                                    fmt_num(lo->get<double>()));
      }
      if (t == "cylinder") {
        const json* r = number("radius");
        const json* ro = number("outlet_radius");
        if (r && ro && ro->get<double>() >= r->get<double>())
          ck.add(base + "/outlet_radius",
                 "expected outlet_radius < radius, found outlet_radius " + fmt_num(ro->get<double>()) +
                     " >= radius " + fmt_num(r->get<double>()),
                 "the outlet is a hole in the cylinder's flat bottom");
        if (ro && member(w, "closed_bottom") && (*member(w, "closed_bottom")) == false)
          ck.add(base + "/outlet_radius", "an outlet needs the flat bottom, found closed_bottom false",
                 "remove closed_bottom, or remove outlet_radius for an open-ended tube");
        if (member(w, "outlet_open_at") && !ro)
          ck.add(base + "/outlet_open_at", "outlet_open_at needs outlet_radius (the outlet it opens)");
      }
      if (t == "cone" && member(w, "outlet_open_at") && !(member(w, "closed_bottom") && (*member(w, "closed_bottom")) == true))
        ck.add(base + "/outlet_open_at", "outlet_open_at needs closed_bottom: true (the plug it removes)");
      if (t == "disk") {
        const json* r = number("radius");
        const json* ri = number("inner_radius");
        if (r && ri && ri->get<double>() >= r->get<double>())
          ck.add(base + "/inner_radius", "expected inner_radius < radius, found inner_radius " +
                                             fmt_num(ri->get<double>()) + " >= radius " + fmt_num(r->get<double>()));
      }
      if (t == "mesh" && member(w, "file") && w["file"].is_string()) {
        const std::filesystem::path f = scenario_path(ck.file, w["file"].get<std::string>());
        try {
          const TriangleMesh m = load_stl_mesh(f, 1.0, std::array<double, 3>{0, 0, 0}.data());
          (void)m;
        } catch (const MeshError& e) {
          ck.add(base + "/file", e.what(),
                 std::filesystem::exists(f) ? "export the mesh again as STL (ASCII or binary)"
                                            : "paths in \"file\" are relative to the scenario's folder");
        }
      }
      if (const json* mo = member(w, "motion"); mo && mo->is_object()) {
        const json* st = member(*mo, "start");
        const json* en = member(*mo, "end");
        if (st && en && st->is_number() && en->is_number() && en->get<double>() <= st->get<double>())
          ck.add(base + "/motion/end", "expected end > start, found end " + fmt_num(en->get<double>()) +
                                           " <= start " + fmt_num(st->get<double>()));
        const json* om = member(*mo, "angular_velocity");
        if (is_vec3(om) && t != "mesh") {
          const double wv[3] = {(*om)[0].get<double>(), (*om)[1].get<double>(), (*om)[2].get<double>()};
          const double wl = std::sqrt(wv[0] * wv[0] + wv[1] * wv[1] + wv[2] * wv[2]);
          // the wall's own axis: the normal of a plane or disk, the axis of a cylinder or cone
          double ax[3] = {0, 0, 0};
          bool have_axis = false;
          if ((t == "plane" || t == "disk") && is_vec3(member(w, "normal"))) {
            for (int a = 0; a < 3; ++a) ax[a] = w["normal"][a].get<double>();
            have_axis = true;
          } else if (t == "cylinder" || t == "cone") {
            ax[axis_index(member(w, "axis"))] = 1.0;
            have_axis = true;
          }
          const double al = std::sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
          auto cross_norm = [](const double* a, const double* b) {
            const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
            return std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
          };
          if (wl > 0 && t == "box") {
            ck.add(base + "/motion/angular_velocity", "a box wall cannot rotate, found a non-zero angular_velocity",
                   "use a mesh wall for a rotating box, or only a velocity");
          } else if (wl > 0 && have_axis && al > 0 && cross_norm(wv, ax) > 1e-9 * wl * al) {
            ck.add(base + "/motion/angular_velocity",
                   "a " + t + " wall rotates only about its own " + (t == "plane" || t == "disk" ? "normal" : "axis") +
                       ", found angular_velocity [" + fmt_num(wv[0]) + ", " + fmt_num(wv[1]) + ", " + fmt_num(wv[2]) +
                       "] not parallel to it",
                   "use a mesh wall for other rotations");
          } else if (wl > 0 && have_axis && al > 0 && is_vec3(member(*mo, "origin"))) {
            const char* ref = t == "plane" ? "point" : "center";
            if (is_vec3(member(w, ref))) {
              double d[3];
              for (int a = 0; a < 3; ++a) d[a] = (*mo)["origin"][a].get<double>() - w[ref][a].get<double>();
              const double dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
              if (cross_norm(d, ax) > 1e-9 * al * std::max(1.0, dl))
                ck.add(base + "/motion/origin",
                       "a " + t + " wall rotates only about its own axis, found an origin off the axis through its " +
                           ref,
                       "omit origin, or use a mesh wall for an eccentric rotation");
            }
          }
        }
      }
    }
  }

  // subdomains
  std::set<std::string> sd_names;
  std::vector<std::pair<std::string, std::string>> sd_materials;  // (subdomain, material)
  if (const json* sds = member(doc, "subdomains"); sds && sds->is_array()) {
    for (std::size_t k = 0; k < sds->size(); ++k) {
      const json& sd = (*sds)[k];
      const std::string base = idx("/subdomains", k);
      const json* name = member(sd, "name");
      if (name && name->is_string() && !sd_names.insert(name->get<std::string>()).second)
        ck.add(base + "/name", "duplicate subdomain name '" + name->get<std::string>() + "'");
      const std::string mat = check_material(member(sd, "material"), base + "/material");
      if (!mat.empty()) {
        if (!has_density[mat])
          ck.add("/materials/" + escape_pointer_token(mat), "missing required property 'density'",
                 "subdomain '" + (name && name->is_string() ? name->get<std::string>() : std::to_string(k)) +
                     "' makes particles of this material");
        sd_materials.emplace_back(name && name->is_string() ? name->get<std::string>() : std::to_string(k), mat);
      }
      if (const json* st = member(sd, "initial_state"); st && st->is_string() && !st->get<std::string>().empty()) {
        const std::filesystem::path f = scenario_path(ck.file, st->get<std::string>());
        try {
          if (io::for_each_particle_state_row(f, [](const io::ParticleStateRow&) {}) == 0)
            ck.add(base + "/initial_state", "expected at least one particle in " + f.string() + ", found none");
        } catch (const std::exception& e) {
          ck.add(base + "/initial_state", e.what(),
                 std::filesystem::exists(f) ? "write it with output.state: true in an earlier run"
                                            : "paths in \"initial_state\" are relative to the scenario's folder");
        }
      }
    }
  }

  // pours: a window that is not empty
  if (const json* sds = member(doc, "subdomains"); sds && sds->is_array())
    for (std::size_t k = 0; k < sds->size(); ++k)
      if (const json* pours = member((*sds)[k], "pour"); pours && pours->is_array())
        for (std::size_t q = 0; q < pours->size(); ++q) {
          const json& p = (*pours)[q];
          const json* a = member(p, "start");
          const json* b = member(p, "end");
          const double start = a && a->is_number() ? a->get<double>() : 0.0;
          if (b && b->is_number() && b->get<double>() <= start)
            ck.add(idx(idx("/subdomains", k) + "/pour", q) + "/end",
                   "expected end > start, found end " + fmt_num(b->get<double>()) + " <= start " + fmt_num(start));
        }

  // deletion regions and mass-flow planes: unique names (they name probes.csv columns), sane windows and normals
  std::set<std::string> flow_names;
  auto check_flow_item = [&](const json& item, const std::string& pointer) {
    if (!item.is_object()) return;
    if (const json* n = member(item, "name"); n && n->is_string() && !flow_names.insert(n->get<std::string>()).second)
      ck.add(pointer + "/name", "duplicate name '" + n->get<std::string>() + "'",
             "deletion regions and mass-flow planes share one namespace (their probes.csv columns)");
    if (const json* w = member(item, "rate_window"); w && w->is_array() && w->size() == 2 && (*w)[0].is_number() &&
                                                      (*w)[1].is_number() && (*w)[1].get<double>() <= (*w)[0].get<double>())
      ck.add(pointer + "/rate_window", "expected [t0, t1] with t1 > t0, found [" + fmt_num((*w)[0].get<double>()) +
                                           ", " + fmt_num((*w)[1].get<double>()) + "]");
    if (is_vec3(member(item, "normal"))) {
      const json& n = item["normal"];
      if (n[0].get<double>() == 0 && n[1].get<double>() == 0 && n[2].get<double>() == 0)
        ck.add(pointer + "/normal", "expected a non-zero normal vector, found [0, 0, 0]");
    }
  };
  if (const json* dr = member(doc, "deletion_regions"); dr && dr->is_array())
    for (std::size_t k = 0; k < dr->size(); ++k) check_flow_item((*dr)[k], idx("/deletion_regions", k));
  if (const json* out = member(doc, "output"); out && out->is_object())
    if (const json* mf = member(*out, "mass_flow"); mf && mf->is_array())
      for (std::size_t k = 0; k < mf->size(); ++k) check_flow_item((*mf)[k], idx("/output/mass_flow", k));

  // interactions
  std::set<std::pair<std::string, std::string>> pairs;
  if (const json* inter = member(doc, "interactions"); inter && inter->is_array()) {
    for (std::size_t k = 0; k < inter->size(); ++k) {
      const json* ms = member((*inter)[k], "materials");
      if (!ms || !ms->is_array() || ms->size() != 2) continue;
      const std::string a = check_material(&(*ms)[0], idx("/interactions", k) + "/materials/0");
      const std::string b = check_material(&(*ms)[1], idx("/interactions", k) + "/materials/1");
      if (a.empty() || b.empty()) continue;
      if (!pairs.insert(std::minmax(a, b)).second)
        ck.add(idx("/interactions", k), "duplicate interaction for materials '" + a + "' and '" + b + "'");
    }
  }
  auto need = [&](const std::string& a, const std::string& b, const std::string& why) {
    if (pairs.count(std::minmax(a, b))) return;
    ck.add("/interactions", "no interaction for materials '" + a + "' and '" + b + "', needed by " + why,
           "add {\"materials\": [\"" + a + "\", \"" + b + "\"], \"restitution\": ..., \"friction\": ...}");
    pairs.insert(std::minmax(a, b));  // report each missing pair once
  };
  for (const auto& [sd, mat] : sd_materials) {
    need(mat, mat, "subdomain '" + sd + "'");
    for (const auto& [wall, wmat] : wall_materials) need(mat, wmat, "subdomain '" + sd + "' touching wall '" + wall + "'");
  }
}

std::vector<Diagnostic> validate_document(const json& doc, const std::filesystem::path& file, PluginRegistry& registry) {
  Checker ck;
  ck.file = file;
  // Plugin libraries named by the scenario, relative to its folder.
  if (const json* plugins = member(doc, "plugins"); plugins && plugins->is_array()) {
    for (std::size_t k = 0; k < plugins->size(); ++k) {
      if (!(*plugins)[k].is_string()) continue;
      const std::filesystem::path p = scenario_path(file, (*plugins)[k].get<std::string>());
      try {
        registry.load(p);
      } catch (const PluginError& e) {
        ck.add(idx("/plugins", k), e.what(),
               std::filesystem::exists(p) ? std::string() : "paths in \"plugins\" are relative to the scenario's folder");
      }
    }
  }
  SchemaValidator(platform_scenario_schema()).validate(doc, ck.diags);
  for (auto& d : ck.diags)
    if (d.file.empty()) d.file = file.string();
  check_models(ck, doc, registry);
  check_references(ck, doc);
  return ck.diags;
}

json read_json_file(const std::filesystem::path& file, std::vector<Diagnostic>& diags) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    diags.push_back({file.string(), "", "cannot open the scenario file", "check the path"});
    return {};
  }
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return json::parse(ss.str());
  } catch (const json::parse_error& e) {
    std::string what = e.what();
    const auto pos = what.find("] ");
    if (pos != std::string::npos) what = what.substr(pos + 2);
    diags.push_back({file.string(), "", "not valid JSON: " + what,
                     "look for a missing ',' or '\"' just before that position, or a trailing ','"});
    return {};
  }
}

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
    r.axis = static_cast<uint32_t>(axis_index(member(c, "axis")));
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
    m.axis = axis_index(member(w, "axis"));
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
    }
  } else if (type == "cylinder") {
    WallPrimitive m = mantle(WallPrimitive::Shape::cylinder_inside);
    m.radius = w["radius"].get<double>();
    out.push_back(m);
    double p[3] = {m.c[0], m.c[1], m.c[2]}, n[3] = {0, 0, 0};
    if (w.value("closed_bottom", true)) {
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
    if (w.value("closed_top", false)) {
      p[m.axis] = m.hi; n[m.axis] = -1.0;
      plane(name + ".top", p, n);
    }
  } else if (type == "cone") {
    WallPrimitive m = mantle(WallPrimitive::Shape::cone_inside);
    m.radius = w["radius_bottom"].get<double>();
    m.radius_hi = w["radius_top"].get<double>();
    out.push_back(m);
    if (w.value("closed_bottom", false)) {
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
    d.r_inner = w.value("inner_radius", 0.0);
    d.r_outer = w["radius"].get<double>();
    out.push_back(d);
  } else {  // mesh
    const std::filesystem::path f = scenario_path(scenario_file, w["file"].get<std::string>());
    double tr[3] = {0, 0, 0};
    if (w.contains("translate"))
      for (int a = 0; a < 3; ++a) tr[a] = w["translate"][a].get<double>();
    auto mesh = std::make_shared<TriangleMesh>(load_stl_mesh(f, w.value("scale", 1.0), tr));
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

std::vector<WallPrimitive> expand_wall(const json& w, std::size_t material, const std::filesystem::path& scenario_file) {
  std::vector<WallPrimitive> out = expand_wall_shape(w, material, scenario_file);
  if (w.contains("remove_at"))
    for (auto& p : out) p.remove_at = std::min(p.remove_at, w["remove_at"].get<double>());
  if (const json* mo = member(w, "motion")) {
    const std::string type = w["type"].get<std::string>();
    for (auto& p : out) {
      p.moving = true;
      for (int a = 0; a < 3; ++a) {
        p.velocity[a] = mo->contains("velocity") ? (*mo)["velocity"][a].get<double>() : 0.0;
        p.omega[a] = mo->contains("angular_velocity") ? (*mo)["angular_velocity"][a].get<double>() : 0.0;
        // default origin: the wall's own centre or point (on its rotation axis), 0 for a mesh
        p.origin[a] = mo->contains("origin") ? (*mo)["origin"][a].get<double>()
                      : type == "plane"      ? w["point"][a].get<double>()
                      : w.contains("center") ? w["center"][a].get<double>()
                                             : 0.0;
      }
      p.motion_start = mo->value("start", 0.0);
      if (mo->contains("end")) p.motion_end = (*mo)["end"].get<double>();
    }
  }
  return out;
}

std::unique_ptr<Simulation> build(const json& doc, const std::filesystem::path& file, PluginRegistry& registry) {
  Checker ck;
  ck.file = file;
  auto sim = std::make_unique<Simulation>();
  sim->scenario_file = file;
  sim->name = doc.value("name", file.stem().string());
  if (doc.contains("gravity"))
    for (int a = 0; a < 3; ++a) sim->gravity[a] = doc["gravity"][a].get<double>();

  std::map<std::string, std::size_t> mat_index;
  for (auto& [name, m] : doc["materials"].items()) {
    Material mat;
    mat.name = name;
    mat.density = m.value("density", 0.0);
    mat.youngs_modulus = m["youngs_modulus"].get<double>();
    mat.poisson_ratio = m["poisson_ratio"].get<double>();
    mat_index[name] = sim->materials.size();
    sim->materials.push_back(mat);
  }
  std::map<std::pair<std::string, std::string>, PairCoefficients> coeffs;
  for (const auto& it : doc["interactions"]) {
    // std::minmax returns references: bind the names first (temporaries would dangle)
    const std::string a = it["materials"][0].get<std::string>(), b = it["materials"][1].get<std::string>();
    const std::pair<std::string, std::string> key = std::minmax(a, b);
    coeffs[key] = {it["restitution"].get<double>(), it["friction"].get<double>()};
  }
  if (doc.contains("walls"))
    for (const auto& w : doc["walls"]) {
      try {
        auto prims = expand_wall(w, mat_index.at(w["material"].get<std::string>()), file);
        sim->walls.insert(sim->walls.end(), prims.begin(), prims.end());
      } catch (const MeshError& e) {  // the file changed since validation
        ck.add("/walls", e.what());
      }
    }

  const json& run = doc["run"];
  sim->seed = run.value("seed", static_cast<std::uint64_t>(1));
  sim->threads = run.value("threads", 0);  // 0: not given (DOMEL_THREADS or 1)

  std::uint64_t next_id = 1;
  const json& sds = doc["subdomains"];
  for (std::size_t k = 0; k < sds.size(); ++k) {
    const json& sd = sds[k];
    const std::string base = idx("/subdomains", k);
    const std::string sd_name = sd["name"].get<std::string>();
    const std::string mat_name = sd["material"].get<std::string>();
    const double alpha = sd.value("coarse_grain", 1.0);
    const json contact = sd.value("contact", json::object());
    // inserter seeds derive from the run seed, this hash of the subdomain's
    // name and the inserter's position, so adding or removing another
    // subdomain changes nothing here (FNV-1a)
    std::uint64_t name_hash = 1469598103934665603ull;
    for (unsigned char ch : sd_name) name_hash = (name_hash ^ ch) * 1099511628211ull;

    std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots;
    json used = json::object();
    bool ok = true;
    for (std::size_t s = 0; s < kSlotCount; ++s) {
      json block = contact.contains(kSlotNames[s]) ? contact[kSlotNames[s]] : json{{"model", kDefaultSlotModel[s]}};
      const std::string model = block["model"].get<std::string>();
      if (model == "none") continue;
      const RegisteredModel* m = registry.find(kSlotKinds[s], model);
      const std::string where = base + "/contact/" + kSlotNames[s];
      if (!m) {  // a default the loaded plugins do not provide
        ck.add(where, std::string("no ") + kSlotNames[s] + " model '" + model + "' is loaded",
               suggest(model, registry.names(kSlotKinds[s])));
        ok = false;
        continue;
      }
      try {
        slots[s] = std::make_unique<ModelInstance>(*m, plugin_params(block, kSlotKinds[s]), "subdomain '" + sd_name + "'");
      } catch (const PluginError& e) {
        ck.add(where, e.what());
        ok = false;
        continue;
      }
      used[kSlotNames[s]] = {{"model", model},
                             {"version", m->version},
                             {"library", registry.libraries()[m->library].name},
                             {"library_version", registry.libraries()[m->library].version}};
    }
    if (!ok) continue;
    sim->models_used[sd_name] = used;
    auto sub = std::make_unique<Subdomain>(sd_name, alpha, mat_index.at(mat_name),
                                           std::make_unique<ContactPipeline>(std::move(slots)));
    std::vector<PairCoefficients> wall_coeffs;
    for (const auto& w : sim->walls)
      wall_coeffs.push_back(coeffs.at(std::minmax(mat_name, sim->materials[w.material].name)));
    sub->set_environment(sim->materials, wall_coeffs, coeffs.at(std::minmax(mat_name, mat_name)), &sim->walls,
                         sim->gravity);

    // insertion: a state file first, then the inserters (which avoid its particles)
    const std::size_t problems_before_insert = ck.diags.size();
    if (sd.contains("initial_state")) {
      const std::filesystem::path f = scenario_path(file, sd["initial_state"].get<std::string>());
      try {
        ParticleStore& st = sub->store();
        const double density = sim->materials[mat_index.at(mat_name)].density;
        // streamed into the store, which is sized from the file's line count
        // first (an upper bound): no copy of the rows, no doubling slack
        st.reserve(st.size() + io::count_lines(f));
        const std::size_t rows = io::for_each_particle_state_row(f, [&](const io::ParticleStateRow& p) {
          st.add(next_id++, p.x, p.y, p.z, p.radius, density, p.fixed);
          if (p.fixed) return;  // a fixed particle stays at rest
          st.vx.back() = p.vx; st.vy.back() = p.vy; st.vz.back() = p.vz;
          st.wx.back() = p.wx; st.wy.back() = p.wy; st.wz.back() = p.wz;
        });
        spdlog::info("subdomain '{}': {} particles from {} (contact history starts at zero)", sd_name, rows,
                     f.string());
      } catch (const std::exception& e) {
        ck.add(base + "/initial_state", e.what());
      }
    }
    if (sd.contains("insert")) {
      for (std::size_t q = 0; q < sd["insert"].size(); ++q) {
        const json& block = sd["insert"][q];
        const std::string where = idx(base + "/insert", q);
        const RegisteredModel* m = registry.find(DOMEL_KIND_INSERTION, block["model"].get<std::string>());
        try {
          ModelInstance inst(*m, plugin_params(block, DOMEL_KIND_INSERTION), "subdomain '" + sd_name + "'");
          ParticleStore& st = sub->store();
          domel_insert_request_v1 req{};
          req.struct_size = sizeof(req);
          req.region = make_region(block["region"]);
          req.seed = block.contains("seed") ? block["seed"].get<std::uint64_t>()
                                            : sim->seed * 1000003ull + name_hash + q;
          req.length_scale = alpha;
          req.n_existing = st.size();
          req.ex_x = st.x.data(); req.ex_y = st.y.data(); req.ex_z = st.z.data(); req.ex_r = st.radius.data();
          std::vector<double> x, y, z, r;
          inst.insert(req, x, y, z, r);
          double v[3] = {0, 0, 0};
          if (block.contains("velocity"))
            for (int a = 0; a < 3; ++a) v[a] = block["velocity"][a].get<double>();
          const double density = sim->materials[mat_index.at(mat_name)].density;
          const bool fixed = block.value("fixed", false);
          st.reserve(st.size() + x.size());
          for (std::size_t p = 0; p < x.size(); ++p) {
            st.add(next_id++, x[p], y[p], z[p], r[p], density, fixed);
            st.vx.back() = v[0]; st.vy.back() = v[1]; st.vz.back() = v[2];
          }
          spdlog::info("subdomain '{}': inserted {} particles with '{}' ({})", sd_name, x.size(), m->name, where);
          if (x.empty()) spdlog::warn("subdomain '{}': {} inserted no particles", sd_name, where);
        } catch (const PluginError& e) {
          ck.add(where, e.what());
        }
      }
    }

    // pours: their model instances live for the run; one dry event per pour
    // (no particle present) gives the radii it will insert, for the skin and
    // the time step of a subdomain that starts empty.
    std::vector<double> pour_radii;
    if (sd.contains("pour")) {
      for (std::size_t q = 0; q < sd["pour"].size(); ++q) {
        const json& pb = sd["pour"][q];
        const json& block = pb["insert"];
        const std::string where = idx(base + "/pour", q);
        const RegisteredModel* m = registry.find(DOMEL_KIND_INSERTION, block["model"].get<std::string>());
        try {
          Pour p;
          p.where = where;
          p.subdomain = sim->subdomains.size();
          p.model = std::make_shared<ModelInstance>(*m, plugin_params(block, DOMEL_KIND_INSERTION), "subdomain '" + sd_name + "'");
          p.region = make_region(block["region"]);
          if (block.contains("velocity"))
            for (int a = 0; a < 3; ++a) p.velocity[a] = block["velocity"][a].get<double>();
          p.fixed = block.value("fixed", false);
          p.density = sim->materials[mat_index.at(mat_name)].density;
          p.alpha = alpha;
          p.mass_rate = pb["mass_rate"].get<double>();
          if (pb.contains("total_mass")) p.total_mass = pb["total_mass"].get<double>();
          p.start = pb.value("start", 0.0);
          if (pb.contains("end")) p.end = pb["end"].get<double>();
          p.seed = block.contains("seed") ? block["seed"].get<std::uint64_t>()
                                          : sim->seed * 1000003ull + name_hash + 7919ull * (q + 1);
          if (pb.contains("interval")) {
            p.interval = pb["interval"].get<double>();
          } else {
            // the time the inserted particles need to leave the region
            const double speed = std::sqrt(p.velocity[0] * p.velocity[0] + p.velocity[1] * p.velocity[1] +
                                           p.velocity[2] * p.velocity[2]);
            const double g = std::sqrt(sim->gravity[0] * sim->gravity[0] + sim->gravity[1] * sim->gravity[1] +
                                       sim->gravity[2] * sim->gravity[2]);
            if (speed > 0) {
              const double u[3] = {p.velocity[0] / speed, p.velocity[1] / speed, p.velocity[2] / speed};
              p.interval = region_extent(p.region, u) / speed;
            } else if (g > 0) {
              const double u[3] = {sim->gravity[0] / g, sim->gravity[1] / g, sim->gravity[2] / g};
              p.interval = std::sqrt(2.0 * region_extent(p.region, u) / g);
            } else {
              p.interval = 0.01;
            }
          }
          domel_insert_request_v1 req{};
          req.struct_size = sizeof(req);
          req.region = p.region;
          req.seed = p.seed;
          req.length_scale = alpha;
          std::vector<double> x, y, z, r;
          p.model->insert(req, x, y, z, r);
          if (x.empty()) {
            ck.add(where + "/insert", "the insertion model placed no particle in the pour region",
                   "enlarge the region or raise the model's volume_fraction / count");
            continue;
          }
          pour_radii.insert(pour_radii.end(), r.begin(), r.end());
          double one_event = 0;
          for (double rr : r) one_event += p.density * 4.0 / 3.0 * M_PI * rr * rr * rr;
          spdlog::info("subdomain '{}': pour {} inserts {:.4g} kg/s with '{}' every {:.4g} s (one full region: {} "
                       "particles, {:.4g} kg)",
                       sd_name, where, p.mass_rate, m->name, p.interval, x.size(), one_event);
          if (one_event < p.mass_rate * p.interval)
            spdlog::warn("{}: one filled pour region ({:.3g} kg) holds less than the mass of one interval ({:.3g} kg); "
                         "the pour will fall behind its rate", where, one_event, p.mass_rate * p.interval);
          sim->flow.pours.push_back(std::move(p));
        } catch (const PluginError& e) {
          ck.add(where + "/insert", e.what());
        }
      }
    }

    if (ck.diags.size() > problems_before_insert) continue;  // no time step from a half-built subdomain

    // neighbour skin: fraction of the largest diameter
    double rmax = 0;
    for (double r : sub->store().radius) rmax = std::max(rmax, r);
    for (double r : pour_radii) rmax = std::max(rmax, r);
    sub->set_skin(sd.value("skin", 0.5) * 2.0 * (rmax > 0 ? rmax : 1e-3));
    sub->set_reorder_every(sd.value("reorder_every", static_cast<std::size_t>(20)));

    // time step
    const double v_imp = sd.value("impact_velocity", 1.0);
    TimeStepReport rep;
    // a pour's smallest particle, present only for the estimate (the
    // smallest particle sets the Rayleigh time)
    const bool probe_particle = !pour_radii.empty();
    if (probe_particle)
      sub->store().add(0, 0.0, 0.0, 0.0, *std::min_element(pour_radii.begin(), pour_radii.end()),
                       sim->materials[mat_index.at(mat_name)].density);
    try {
      rep = sub->estimate_time_step(v_imp);
    } catch (const PluginError& e) {
      ck.add(base + "/contact", std::string("the contact model failed while estimating the time step: ") + e.what());
      continue;
    }
    if (probe_particle) sub->store().swap_remove(sub->store().size() - 1);
    const json ts = sd.value("time_step", json("auto"));
    if (sub->store().size() == 0 && !probe_particle) {
      if (!ts.is_number()) {
        ck.add(base + "/time_step", "cannot choose a time step automatically for a subdomain without particles",
               "give time_step in seconds");
        continue;
      }
      rep.chosen = ts.get<double>();
      rep.reason = "given (no particles to check it against)";
    } else if (ts.is_number()) {
      rep.chosen = ts.get<double>();
      rep.reason = "given";
      if (rep.chosen > rep.critical) {
        ck.add(base + "/time_step",
               "time step " + fmt_num(rep.chosen) + " s exceeds the explicit stability limit " + fmt_num(rep.critical) +
                   " s set by the " + rep.critical_of + " (impact velocity " + fmt_num(v_imp) + " m/s, contact time " +
                   fmt_num(rep.contact_time) + " s)",
               "use at most " + fmt_num(rep.critical) + " s, or \"auto\"");
        continue;
      }
      if (rep.chosen > rep.contact_time / 20.0)
        spdlog::warn("subdomain '{}': time step {:.3g} s resolves a collision ({:.3g} s) with only {:.0f} steps; "
                     "expect inaccurate restitution (20-50 steps per contact are usual)",
                     sd_name, rep.chosen, rep.contact_time, rep.contact_time / rep.chosen);
    } else {
      const double by_rayleigh = 0.2 * rep.rayleigh, by_contact = rep.contact_time / 50.0;
      rep.chosen = std::min({by_rayleigh, by_contact, 0.5 * rep.critical});
      rep.reason = rep.chosen == by_rayleigh   ? "auto: 0.2 x Rayleigh time"
                   : rep.chosen == by_contact ? "auto: contact time / 50"
                                              : "auto: half the stability limit of the " + rep.critical_of;
    }
    sub->set_time_step(rep.chosen);
    spdlog::info("subdomain '{}': {} particles, time step {:.4g} s ({}); Rayleigh time {:.4g} s, contact time {:.4g} s "
                 "at {:.3g} m/s, stability limit {:.4g} s ({})",
                 sd_name, sub->store().size(), rep.chosen, rep.reason, rep.rayleigh, rep.contact_time, v_imp,
                 rep.critical, rep.critical_of);
    sim->time_steps.push_back(rep);
    sim->subdomains.push_back(std::move(sub));
  }
  sim->flow.next_id = next_id;
  for (int a = 0; a < 3; ++a) sim->flow.gravity[a] = sim->gravity[a];
  sim->flow.deletion_interval = run.value("deletion_interval", 0.005);
  if (doc.contains("deletion_regions"))
    for (const auto& d : doc["deletion_regions"]) {
      DeletionRegion dr;
      dr.name = d["name"].get<std::string>();
      dr.region = make_region(d["region"]);
      if (d.contains("rate_window"))
        for (int a = 0; a < 2; ++a) dr.rate_window[a] = d["rate_window"][a].get<double>();
      sim->flow.deletions.push_back(dr);
    }
  if (doc.contains("output") && doc["output"].contains("mass_flow"))
    for (const auto& d : doc["output"]["mass_flow"]) {
      MassFlowPlane pl;
      pl.name = d["name"].get<std::string>();
      double len = 0;
      for (int a = 0; a < 3; ++a) {
        pl.p[a] = d["point"][a].get<double>();
        pl.n[a] = d["normal"][a].get<double>();
        len += pl.n[a] * pl.n[a];
      }
      for (int a = 0; a < 3; ++a) pl.n[a] /= std::sqrt(len);
      if (d.contains("rate_window"))
        for (int a = 0; a < 2; ++a) pl.rate_window[a] = d["rate_window"][a].get<double>();
      sim->flow.planes.push_back(pl);
    }
  if (doc.contains("output") && doc["output"].contains("grids")) {
    const json& gs = doc["output"]["grids"];
    for (std::size_t g = 0; g < gs.size(); ++g) {
      const json& gj = gs[g];
      Simulation::GridSetup setup;
      setup.spec.name = gj["name"].get<std::string>();
      for (int a = 0; a < 3; ++a) {
        setup.spec.lo[a] = gj["min"][a].get<double>();
        setup.spec.hi[a] = gj["max"][a].get<double>();
        setup.spec.cells[a] = gj["cells"][a].get<int>();
      }
      setup.spec.every = gj.value("every", 15);
      setup.spec.write_interval = -1.0;  // default set below, once the duration is known
      if (gj.contains("write_interval")) setup.spec.write_interval = gj["write_interval"].get<double>();
      setup.spec.accessible_samples = gj.value("accessible_samples", 8);
      setup.profile_axis = axis_index(member(gj, "profile_axis"));
      if (gj.contains("subdomain")) {
        const std::string want = gj["subdomain"].get<std::string>();
        std::vector<std::string> names;
        bool found = false;
        for (std::size_t k = 0; k < sim->subdomains.size(); ++k) {
          names.push_back(sim->subdomains[k]->name());
          if (names.back() == want) {
            setup.subdomain = k;
            found = true;
          }
        }
        if (!found) ck.add(idx("/output/grids", g) + "/subdomain", "unknown subdomain '" + want + "'", suggest(want, names));
      } else if (sim->subdomains.size() > 1) {
        ck.add(idx("/output/grids", g), "missing required property 'subdomain'",
               "the scenario has more than one subdomain; name the one this grid averages");
      }
      bool corners = true;
      for (int a = 0; a < 3; ++a)
        if (setup.spec.hi[a] <= setup.spec.lo[a]) {
          corners = false;
          ck.add(idx("/output/grids", g) + "/max/" + std::to_string(a),
                 "expected max > min along " + std::string(1, "xyz"[a]) + ", found max " + fmt_num(setup.spec.hi[a]) +
                     " <= min " + fmt_num(setup.spec.lo[a]));
        }
      if (corners) try {
          CellGrid probe(setup.spec);  // the grid's own checks
        } catch (const std::invalid_argument& e) {
          ck.add(idx("/output/grids", g), e.what());
        }
      for (std::size_t h = 0; h < g; ++h)
        if (gs[h]["name"] == gj["name"])
          ck.add(idx("/output/grids", g) + "/name", "duplicate grid name '" + setup.spec.name + "'");
      sim->grid_setups.push_back(setup);
    }
  }
  if (!ck.diags.empty()) throw ConfigError(ck.diags);

  if (run.contains("duration")) {
    sim->duration = run["duration"].get<double>();
  } else {
    sim->duration = static_cast<double>(run["steps"].get<std::uint64_t>()) * sim->macro_step();
  }
  const json out = doc.value("output", json::object());
  sim->output_directory = out.value("directory", sim->name + "_out");
  sim->vtk_interval = out.value("vtk_interval", sim->duration / 50.0);
  sim->probe_interval = out.value("probe_interval", sim->duration / 500.0);
  sim->write_state = out.value("state", false);
  for (auto& g : sim->grid_setups)
    if (g.spec.write_interval < 0) g.spec.write_interval = sim->duration / 20.0;
  if (out.contains("repose_angle")) {
    const json& r = out["repose_angle"];
    ReposeProbeSettings rp;
    rp.base_height = r.value("base_height", 0.0);
    rp.cell = r.value("cell", 1.5);
    if (r.contains("band")) {
      rp.band_lo = r["band"][0].get<double>();
      rp.band_hi = r["band"][1].get<double>();
    }
    sim->repose_probe = rp;
  }
  return sim;
}

}  // namespace

std::vector<Diagnostic> validate_scenario_file(const std::filesystem::path& file, PluginRegistry& registry) {
  std::vector<Diagnostic> diags;
  const json doc = read_json_file(file, diags);
  if (!diags.empty()) return diags;
  return validate_document(doc, file, registry);
}

std::unique_ptr<Simulation> load_scenario(const nlohmann::json& doc, const std::filesystem::path& file,
                                          PluginRegistry& registry) {
  auto diags = validate_document(doc, file, registry);
  if (!diags.empty()) throw ConfigError(diags);
  return build(doc, file, registry);
}

std::unique_ptr<Simulation> load_scenario(const std::filesystem::path& file, PluginRegistry& registry) {
  std::vector<Diagnostic> diags;
  const json doc = read_json_file(file, diags);
  if (!diags.empty()) throw ConfigError(diags);
  return load_scenario(doc, file, registry);
}

}  // namespace domel::platform
