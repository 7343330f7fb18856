// SPDX-License-Identifier: MIT
// Internal to platform/scenario: the helpers that the validation passes
// (scenario.cpp) and the builders (builders.cpp) share, and the entry of the
// build. Not installed, not for other folders.
#pragma once

#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scheduler/simulation.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace domel::platform::scenario_detail {

using nlohmann::json;

inline constexpr uint32_t kSlotKinds[kSlotCount] = {DOMEL_KIND_NORMAL, DOMEL_KIND_DAMPING, DOMEL_KIND_TANGENTIAL,
                                                    DOMEL_KIND_ROLLING, DOMEL_KIND_TWISTING};

inline std::string idx(const std::string& base, std::size_t k) { return base + "/" + std::to_string(k); }

inline std::string escape_pointer_token(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '~') out += "~0";
    else if (ch == '/') out += "~1";
    else out += ch;
  }
  return out;
}

inline std::string fmt_num(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

/// A file named in the scenario (mesh, plugin, state file): a relative path
/// is relative to the scenario's folder.
inline std::filesystem::path scenario_path(const std::filesystem::path& scenario_file, const std::string& named) {
  std::filesystem::path p = named;
  return p.is_relative() ? scenario_file.parent_path() / p : p;
}

/// Diagnostics collected by a validation pass or a builder.
struct Checker {
  std::filesystem::path file;
  std::vector<Diagnostic> diags;
  void add(const std::string& pointer, const std::string& message, const std::string& hint = {}) {
    diags.push_back({file.string(), pointer, message, hint});
  }
};

inline const json* member(const json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

inline bool is_vec3(const json* j) {
  return j && j->is_array() && j->size() == 3 && (*j)[0].is_number() && (*j)[1].is_number() && (*j)[2].is_number();
}

/// "x", "y", "z" -> 0, 1, 2. The validation passes may meet a document the
/// schema refused: anything but "x" or "y" reads as z there.
inline int axis_index(const json* j) {
  if (!j || !j->is_string()) return 2;
  const std::string a = j->get<std::string>();
  return a == "x" ? 0 : a == "y" ? 1 : 2;
}

/// Platform keys of a model block that are not the plugin's parameters.
inline std::vector<std::string> platform_keys(uint32_t kind) {
  if (kind == DOMEL_KIND_INSERTION) return {"model", "region", "seed", "velocity", "fixed", "material"};
  if (kind == DOMEL_KIND_FLUID_COUPLER) return {"model", "subdomains", "interval", "write_interval"};
  if (kind == DOMEL_KIND_CONTROLLER) return {"model", "enabled"};
  return {"model"};
}

/// The mixture of an insertion block ("distribution": {"type": "mixture"}),
/// or null.
inline const json* insertion_mixture(const json& block) {
  const json* d = member(block, "distribution");
  if (!d || !d->is_object()) return nullptr;
  const json* t = member(*d, "type");
  return t && t->is_string() && t->get<std::string>() == "mixture" ? d : nullptr;
}

/// The material names an insertion block makes particles of, each with the
/// JSON pointer (below the block's) of where it is named: the block's
/// "material", and each mixture component's (a component without one takes
/// the block's, or the subdomain's). Names that are not strings are skipped.
inline std::vector<std::pair<std::string, std::string>> insertion_material_names(const json& block) {
  std::vector<std::pair<std::string, std::string>> out;
  if (const json* m = member(block, "material"); m && m->is_string()) out.emplace_back(m->get<std::string>(), "/material");
  if (const json* mix = insertion_mixture(block))
    if (const json* comps = member(*mix, "components"); comps && comps->is_array())
      for (std::size_t k = 0; k < comps->size(); ++k)
        if (const json* m = member((*comps)[k], "material"); m && m->is_string())
          out.emplace_back(m->get<std::string>(), "/distribution/components/" + std::to_string(k) + "/material");
  return out;
}

inline json plugin_params(const json& block, uint32_t kind) {
  json p = block;
  for (const auto& k : platform_keys(kind)) p.erase(k);
  return p;
}

/// A region block ({"box": ...} or {"cylinder": ...}) as the ABI's region (shapes.cpp).
domel_region_v1 make_region(const json& region);

/// The axis-aligned box [lo, hi] enclosing a region (a cylinder: its radius about the axis).
void region_box(const domel_region_v1& r, double lo[3], double hi[3]);

/// A wall block as its primitives, remove_at and motion applied (shapes.cpp).
/// Throws MeshError when a mesh file cannot be read.
std::vector<WallPrimitive> expand_wall(const json& w, std::size_t wall_index, std::size_t material,
                                       const std::filesystem::path& scenario_file);

/// Build a Simulation from a validated document whose schema defaults are
/// filled in (builders.cpp); throws ConfigError with every problem found.
std::unique_ptr<Simulation> build(const json& doc, const std::filesystem::path& file, PluginRegistry& registry);

}  // namespace domel::platform::scenario_detail
