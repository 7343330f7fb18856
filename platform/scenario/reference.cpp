// SPDX-License-Identifier: MIT
// Schema -> parameter tables and the Markdown scenario reference.
#include "scenario/reference.hpp"

#include "scenario/scenario.hpp"

#include <iomanip>
#include <sstream>
#include <vector>

namespace domel::platform {

namespace {

using nlohmann::json;

const json& resolve(const json& s, const json& root) {
  if (s.is_object() && s.contains("$ref") && s["$ref"].is_string()) {
    const std::string ref = s["$ref"].get<std::string>();
    if (ref.rfind("#", 0) == 0) {
      try {
        return root.at(json::json_pointer(ref.substr(1)));
      } catch (const std::exception&) {
      }
    }
  }
  return s;
}

std::string compact(const json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

std::string type_of(const json& s, const json& root) {
  const json& r = resolve(s, root);
  if (r.contains("type")) {
    if (r["type"].is_string()) {
      std::string t = r["type"].get<std::string>();
      if (t == "array" && r.contains("items")) {
        const json& it = resolve(r["items"], root);
        if (it.contains("type") && it["type"].is_string()) t = it["type"].get<std::string>() + "[]";
        if (r.contains("minItems") && r.contains("maxItems") && r["minItems"] == r["maxItems"])
          t += std::to_string(r["minItems"].get<int>());
      }
      if (s.contains("$ref") && s["$ref"] == "#/$defs/vec3") t = "vec3";
      return t;
    }
    return compact(r["type"]);
  }
  if (r.contains("enum")) return "enum";
  if (r.contains("const")) return "const " + compact(r["const"]);
  if (r.contains("oneOf")) {
    std::string t;
    for (const auto& alt : r["oneOf"]) t += (t.empty() ? "" : " | ") + type_of(alt, root);
    return t;
  }
  if (s.contains("$ref")) return "object (" + s["$ref"].get<std::string>().substr(8) + ")";
  return "any";
}

std::string constraint_of(const json& s, const json& root) {
  const json& r = resolve(s, root);
  std::string c;
  auto add = [&](const std::string& x) { c += (c.empty() ? "" : ", ") + x; };
  if (r.contains("minimum")) add(">= " + r["minimum"].dump());
  if (r.contains("exclusiveMinimum")) add("> " + r["exclusiveMinimum"].dump());
  if (r.contains("maximum")) add("<= " + r["maximum"].dump());
  if (r.contains("exclusiveMaximum")) add("< " + r["exclusiveMaximum"].dump());
  if (r.contains("x-plausible")) {  // refused outside unless run.allow_implausible
    auto num = [](const json& v) {
      std::ostringstream os;
      os << std::setprecision(6) << v.get<double>();
      return os.str();
    };
    add("plausible " + num(r["x-plausible"]["range"][0]) + " to " + num(r["x-plausible"]["range"][1]) + " (" +
        r["x-plausible"]["why"].get<std::string>() + "; run.allow_implausible accepts more)");
  }
  if (r.contains("enum")) {
    std::string e;
    for (const auto& v : r["enum"]) e += (e.empty() ? "" : ", ") + v.dump();
    add("one of " + e);
  }
  if (r.contains("items")) {
    const json& it = resolve(r["items"], root);
    if (it.contains("enum")) {
      std::string e;
      for (const auto& v : it["enum"]) e += (e.empty() ? "" : ", ") + v.dump();
      add("items: " + e);
    }
  }
  if (r.contains("oneOf"))
    for (const auto& alt : r["oneOf"]) {
      const std::string sub = constraint_of(alt, root);
      if (!sub.empty()) add(sub);
    }
  return c;
}

std::string md_escape(std::string s) {
  std::string out;
  for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return out;
}

void table(std::ostringstream& os, const json& schema, const json& root) {
  const auto rows = parameter_rows(schema, root);
  if (rows.empty()) {
    os << "No parameters.\n\n";
    return;
  }
  os << "| key | type | unit | required | default | allowed | description |\n";
  os << "|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    os << "| `" << r.name << "` | " << md_escape(r.type) << " | " << r.unit << " | " << (r.required ? "yes" : "no")
       << " | " << md_escape(r.default_value) << " | " << md_escape(r.constraint) << " | "
       << md_escape(r.description) << " |\n";
  os << "\n";
  if (schema.contains("oneOf")) {
    os << "Exactly one of these key sets is required: ";
    std::string alts;
    for (const auto& alt : schema["oneOf"])
      if (alt.contains("required")) {
        std::string keys;
        for (const auto& k : alt["required"]) keys += (keys.empty() ? "" : " + ") + std::string("`") + k.get<std::string>() + "`";
        alts += (alts.empty() ? "" : "; ") + keys;
      }
    os << alts << ".\n\n";
  }
}

/// The members of an object-valued property, as a table each, one level at
/// a time down to `depth`: `prefix.name` headings, siblings with the same
/// schema (a box's six sides) under one heading.
void nested_tables(std::ostringstream& os, const json& schema, const json& root, const std::string& prefix,
                   int depth) {
  const json& s = resolve(schema, root);
  if (depth <= 0 || !s.contains("properties")) return;
  std::vector<std::pair<std::string, std::vector<std::string>>> groups;  // schema text -> names
  for (const auto& [name, prop] : s["properties"].items()) {
    const json& r = resolve(prop, root);
    if (!r.contains("properties") || r["properties"].empty()) continue;
    const std::string key = r.dump();
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == key; });
    if (it == groups.end()) groups.push_back({key, {name}});
    else it->second.push_back(name);
  }
  for (const auto& [key, names] : groups) {
    std::string heading;
    for (const auto& n : names) heading += (heading.empty() ? "" : ", ") + std::string("`") + prefix + n + "`";
    os << "#### " << heading << "\n\n";
    const json& r = resolve(s["properties"][names[0]], root);
    if (r.contains("description")) os << r["description"].get<std::string>() << "\n\n";
    table(os, r, root);
    nested_tables(os, r, root, prefix + names[0] + ".", depth - 1);
  }
}

}  // namespace

std::vector<ParameterRow> parameter_rows(const json& object_schema, const json& root) {
  std::vector<ParameterRow> rows;
  const json& s = resolve(object_schema, root);
  if (!s.contains("properties")) return rows;
  std::vector<std::string> required;
  if (s.contains("required"))
    for (const auto& r : s["required"]) required.push_back(r.get<std::string>());
  for (auto& [name, prop] : s["properties"].items()) {
    if (name == "model" && prop.contains("const")) continue;
    ParameterRow row;
    row.name = name;
    row.type = type_of(prop, root);
    const json& r = resolve(prop, root);
    row.unit = prop.value("x-unit", r.value("x-unit", std::string()));
    if (prop.contains("default")) row.default_value = compact(prop["default"]);
    row.constraint = constraint_of(prop, root);
    row.description = prop.value("description", r.value("description", std::string()));
    row.required = std::find(required.begin(), required.end(), name) != required.end();
    rows.push_back(row);
  }
  return rows;
}

std::string scenario_reference_markdown(const PluginRegistry& registry) {
  const json root = composed_scenario_schema(registry);
  std::ostringstream os;
  os << "<!-- GENERATED by `domel docs` from platform/scenario/scenario.schema.json and the plugins' schemas. "
        "Do not edit; regenerate. -->\n";
  os << "# Scenario reference\n\n" << root.value("description", "") << "\n\n";
  os << "Units are SI. A scenario is one JSON object; unknown keys are errors. "
        "Validate a file with `domel validate FILE`; `domel schema` prints the complete JSON Schema for editors.\n\n";
  os << "## Top level\n\n";
  table(os, root, root);
  const char* blocks[][2] = {{"material", "Material (`materials.<name>`)"},
                             {"interaction", "Interaction (`interactions[]`)"},
                             {"wall", "Wall (`walls[]`)"},
                             {"wall_motion", "Wall motion (`walls[].motion`)"},
                             {"wall_vibration", "Wall vibration (`walls[].motion.vibration`)"},
                             {"wall_servo", "Servo wall (`walls[].motion.servo`)"},
                             {"gravity_table", "Gravity over time: a table (`gravity`)"},
                             {"gravity_rotation", "Gravity over time: a rotation (`gravity`)"},
                             {"region", "Region (`insert[].region`)"},
                             {"subdomain", "Subdomain (`subdomains[]`)"},
                             {"periodic", "Periodic boundaries (`subdomains[].periodic`)"},
                             {"contact", "Contact model (`subdomains[].contact`)"},
                             {"insertion_model", "Inserter, platform keys (`subdomains[].insert[]`)"},
                             {"pour", "Pour (`subdomains[].pour[]`)"},
                             {"deletion_region", "Deletion region (`deletion_regions[]`)"},
                             {"coupling", "Coupling between levels (`couplings[]`)"},
                             {"fluid_model", "Fluid coupling, platform keys (`fluid`)"},
                             {"run", "Run (`run`)"},
                             {"output", "Output (`output`)"},
                             {"mass_flow_plane", "Mass-flow plane (`output.mass_flow[]`)"},
                             {"region_mass", "Mass in a region (`output.region_mass[]`)"},
                             {"wall_load", "Load on a wall (`output.wall_loads[]`)"},
                             {"cell_grid", "Cell grid (`output.grids[]`)"}};
  for (const auto& b : blocks) {
    const json& s = root["$defs"][b[0]];
    os << "## " << b[1] << "\n\n";
    if (s.contains("description")) os << s["description"].get<std::string>() << "\n\n";
    if (std::string(b[0]) == "insertion_model" || std::string(b[0]) == "fluid_model") {
      table(os, platform_scenario_schema()["$defs"][b[0]], root);
      continue;
    }
    if (std::string(b[0]) == "region") {
      table(os, s, root);
      os << "### `box`\n\n";
      table(os, s["properties"]["box"], root);
      os << "### `cylinder`\n\n";
      table(os, s["properties"]["cylinder"], root);
      continue;
    }
    table(os, s, root);
    // Nested objects whose keys get a table of their own: (block, path prefix, members).
    const struct {
      const char* block;
      const char* prefix;
      std::vector<const char*> members;
    } nested[] = {{"coupling", "couplings[].", {"region", "stress_control", "velocity_control"}},
                  {"output", "output.", {"repose_angle", "contacts"}},
                  {"wall_load", "output.wall_loads[].", {"axis"}},
                  {"gravity_rotation", "gravity.", {"rotation"}}};
    for (const auto& n : nested) {
      if (std::string(b[0]) != n.block) continue;
      for (const char* sub : n.members) {
        os << "### `" << n.prefix << sub << "`\n\n";
        const json& ss = s["properties"][sub];
        if (ss.contains("description")) os << ss["description"].get<std::string>() << "\n\n";
        table(os, ss, root);
      }
    }
  }
  const std::pair<uint32_t, const char*> kinds[] = {
      {DOMEL_KIND_NORMAL, "Normal-force models (`contact.normal`)"},
      {DOMEL_KIND_DAMPING, "Normal-damping models (`contact.damping`)"},
      {DOMEL_KIND_TANGENTIAL, "Tangential models (`contact.tangential`)"},
      {DOMEL_KIND_ROLLING, "Rolling-resistance models (`contact.rolling`)"},
      {DOMEL_KIND_TWISTING, "Twisting-resistance models (`contact.twisting`)"},
      {DOMEL_KIND_INSERTION, "Insertion models (`insert[]`)"},
      {DOMEL_KIND_CONTROLLER, "Controller models (`couplings[].stress_control`, `couplings[].velocity_control`)"},
      {DOMEL_KIND_FLUID_COUPLER, "Fluid couplers (`fluid`)"}};
  for (const auto& [kind, title] : kinds) {
    os << "## " << title << "\n\n";
    bool any = false;
    for (const auto& m : registry.models()) {
      if (m.desc.kind != kind) continue;
      any = true;
      const auto& lib = registry.libraries()[m.library];
      os << "### `" << m.name << "`\n\n" << m.summary << "\n\n";
      os << "Version " << m.version << ", library `" << lib.name << "` " << lib.version;
      if (is_contact_kind(kind)) os << ", per-contact history: " << m.contact.history_slots << " value(s)";
      os << ".\n\n";
      if (m.schema.contains("description")) os << m.schema["description"].get<std::string>() << "\n\n";
      // a plugin's "$ref": "#/$defs/..." point into its own schema
      json model_root = root;
      if (m.schema.contains("$defs"))
        for (const auto& [k, v] : m.schema["$defs"].items())
          if (!model_root["$defs"].contains(k)) model_root["$defs"][k] = v;
      table(os, m.schema, model_root);
      nested_tables(os, m.schema, model_root, "", 3);
    }
    if (kind == DOMEL_KIND_ROLLING || kind == DOMEL_KIND_TWISTING)
      os << (any ? "" : "No model is installed yet. ") << "`{\"model\": \"none\"}` (the default) leaves the slot empty.\n\n";
    else if (!any)
      os << "No model is installed.\n\n";
  }
  return os.str();
}

}  // namespace domel::platform
