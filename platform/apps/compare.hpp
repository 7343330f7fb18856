// SPDX-License-Identifier: MIT
// `domel compare`: run variants of one scenario (same seeds, same insertion,
// one or more JSON-pointer overrides each) and write a side-by-side report:
// report.md with a table of final values and PNG plots of the probe series;
// or (--runs) the same report of runs made before, by any scenarios.
#pragma once

#include "loader/plugin_registry.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace domel::platform {

struct CompareVariant {
  std::string label;
  std::vector<std::pair<std::string, std::string>> assignments;  ///< (JSON pointer, value text)
};

struct CompareOptions {
  std::filesystem::path scenario;
  std::filesystem::path output_directory;
  std::vector<CompareVariant> variants;
  int threads = 0;
  std::uint64_t max_steps = 0;
  bool progress = true;
};

/// Parses "POINTER=VALUE;POINTER=VALUE" (VALUE: JSON, or a bare string).
CompareVariant parse_variant(const std::string& text, const std::string& label);

/// The report (report.md and plots in `out`) of finished runs' output
/// folders, each with summary.json and probes.csv; labels: one per run, or
/// none (the folders' names). Throws ConfigError naming a folder that is not
/// a finished run's.
std::filesystem::path report_runs(const std::filesystem::path& out, const std::vector<std::filesystem::path>& runs,
                                  std::vector<std::string> labels);

/// Runs every variant and writes the report; returns the report's path.
/// Throws ConfigError (a variant's scenario is refused) or RuntimeError.
std::filesystem::path run_compare(const CompareOptions& options, PluginRegistry& registry);

}  // namespace domel::platform
