// SPDX-License-Identifier: MIT
// Test support: a registry with the built-in plugins (as the runtime loads
// them) and a small scenario builder, so physics tests exercise the full
// stack: scenario -> plugins -> contact pipeline -> integrator.
#pragma once

#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <string>

namespace domel::test {

inline platform::PluginRegistry& builtin_registry() {
  static platform::PluginRegistry registry;
  static bool loaded = false;
  if (!loaded) {
    registry.load_directory(DOMEL_BINARY_DIR "/plugins");
    loaded = true;
  }
  return registry;
}

/// One material "m" (S1 beads unless overridden), one interaction, no walls,
/// one empty subdomain "sd" with the given contact block and time step.
inline nlohmann::json scenario(const nlohmann::json& contact, double dt, double restitution, double friction,
                               double youngs = 5e6, double poisson = 0.3, double density = 2500) {
  return {
      {"name", "test"},
      {"gravity", {0, 0, 0}},
      {"materials", {{"m", {{"density", density}, {"youngs_modulus", youngs}, {"poisson_ratio", poisson}}}}},
      {"interactions", {{{"materials", {"m", "m"}}, {"restitution", restitution}, {"friction", friction}}}},
      {"walls", nlohmann::json::array()},
      {"subdomains", {{{"name", "sd"}, {"material", "m"}, {"contact", contact}, {"time_step", dt}}}},
      {"run", {{"duration", 1.0}}},
      {"output", {{"vtk_interval", 0}, {"probe_interval", 0}}}};
}

inline nlohmann::json hertz_mindlin() {
  return {{"normal", {{"model", "hertz"}}}, {"damping", {{"model", "restitution"}}}, {"tangential", {{"model", "mindlin"}}}};
}

inline nlohmann::json linear_spring(double stiffness) {
  return {{"normal", {{"model", "linear"}, {"stiffness", stiffness}}},
          {"damping", {{"model", "restitution"}}},
          {"tangential", {{"model", "linear"}}}};
}

inline std::unique_ptr<platform::Simulation> build(const nlohmann::json& doc) {
  return platform::load_scenario(doc, "test.json", builtin_registry());
}

/// Add a wall to a scenario document (material "m").
inline void add_plane(nlohmann::json& doc, const std::string& name, const std::array<double, 3>& point,
                      const std::array<double, 3>& normal) {
  doc["walls"].push_back({{"name", name}, {"type", "plane"}, {"material", "m"}, {"point", point}, {"normal", normal}});
}

}  // namespace domel::test
