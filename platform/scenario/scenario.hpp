// SPDX-License-Identifier: MIT
// Scenario loading: JSON text -> validated -> built Simulation.
// Validation runs in passes and collects every problem before anything is
// built or written: (1) JSON syntax, (2) plugin libraries named by the
// scenario, (3) the platform schema, (4) each plugin block against the
// schema of the model it names (unknown names get "did you mean" or the list
// of valid names), (5) cross-references (materials, interactions, wall
// shapes). After pass (3) the schema's defaults are written into the
// document, and each model block gets its model's defaults in pass (4), so
// that the later passes and the builders (builders.cpp, one per block) read
// every defaulted value from the document. Building then creates model
// instances, inserts particles and checks each time step against the
// stability limit.
#pragma once

#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scheduler/simulation.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <vector>

namespace domel::platform {

/// The platform's scenario schema (embedded from scenario.schema.json).
const nlohmann::json& platform_scenario_schema();

/// The complete schema: the platform schema with every registered model's
/// parameter schema filled into its slot, for editors (`domel schema`).
nlohmann::json composed_scenario_schema(const PluginRegistry& registry);

/// Schema of one model's block as it appears in a scenario: the plugin's
/// parameter schema plus the platform-owned keys of that block.
nlohmann::json model_block_schema(const RegisteredModel& model);

/// A ceiling on run.max_particles for every scenario this process builds
/// (0, the default: none). The fuzz harness (tests/fuzz/scenario_fuzz.cpp)
/// sets one so that an input asking for millions of particles is refused
/// within its time and memory budget, as a larger one is in a normal run.
void set_particle_ceiling(std::size_t n);
std::size_t particle_ceiling();

/// Load plugins the scenario names, and validate. Returns all problems (empty if valid).
std::vector<Diagnostic> validate_scenario_file(const std::filesystem::path& file, PluginRegistry& registry);

/// Validate and build; throws ConfigError with every problem found.
std::unique_ptr<Simulation> load_scenario(const std::filesystem::path& file, PluginRegistry& registry);

/// Same, from an in-memory document (`file` is used for messages and relative paths).
std::unique_ptr<Simulation> load_scenario(const nlohmann::json& doc, const std::filesystem::path& file,
                                          PluginRegistry& registry);

}  // namespace domel::platform
