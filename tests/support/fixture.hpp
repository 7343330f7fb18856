// SPDX-License-Identifier: MIT
// Test support: a registry with the built-in plugins (as the runtime loads
// them) and a small scenario builder, so physics tests exercise the full
// stack: scenario -> plugins -> contact pipeline -> integrator.
#pragma once

#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

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

/// A 10 x 10 x 20 lattice column of diameter d (spacing 1.02 d, jitter
/// 0.005) settling under gravity in a box 40 layers high, open at the top:
/// pairs and walls in contact (Hertz-Mindlin, e = 0.5, mu = 0.5, dt 1e-5 s).
inline nlohmann::json lattice_column(double d) {
  nlohmann::json doc = scenario(hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  const double a = 1.02 * d;
  doc["walls"] = {{{"name", "box"}, {"type", "box"}, {"material", "m"}, {"min", {0, 0, 0}},
                   {"max", {10 * a, 10 * a, 40 * a}}, {"open", {"zmax"}}}};
  nlohmann::json insert = {{"model", "lattice"}, {"diameter", d}, {"spacing", 1.02}, {"jitter", 0.005}};
  insert["region"] = {{"box", {{"min", {0, 0, 0}}, {"max", {10 * a, 10 * a, 20 * a}}}}};
  doc["subdomains"][0]["insert"] = nlohmann::json::array({insert});
  return doc;
}

/// A lattice of 2.8 mm parcels (material diameter 1.4 mm, alpha 2) 20 mm
/// deep in a box 10 lattice spacings wide, open at the top; a coupling
/// "zone" makes its lower 10 mm the region of an empty fine level (alpha 1),
/// so the parcels there are refined at the start (docs/adaptive.md).
/// Hertz-Mindlin, e = 0.5, mu = 0.5, gravity, steps 3.6e-5 and 1.8e-5 s.
inline nlohmann::json refined_region(double duration) {
  const double d = 0.0014, a = 1.02 * 2 * d, w = 10 * a;
  nlohmann::json doc = scenario(hertz_mindlin(), 1.8e-5, 0.5, 0.5);
  doc["gravity"] = {0, 0, -9.81};
  nlohmann::json coarse = {{"name", "coarse"}, {"material", "m"}, {"coarse_grain", 2}, {"contact", hertz_mindlin()},
                           {"time_step", 3.6e-5}};
  coarse["insert"] = {{{"model", "lattice"}, {"diameter", d}, {"spacing", 1.02},
                       {"region", {{"box", {{"min", {0, 0, 0}}, {"max", {w, w, 0.02}}}}}}}};
  nlohmann::json fine = {{"name", "fine"}, {"material", "m"}, {"coarse_grain", 1}, {"contact", hertz_mindlin()},
                         {"time_step", 1.8e-5}};
  doc["subdomains"] = {coarse, fine};
  doc["walls"] = {{{"name", "box"}, {"type", "box"}, {"material", "m"}, {"min", {0, 0, 0}}, {"max", {w, w, 0.06}},
                   {"open", {"zmax"}}}};
  doc["couplings"] = {{{"name", "zone"},
                       {"coarse", "coarse"},
                       {"fine", "fine"},
                       {"region", {{"min", {0, 0, 0}}, {"max", {w, w, 0.01}}, {"cells", {2, 2, 1}}}},
                       {"inflow_faces", {"+z"}}}};
  doc["run"]["duration"] = duration;
  return doc;
}

inline std::unique_ptr<platform::Simulation> build(const nlohmann::json& doc) {
  return platform::load_scenario(doc, "test.json", builtin_registry());
}

/// The problems load_scenario finds in `doc` (read as if from `file`, which
/// relative paths are resolved against), one "pointer: message" line each;
/// empty when it is accepted.
inline std::string problems(const nlohmann::json& doc, const std::filesystem::path& file = "test.json") {
  try {
    platform::load_scenario(doc, file, builtin_registry());
  } catch (const platform::ConfigError& e) {
    std::string all;
    for (const platform::Diagnostic& d : e.diagnostics()) all += d.pointer + ": " + d.message + "\n";
    return all;
  }
  return {};
}

/// Add a wall to a scenario document (material "m").
inline void add_plane(nlohmann::json& doc, const std::string& name, const std::array<double, 3>& point,
                      const std::array<double, 3>& normal) {
  doc["walls"].push_back({{"name", name}, {"type", "plane"}, {"material", "m"}, {"point", point}, {"normal", normal}});
}

/// One sphere (id 1, centre x, radius r, density rho) in the scenario's
/// first subdomain, with a time step of 1/50 of its contact time at 0.1 m/s
/// (at most 2e-5 s) and a skin of 0.4 r; set up and ready to step.
inline platform::Subdomain& one_sphere(platform::Simulation& sim, const std::array<double, 3>& x, double r, double rho) {
  platform::Subdomain& sd = *sim.subdomains[0];
  sd.store().add(1, x[0], x[1], x[2], r, rho);
  const auto rep = sd.estimate_time_step(0.1);
  sd.set_time_step(std::min(rep.contact_time / 50.0, 2e-5));
  sd.set_skin(0.4 * r);
  sd.setup();
  return sd;
}

/// A CSV file of numbers with a header (probes.csv, a grid's profile):
/// column index by name, and the rows.
struct Csv {
  std::map<std::string, std::size_t> column;
  std::vector<std::vector<double>> rows;
  double at(std::size_t row, const std::string& name) const { return rows[row][column.at(name)]; }
};

inline Csv read_csv(const std::filesystem::path& file) {
  Csv out;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  {
    std::stringstream hs(line);
    std::string n;
    for (std::size_t k = 0; std::getline(hs, n, ','); ++k) out.column[n] = k;
  }
  while (std::getline(in, line)) {
    std::vector<double> f;
    std::stringstream ls(line);
    std::string x;
    while (std::getline(ls, x, ',')) f.push_back(std::stod(x));
    out.rows.push_back(std::move(f));
  }
  return out;
}

/// Run a scenario document (as if read from `file`, which paths in it are
/// relative to) on `threads` threads, without progress, into a fresh
/// temporary folder named after `name` and the process; returns the folder.
inline std::filesystem::path run_into_temp(const nlohmann::json& doc, const std::string& file, const std::string& name,
                                           int threads) {
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / ("domel_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(out);
  auto sim = platform::load_scenario(doc, file, builtin_registry());
  platform::RunOptions opt;
  opt.output_directory = out;
  opt.progress = false;
  opt.threads = threads;
  sim->run(opt, builtin_registry());
  return out;
}

}  // namespace domel::test
