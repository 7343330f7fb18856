// SPDX-License-Identifier: MIT
// What the two libFuzzer harnesses share (scenario_fuzz.cpp, run_fuzz.cpp):
// the built-in plugins, loaded once, and the folder each input is written to.
#pragma once

#include "loader/plugin_registry.hpp"

#include <cstdlib>
#include <filesystem>

namespace domel::fuzz {

inline platform::PluginRegistry& registry() {
  static platform::PluginRegistry r;
  static bool loaded = false;
  if (!loaded) {
    r.load_directory(DOMEL_FUZZ_PLUGIN_DIR);
    loaded = true;
  }
  return r;
}

/// The folder each input is written to: relative paths in a scenario
/// (meshes, state files) resolve against the copies bench/fuzz_scenarios.py
/// put there ($DOMEL_FUZZ_WORKDIR, else a temporary folder).
inline const std::filesystem::path& work_dir() {
  static const std::filesystem::path d = [] {
    const char* env = std::getenv("DOMEL_FUZZ_WORKDIR");
    std::filesystem::path p = env ? env : std::filesystem::temp_directory_path() / "domel_fuzz";
    std::filesystem::create_directories(p);
    return p;
  }();
  return d;
}

}  // namespace domel::fuzz
