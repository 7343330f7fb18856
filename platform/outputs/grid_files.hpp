// SPDX-License-Identifier: MIT
// output.grids: Eulerian cell grids (averaging/cell_grid.hpp), each
// sampling one subdomain every `every` of its steps, their means written
// every write interval as <name>_<n>.vti / <name>.pvd and a layer profile
// <name>_profile.csv. The same component keeps every grid of the run (the
// couplings' too) on the volume the walls leave accessible: when a wall
// appears or disappears (an outlet plug), the accessible volumes are
// computed anew, after the output grids' files of that time and before the
// couplings' (the builder registers it just before the couplings).
#pragma once

#include "averaging/cell_grid.hpp"
#include "core/archive.hpp"
#include "io/cell_grid_output.hpp"
#include "loop/component.hpp"

#include <memory>
#include <vector>

namespace domel::platform {

/// One output grid as the scenario gives it.
struct GridSetup {
  CellGridSpec spec;
  std::size_t subdomain = 0;
  int profile_axis = 2;
};

class GridFiles final : public Component {
 public:
  explicit GridFiles(std::vector<GridSetup> setups) : setups_(std::move(setups)) {}

  unsigned points() const override { return kOutput; }
  std::string section() const override { return "grids/"; }
  /// The grids built (accessible volume from the walls present at t = 0),
  /// their files opened, each registered with the context as a sampler.
  void setup(RunContext& ctx) override;
  /// Files due at t; then the accessible volumes of every sampler's grid
  /// when the set of active walls changed.
  void output(RunContext& ctx, const MacroStep& step) override;
  /// The last means, whatever the interval; summary.json names the files.
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  /// Each grid's sums, its files' schedule and lengths.
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) override;

  const std::vector<GridSetup>& setups() const { return setups_; }
  /// The grids, built by setup(), in the order of setups(); readable after the run.
  const std::vector<std::unique_ptr<CellGrid>>& grids() const { return grids_; }

 private:
  void refresh_accessible(RunContext& ctx, double t);
  /// Grid g's files in a checkpoint, both directions (core/archive.hpp).
  void file_fields(CheckpointFields& f, std::size_t g, std::uint64_t first);

  std::vector<GridSetup> setups_;
  std::vector<std::unique_ptr<CellGrid>> grids_;
  std::vector<std::unique_ptr<io::CellGridVtkSeries>> vtk_;
  std::vector<std::unique_ptr<io::CellGridProfileCsv>> csv_;
  std::vector<Cadence> files_;
  std::vector<char> wall_active_;  ///< per wall, active at the last look
};

}  // namespace domel::platform
