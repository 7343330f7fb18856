// SPDX-License-Identifier: MIT
// Scenario validation passes, the filling of schema defaults, and the
// composition of the schema for editors; the Simulation is built from the
// filled document by builders.cpp. About 790 lines in one file: the passes
// run in order over one document and share its name lookups (materials,
// subdomains, walls, models) and the composed schema they check against;
// each pass is one function here.
#include "scenario/scenario.hpp"

#include "outputs/output_kinds.hpp"

#include "core/rotation.hpp"

#include "geometry/region.hpp"
#include "geometry/triangle_mesh.hpp"
#include "io/particle_state.hpp"
#include "scenario/json_schema.hpp"
#include "scenario/scenario_detail.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace domel::platform {

extern const char* const kScenarioSchemaText;

using namespace scenario_detail;

namespace {

json platform_block_properties(uint32_t kind) {
  const json& defs = platform_scenario_schema()["$defs"];
  if (kind == DOMEL_KIND_INSERTION) return defs["insertion_model"]["properties"];
  if (kind == DOMEL_KIND_FLUID_COUPLER) return defs["fluid_model"]["properties"];
  if (kind == DOMEL_KIND_CONTROLLER)  // a controller block's own key beside the model's parameters
    return json{{"enabled", defs["coupling"]["properties"]["velocity_control"]["properties"]["enabled"]}};
  return json::object();
}


/// What must not cross periodic axis a ([lo, hi]) of subdomain `sd_name`
/// (reported at `pointer`, the periodic range): walls not invariant along
/// the axis, couplings and a fluid block, mass-flow planes across it.
void check_periodic_axis(const json& doc, int a, double lo, double hi, const std::string& sd_name,
                         const std::string& pointer, Checker& ck) {
  const std::string ax(1, static_cast<char>('x' + a));
  auto refuse = [&](const std::string& where, const std::string& what, const std::string& hint) {
    ck.add(where, what + ", across the periodic axis " + ax + " of subdomain '" + sd_name + "' (" + pointer + ")", hint);
  };
  if (const json* walls = member(doc, "walls"); walls && walls->is_array())
    for (std::size_t w = 0; w < walls->size(); ++w) {
      const json& wall = (*walls)[w];
      const std::string wb = idx("/walls", w);
      const std::string t = (member(wall, "type") && wall["type"].is_string()) ? wall["type"].get<std::string>() : "";
      if (t == "plane") {
        if (is_vec3(member(wall, "normal")) && std::fabs(wall["normal"][a].get<double>()) > 0)
          refuse(wb + "/normal", "a plane whose normal has an " + ax + " component",
                 "make the plane parallel to " + ax + ", or drop the periodic axis");
      } else if (t == "box") {
        std::set<std::string> open;
        if (const json* o = member(wall, "open"); o && o->is_array())
          for (const auto& f : *o)
            if (f.is_string()) open.insert(f.get<std::string>());
        if (!open.count(ax + "min") || !open.count(ax + "max"))
          refuse(wb + "/open", "a box with a face across " + ax, "add \"" + ax + "min\" and \"" + ax + "max\" to \"open\"");
      } else if (t == "cylinder") {
        const bool along = axis_index(member(wall, "axis")) == a;
        const double b0 = member(wall, "bottom") && wall["bottom"].is_number() ? wall["bottom"].get<double>() : 0.0;
        const double b1 = member(wall, "top") && wall["top"].is_number() ? wall["top"].get<double>() : 0.0;
        const bool closed = (!member(wall, "closed_bottom") || wall["closed_bottom"] == true) ||
                            (member(wall, "closed_top") && wall["closed_top"] == true);
        if (!along || closed || b0 > lo || b1 < hi)
          refuse(wb, std::string("a cylinder ") + (!along ? "whose axis is not " + ax : closed ? "with a bottom or lid" : "shorter than the periodic box"),
                 "a periodic pipe is a cylinder along " + ax + " with \"closed_bottom\": false reaching past both faces");
      } else if (!t.empty()) {
        refuse(wb + "/type", "a " + t + " wall", "only planes, open boxes and open cylinders are invariant along a periodic axis");
      }
    }
  if (const json* c = member(doc, "couplings"); c && c->is_array() && !c->empty())
    refuse("/couplings", "couplings between levels", "couplings do not support periodic boundaries yet");
  if (member(doc, "fluid")) refuse("/fluid", "a fluid block", "the fluid grid is not periodic yet");
  if (const json* out = member(doc, "output"))
    if (const json* planes = member(*out, "mass_flow"); planes && planes->is_array())
      for (std::size_t i = 0; i < planes->size(); ++i) {
        const json& pl = (*planes)[i];
        const bool other = (member(pl, "subdomain") && pl["subdomain"].is_string()) && pl["subdomain"].get<std::string>() != sd_name;
        if (!other && is_vec3(member(pl, "normal")) && std::fabs(pl["normal"][a].get<double>()) > 0)
          refuse(idx("/output/mass_flow", i) + "/normal", "a mass-flow plane whose normal has an " + ax + " component",
                 "particles re-entering through the periodic face would cross it backwards; measure the flux with "
                 "region_mass or the cell grids");
      }
}

}  // namespace

const json& platform_scenario_schema() {
  // the registered output kinds' blocks join the output block (outputs/output_kinds.hpp)
  static const json schema = [] {
    json s = json::parse(kScenarioSchemaText);
    for (const OutputKind& k : output_kinds()) s["$defs"]["output"]["properties"][k.key] = k.schema;
    return s;
  }();
  return schema;
}

/// Replace every {"$ref": "#/$defs/<name>"} of a plugin's schema by the
/// plugin's own definition (recursively, to a depth of 16), so that the
/// schema can sit inside the scenario's, whose "$defs" are the platform's.
void inline_plugin_refs(json& node, const json& defs, int depth = 0) {
  if (depth > 16) return;
  if (node.is_object()) {
    if (auto it = node.find("$ref"); it != node.end() && it->is_string()) {
      const std::string ref = it->get<std::string>();
      const std::string prefix = "#/$defs/";
      if (ref.rfind(prefix, 0) == 0 && defs.contains(ref.substr(prefix.size()))) {
        json resolved = defs[ref.substr(prefix.size())];
        for (auto& [k, v] : node.items())
          if (k != "$ref") resolved[k] = v;
        node = std::move(resolved);
        inline_plugin_refs(node, defs, depth + 1);
        return;
      }
    }
    for (auto& [k, v] : node.items()) inline_plugin_refs(v, defs, depth);
  } else if (node.is_array()) {
    for (auto& v : node) inline_plugin_refs(v, defs, depth);
  }
}

json model_block_schema(const RegisteredModel& model) {
  json s = model.schema.is_object() ? model.schema : json::object();
  if (s.contains("$defs") && s["$defs"].is_object()) {
    const json defs = s["$defs"];
    s.erase("$defs");
    inline_plugin_refs(s, defs);
  }
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
  if (model.desc.kind == DOMEL_KIND_FLUID_COUPLER) add_req("interval");
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
  fill("fluid_model", DOMEL_KIND_FLUID_COUPLER, false);
  // A coupling's controller blocks: any loaded controller's block; a block
  // without "model" is the default model's (its "model" not required).
  for (const char* key : {"stress_control", "velocity_control"}) {
    json& block = schema["$defs"]["coupling"]["properties"][key];
    const json fallback = block["properties"]["model"]["default"];
    json alternatives = json::array();
    for (const auto& m : registry.models()) {
      if (m.desc.kind != DOMEL_KIND_CONTROLLER) continue;
      json s = model_block_schema(m);
      alternatives.push_back(s);
      if (json(m.name) != fallback) continue;
      json& req = s["required"];
      req.erase(std::remove(req.begin(), req.end(), json("model")), req.end());
      alternatives.push_back(s);
    }
    if (!alternatives.empty()) block["anyOf"] = alternatives;
  }
  return schema;
}

namespace {

/// JSON pointers of the values the validation filled in from schema defaults.
using Filled = std::set<std::string>;

/// Validate one model block (contact slot or inserter) against its model's
/// schema, then fill that schema's defaults into it (the plugin's parameters
/// and the platform keys of the block). Returns the model or null.
const RegisteredModel* check_model_block(Checker& ck, const PluginRegistry& registry, json& block,
                                         const std::string& pointer, uint32_t kind, bool allow_none,
                                         const Filled& filled) {
  if (!block.is_object()) return nullptr;  // the platform schema already said so
  const json* name = member(block, "model");
  if (!name || !name->is_string()) return nullptr;
  const std::string model = name->get<std::string>();
  if (allow_none && model == "none") {
    if (block.size() > 1) ck.add(pointer, "an empty slot (\"none\") takes no parameters");
    return nullptr;
  }
  const RegisteredModel* m = registry.find(kind, model);
  if (!m && filled.count(pointer)) {  // the schema's default for an omitted slot
    ck.add(pointer, std::string("no ") + kind_name(kind) + " model '" + model + "' is loaded (the default of an omitted slot)",
           suggest(model, registry.names(kind)));
    return nullptr;
  }
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
    const SchemaValidator validator(schema);
    validator.validate(block, ck.diags, pointer);
    validator.fill_defaults(block, pointer);
  } catch (const std::exception& e) {
    ck.add(pointer, std::string(kind_name(kind)) + " model '" + model + "' has a parameter schema domel cannot use: " + e.what());
  }
  for (auto& d : ck.diags)
    if (d.file.empty()) d.file = ck.file.string();
  return m;
}

json* member_mut(json& j, const char* key) { return const_cast<json*>(member(j, key)); }

void check_models(Checker& ck, json& doc, const PluginRegistry& registry, const Filled& filled) {
  if (json* fluid = member_mut(doc, "fluid"))
    check_model_block(ck, registry, *fluid, "/fluid", DOMEL_KIND_FLUID_COUPLER, false, filled);
  if (json* its = member_mut(doc, "interactions"); its && its->is_array())
    for (std::size_t q = 0; q < its->size(); ++q)
      if (json* rolling = member_mut((*its)[q], "rolling"))
        check_model_block(ck, registry, *rolling, idx("/interactions", q) + "/rolling", DOMEL_KIND_ROLLING, true,
                          filled);
  if (json* cs = member_mut(doc, "couplings"); cs && cs->is_array())
    for (std::size_t q = 0; q < cs->size(); ++q)
      for (const char* key : {"stress_control", "velocity_control"})
        if (json* block = member_mut((*cs)[q], key))
          check_model_block(ck, registry, *block, idx("/couplings", q) + "/" + key, DOMEL_KIND_CONTROLLER, false,
                            filled);
  json* sds = member_mut(doc, "subdomains");
  if (!sds || !sds->is_array()) return;
  for (std::size_t k = 0; k < sds->size(); ++k) {
    json& sd = (*sds)[k];
    const std::string base = idx("/subdomains", k);
    if (json* contact = member_mut(sd, "contact"); contact && contact->is_object()) {
      for (std::size_t s = 0; s < kSlotCount; ++s) {
        json* block = member_mut(*contact, kSlotNames[s]);
        if (!block) continue;
        const bool optional = s >= static_cast<std::size_t>(Slot::rolling);
        if (!optional && block->is_object() && member_mut(*block, "model") && (*block)["model"] == "none")
          ck.add(base + "/contact/" + kSlotNames[s] + "/model",
                 std::string("the ") + kSlotNames[s] + " slot cannot be empty",
                 suggest("none", registry.names(kSlotKinds[s])));
        else
          check_model_block(ck, registry, *block, base + "/contact/" + kSlotNames[s], kSlotKinds[s], optional,
                            filled);
      }
    }
    if (json* ins = member_mut(sd, "insert"); ins && ins->is_array())
      for (std::size_t q = 0; q < ins->size(); ++q)
        check_model_block(ck, registry, (*ins)[q], idx(base + "/insert", q), DOMEL_KIND_INSERTION, false, filled);
    if (json* pours = member_mut(sd, "pour"); pours && pours->is_array())
      for (std::size_t q = 0; q < pours->size(); ++q)
        if (json* ins = member_mut((*pours)[q], "insert"))
          check_model_block(ck, registry, *ins, idx(base + "/pour", q) + "/insert", DOMEL_KIND_INSERTION, false,
                            filled);
  }
}

void check_references(Checker& ck, const json& doc, const Filled& filled) {
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
        // a default of another wall type's key (the wall schema is shared) was filled, not written
        if (!kAllowed.at(t).count(key) && key != "$comment" && !filled.count(base + "/" + escape_pointer_token(key)))
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
      if (const json* mo = member(w, "motion"); mo && (mo->is_object() || mo->is_array())) {
        const json items = mo->is_array() ? *mo : json::array({*mo});
        int servos = 0;
        const json* servo_dir = nullptr;  // the first servo's direction
        for (std::size_t i = 0; i < items.size(); ++i) {
          const json& m = items[i];
          if (!m.is_object()) continue;
          const std::string mp = base + "/motion" + (mo->is_array() ? "/" + std::to_string(i) : std::string());
          const json* st = member(m, "start");
          const json* en = member(m, "end");
          if (st && en && st->is_number() && en->is_number() && en->get<double>() <= st->get<double>())
            ck.add(mp + "/end", "expected end > start, found end " + fmt_num(en->get<double>()) + " <= start " +
                                    fmt_num(st->get<double>()));
          if (const json* sv = member(m, "servo")) {
            if (t == "box" || t == "cylinder" || t == "cone")
              ck.add(mp + "/servo", "a servo on a " + t + " wall, found one: the loads on its opposite sides cancel",
                     "put the servo on a plane, disk or mesh wall (a lid) of its own");
            if (++servos == 2)
              ck.add(mp + "/servo", "expected one servo per wall, found a second one",
                     "a wall holds one target force; give the other servo its own wall");
            auto given = [&](const char* k) {
              const json* v = member(m, k);
              if (!v) return false;
              if (!is_vec3(v)) return true;
              return (*v)[0].get<double>() != 0 || (*v)[1].get<double>() != 0 || (*v)[2].get<double>() != 0;
            };
            for (const char* other : {"velocity", "angular_velocity", "vibration"})
              if (given(other))
                ck.add(mp + "/" + other, std::string("a servo item moves the wall only along its direction, found \"") +
                                             other + "\" beside it",
                       "put the " + std::string(other) + " in an item of its own in a motion list");
            if (const json* dir = member(*sv, "direction"); is_vec3(dir) && (*dir)[0].get<double>() == 0 &&
                                                            (*dir)[1].get<double>() == 0 && (*dir)[2].get<double>() == 0)
              ck.add(mp + "/servo/direction", "expected a non-zero direction, found [0, 0, 0]");
          }
          const json* om = member(m, "angular_velocity");
          if (servo_dir && is_vec3(om) && is_vec3(servo_dir)) {
            // a rotation after a servo would turn the servo's direction away from the one it measures along
            const double wv[3] = {(*om)[0].get<double>(), (*om)[1].get<double>(), (*om)[2].get<double>()};
            const double u[3] = {(*servo_dir)[0].get<double>(), (*servo_dir)[1].get<double>(), (*servo_dir)[2].get<double>()};
            if (!parallel(wv, u))
              ck.add(mp + "/angular_velocity", "a rotation listed after a servo, about an axis not parallel to the servo's "
                                               "direction: it would turn the direction the servo measures along",
                     "list the rotation before the servo");
          }
          if (const json* sv = member(m, "servo"); sv && !servo_dir) {
            const json* dir = member(*sv, "direction");
            if (is_vec3(dir) && ((*dir)[0] != 0 || (*dir)[1] != 0 || (*dir)[2] != 0)) servo_dir = dir;
          }
          if (!is_vec3(om) || t == "mesh") continue;
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
          if (wl > 0 && t == "box") {
            ck.add(mp + "/angular_velocity", "a box wall cannot rotate, found a non-zero angular_velocity",
                   "use a mesh wall for a rotating box, or only a velocity");
          } else if (wl > 0 && have_axis && !parallel(wv, ax)) {
            ck.add(mp + "/angular_velocity",
                   "a " + t + " wall rotates only about an axis parallel to its own " +
                       (t == "plane" || t == "disk" ? "normal" : "axis") + ", found angular_velocity [" +
                       fmt_num(wv[0]) + ", " + fmt_num(wv[1]) + ", " + fmt_num(wv[2]) + "] not parallel to it",
                   "use a mesh wall for other rotations");
          }
        }
      }
    }
  }

  // gravity over time
  if (const json* g = member(doc, "gravity"); g && g->is_object()) {
    if (const json* tab = member(*g, "table"); tab && tab->is_array()) {
      for (std::size_t i = 1; i < tab->size(); ++i) {
        const json& r0 = (*tab)[i - 1];
        const json& r1 = (*tab)[i];
        if (r0.is_array() && r1.is_array() && !r0.empty() && !r1.empty() && r0[0].is_number() &&
            r1[0].is_number() && r1[0].get<double>() <= r0[0].get<double>())
          ck.add("/gravity/table/" + std::to_string(i) + "/0",
                 "expected times strictly increasing, found " + fmt_num(r1[0].get<double>()) + " after " +
                     fmt_num(r0[0].get<double>()));
      }
    }
    if (const json* ax = member(*g, "rotation"); ax && is_vec3(member(*ax, "axis")) &&
                                                 (*ax)["axis"][0].get<double>() == 0 &&
                                                 (*ax)["axis"][1].get<double>() == 0 &&
                                                 (*ax)["axis"][2].get<double>() == 0)
      ck.add("/gravity/rotation/axis", "expected a non-zero axis, found [0, 0, 0]");
    if (const json* rot = member(*g, "rotation")) {
      const json* st = member(*rot, "start");
      const json* en = member(*rot, "end");
      if (en && en->is_number() && en->get<double>() <= (st && st->is_number() ? st->get<double>() : 0.0))
        ck.add("/gravity/rotation/end", "expected end > start, found end " + fmt_num(en->get<double>()));
    }
    if (doc.contains("fluid"))
      ck.add("/gravity", "a fluid block needs a constant gravity, found one that changes with time",
             "give gravity as a vector");
  }

  // periodic boundaries: a valid box, and nothing across a periodic axis
  if (const json* sds = member(doc, "subdomains"); sds && sds->is_array())
    for (std::size_t k = 0; k < sds->size(); ++k) {
      const json* per = member((*sds)[k], "periodic");
      if (!per || !per->is_object()) continue;
      const std::string base = idx("/subdomains", k) + "/periodic";
      const std::string sd_name = (member((*sds)[k], "name") && (*sds)[k]["name"].is_string()) ? (*sds)[k]["name"].get<std::string>() : "";
      for (int a = 0; a < 3; ++a) {
        const std::string ax(1, static_cast<char>('x' + a));
        const json* range = member(*per, ax.c_str());
        if (!range || !range->is_array() || range->size() != 2 || !(*range)[0].is_number() || !(*range)[1].is_number())
          continue;
        const double lo = (*range)[0].get<double>(), hi = (*range)[1].get<double>();
        if (hi <= lo)
          ck.add(base + "/" + ax, "expected lo < hi, found [" + fmt_num(lo) + ", " + fmt_num(hi) + "]");
        check_periodic_axis(doc, a, lo, hi, sd_name, base + "/" + ax, ck);
      }
    }

  // subdomains
  std::set<std::string> sd_names;
  // (subdomain, its materials: its own first, then those its insertions and pours name)
  std::vector<std::pair<std::string, std::vector<std::string>>> sd_materials;
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
        sd_materials.emplace_back(name && name->is_string() ? name->get<std::string>() : std::to_string(k),
                                  std::vector<std::string>{mat});
        // the materials of its insertions and pours (a mixture)
        auto insert_material = [&](const json& block, const std::string& pointer) {
          for (const auto& [name, at] : insertion_material_names(block)) {
            const json value = name;
            const std::string m = check_material(&value, pointer + at);
            if (m.empty()) continue;
            if (!has_density[m])
              ck.add("/materials/" + escape_pointer_token(m), "missing required property 'density'",
                     pointer + " makes particles of this material");
            auto& list = sd_materials.back().second;
            if (std::find(list.begin(), list.end(), m) == list.end()) list.push_back(m);
          }
        };
        if (const json* ins = member(sd, "insert"); ins && ins->is_array())
          for (std::size_t q = 0; q < ins->size(); ++q) insert_material((*ins)[q], idx(base + "/insert", q));
        if (const json* pours = member(sd, "pour"); pours && pours->is_array())
          for (std::size_t q = 0; q < pours->size(); ++q)
            if (const json* ins = member((*pours)[q], "insert"))
              insert_material(*ins, idx(base + "/pour", q) + "/insert");
      }
      if (const json* st = member(sd, "initial_state"); st && st->is_string() && !st->get<std::string>().empty()) {
        const std::filesystem::path f = scenario_path(ck.file, st->get<std::string>());
        try {
          std::set<std::string> names;  // a mixture's (v2) materials
          if (io::for_each_particle_state_row(f, [&](const io::ParticleStateRow& p) { names.insert(p.material); }) == 0)
            ck.add(base + "/initial_state", "expected at least one particle in " + f.string() + ", found none");
          for (const auto& n : names) {
            if (n.empty()) continue;
            if (std::find(materials.begin(), materials.end(), n) == materials.end()) {
              ck.add(base + "/initial_state", "the state file " + f.string() + " holds particles of material '" + n +
                                                  "', which is not in /materials", suggest(n, materials));
              continue;
            }
            if (!has_density[n])
              ck.add("/materials/" + escape_pointer_token(n), "missing required property 'density'",
                     base + "/initial_state makes particles of this material");
            if (!mat.empty()) {  // this subdomain's list is the last one
              auto& list = sd_materials.back().second;
              if (std::find(list.begin(), list.end(), n) == list.end()) list.push_back(n);
            }
          }
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
          const json* a = member(p, "start");  // filled from the schema's default when omitted
          const json* b = member(p, "end");
          if (!a || !a->is_number()) continue;
          const double start = a->get<double>();
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
  for (const auto& [sd, mats] : sd_materials)
    for (std::size_t a = 0; a < mats.size(); ++a) {
      for (std::size_t b = a; b < mats.size(); ++b)
        need(mats[a], mats[b],
             mats.size() == 1 ? "subdomain '" + sd + "'"
                              : "subdomain '" + sd + "', whose particles of " + mats[a] + " touch those of " + mats[b]);
      for (const auto& [wall, wmat] : wall_materials)
        need(mats[a], wmat, "subdomain '" + sd + "' touching wall '" + wall + "'");
    }
}

/// The passes, in order; fills the schema defaults into `doc` on the way
/// (after the platform schema's check, so that the later passes and the
/// builders read every defaulted value from the document).
namespace {

/// Material and interaction values against the ranges the schema gives them
/// ("x-plausible": a range and where it comes from): outside, refused at
/// their pointer with the range, unless /run/allow_implausible (then a
/// warning each). A value the schema refused already is left to that.
void check_plausible(Checker& ck, const json& doc) {
  const json& defs = platform_scenario_schema()["$defs"];
  const json* run = member(doc, "run");
  const json* allow_j = run ? member(*run, "allow_implausible") : nullptr;
  const bool allow = allow_j && allow_j->is_boolean() && allow_j->get<bool>();
  auto refused_already = [&](const std::string& ptr) {
    return std::any_of(ck.diags.begin(), ck.diags.end(), [&](const Diagnostic& d) { return d.pointer == ptr; });
  };
  auto check = [&](const json& object, const json& properties, const std::string& at) {
    if (!object.is_object()) return;
    for (const auto& [key, prop] : properties.items()) {
      const json* plausible = member(prop, "x-plausible");
      const json* v = member(object, key.c_str());
      if (!plausible || !v || !v->is_number()) continue;
      const std::string ptr = at + "/" + key;
      const double x = v->get<double>();
      const double lo = (*plausible)["range"][0].get<double>(), hi = (*plausible)["range"][1].get<double>();
      if ((x >= lo && x <= hi) || refused_already(ptr)) continue;
      const json* unit_j = member(prop, "x-unit");
      const std::string unit = unit_j && unit_j->is_string() ? unit_j->get<std::string>() : "1";
      auto num = [](double d) {
        std::ostringstream os;
        os << std::setprecision(6) << d;
        return os.str();
      };
      const std::string msg = "expected a plausible value within [" + num(lo) + ", " + num(hi) + "]" +
                              (unit == "1" ? "" : " " + unit) + " (" + (*plausible)["why"].get<std::string>() +
                              "), found " + fmt_num(x);
      if (allow)
        spdlog::warn("{}: {}; accepted (/run/allow_implausible)", ptr, msg);
      else
        ck.add(ptr, msg,
               "if it is meant (a scaled density, a deliberately extreme value), set /run/allow_implausible to "
               "true; a scenario in other units needs converting to SI (m, kg, s)");
    }
  };
  if (const json* mats = member(doc, "materials"); mats && mats->is_object())
    for (const auto& [name, m] : mats->items())
      check(m, defs["material"]["properties"], "/materials/" + escape_pointer_token(name));
  if (const json* its = member(doc, "interactions"); its && its->is_array())
    for (std::size_t k = 0; k < its->size(); ++k)
      check((*its)[k], defs["interaction"]["properties"], idx("/interactions", k));
}

}  // namespace

std::vector<Diagnostic> validate_document(json& doc, const std::filesystem::path& file, PluginRegistry& registry) {
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
  static const SchemaValidator platform(platform_scenario_schema());
  platform.validate(doc, ck.diags);
  for (auto& d : ck.diags)
    if (d.file.empty()) d.file = file.string();
  const std::vector<std::string> filled_list = platform.fill_defaults(doc);
  const Filled filled(filled_list.begin(), filled_list.end());
  check_models(ck, doc, registry, filled);
  check_references(ck, doc, filled);
  check_plausible(ck, doc);
  return ck.diags;
}

/// Deepest nesting of arrays and objects a scenario may have. The deepest
/// shipped scenario nests 7 levels; the validator and the builders recurse
/// once per level, so a document nested hundreds of thousands deep would
/// overflow the stack.
constexpr std::size_t kMaxJsonDepth = 64;

/// Where the text first nests deeper than kMaxJsonDepth (outside strings),
/// as "line L, column C"; empty when it never does.
std::string too_deep_at(const std::string& text) {
  std::size_t depth = 0, line = 1, column = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    ++column;
    if (c == '\n') {
      ++line;
      column = 0;
    }
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return "line " + std::to_string(line) + ", column " + std::to_string(column);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return {};
}

/// Where a number beyond the range of a double stands: the JSON parser's
/// DOM build refuses it without a position, so the text is read once more
/// through the SAX interface, which follows the keys and indices down to it
/// and gets the parser's line and column.
struct OverflowLocator {
  struct Level {
    bool array;
    std::size_t index;
    std::string key;
  };
  std::vector<Level> levels;
  std::string pointer;
  std::size_t offset = std::string::npos;  ///< of the number's first character

  void value() {
    if (!levels.empty() && levels.back().array) ++levels.back().index;
  }
  std::string here() const {
    std::string p;
    for (const Level& l : levels) {
      if (l.array) {
        p += "/" + std::to_string(l.index);
        continue;
      }
      p += "/" + escape_pointer_token(l.key);
    }
    return p;
  }
  bool null() { value(); return true; }
  bool boolean(bool) { value(); return true; }
  bool number_integer(json::number_integer_t) { value(); return true; }
  bool number_unsigned(json::number_unsigned_t) { value(); return true; }
  bool number_float(json::number_float_t, const std::string&) { value(); return true; }
  bool string(std::string&) { value(); return true; }
  bool binary(json::binary_t&) { value(); return true; }
  bool start_object(std::size_t) { levels.push_back({false, 0, {}}); return true; }
  bool key(std::string& k) { levels.back().key = k; return true; }
  bool end_object() { levels.pop_back(); value(); return true; }
  bool start_array(std::size_t) { levels.push_back({true, 0, {}}); return true; }
  bool end_array() { levels.pop_back(); value(); return true; }
  // position: the characters read, the token included (an array's index counts the values before it)
  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception&) {
    pointer = here();
    offset = position >= token.size() ? position - token.size() : 0;
    return false;
  }
};

json read_json_file(const std::filesystem::path& file, std::vector<Diagnostic>& diags) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) {
    diags.push_back({file.string(), "", "is a folder, not a scenario file", "name the scenario's .json file"});
    return {};
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    diags.push_back({file.string(), "", "cannot open the scenario file", "check the path"});
    return {};
  }
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  if (const std::string at = too_deep_at(text); !at.empty()) {
    diags.push_back({file.string(), "", "arrays and objects nest deeper than " + std::to_string(kMaxJsonDepth) +
                                            " levels at " + at + "; a scenario nests a few levels",
                     "look for a bracket that is never closed"});
    return {};
  }
  auto message = [](const json::exception& e) {
    std::string what = e.what();
    const auto pos = what.find("] ");
    return pos == std::string::npos ? what : what.substr(pos + 2);
  };
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    diags.push_back({file.string(), "", "not valid JSON: " + message(e),
                     "look for a missing ',' or '\"' just before that position, or a trailing ','"});
  } catch (const json::out_of_range& e) {
    // a number beyond the range of a double, e.g. 1e400: where it stands
    OverflowLocator where;
    json::sax_parse(text, &where);
    std::string at;
    if (where.offset != std::string::npos && where.offset <= text.size()) {
      const std::size_t line = 1 + std::count(text.begin(), text.begin() + where.offset, '\n');
      const std::size_t start = text.rfind('\n', where.offset == 0 ? 0 : where.offset - 1);
      const std::size_t column = where.offset - (start == std::string::npos || where.offset == 0 ? 0 : start + 1) + 1;
      at = " at line " + std::to_string(line) + ", column " + std::to_string(column);
    }
    diags.push_back({file.string(), where.pointer, "not a usable number" + at + ": " + message(e) +
                                                       " (beyond +-1.8e308, the range of a double)",
                     "write the number in SI units within the range of a double"});
  } catch (const json::exception& e) {
    diags.push_back({file.string(), "", "not valid JSON: " + message(e), ""});
  }
  return {};
}

}  // namespace

namespace {
std::atomic<std::size_t> g_particle_ceiling{0};
}  // namespace

void set_particle_ceiling(std::size_t n) { g_particle_ceiling = n; }
std::size_t particle_ceiling() { return g_particle_ceiling; }

std::vector<Diagnostic> validate_scenario_file(const std::filesystem::path& file, PluginRegistry& registry) {
  std::vector<Diagnostic> diags;
  json doc = read_json_file(file, diags);
  if (!diags.empty()) return diags;
  diags = validate_document(doc, file, registry);
  if (!diags.empty()) return diags;
  // What only the build can check (time steps, grids against the particle
  // sizes, couplings between levels) is part of validation too.
  try {
    build(doc, file, registry);
  } catch (const ConfigError& e) {
    return e.diagnostics();
  }
  return diags;
}

std::unique_ptr<Simulation> load_scenario(const nlohmann::json& doc, const std::filesystem::path& file,
                                          PluginRegistry& registry) {
  json filled = doc;
  auto diags = validate_document(filled, file, registry);
  if (!diags.empty()) throw ConfigError(diags);
  return build(filled, file, registry);
}

std::unique_ptr<Simulation> load_scenario(const std::filesystem::path& file, PluginRegistry& registry) {
  std::vector<Diagnostic> diags;
  json doc = read_json_file(file, diags);
  if (!diags.empty()) throw ConfigError(diags);
  auto more = validate_document(doc, file, registry);
  if (!more.empty()) throw ConfigError(more);
  return build(doc, file, registry);
}

}  // namespace domel::platform
