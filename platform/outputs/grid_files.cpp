// SPDX-License-Identifier: MIT
// output.grids and the accessible volumes of every grid (grid_files.hpp).
#include "outputs/grid_files.hpp"

#include "core/archive.hpp"
#include "geometry/wall.hpp"
#include "subdomain/subdomain.hpp"

namespace domel::platform {

void GridFiles::setup(RunContext& ctx) {
  grids_.clear();
  for (const auto& g : setups_) {
    grids_.push_back(std::make_unique<CellGrid>(g.spec));
    grids_.back()->set_accessible(ctx.walls, 0.0);
    grids_.back()->set_periodic(ctx.subdomains[g.subdomain]->periodic());
    const bool files = ctx.writer && g.spec.write_interval > 0;  // every rank samples, rank 0 writes
    vtk_.push_back(files ? std::make_unique<io::CellGridVtkSeries>(ctx.out, g.spec.name) : nullptr);
    csv_.push_back(files ? std::make_unique<io::CellGridProfileCsv>(ctx.out, g.spec.name, g.profile_axis) : nullptr);
    files_.push_back(Cadence::in_time(g.spec.write_interval, g.spec.write_interval, ctx.macro));
    ctx.samplers().push_back({grids_.back().get(), g.subdomain, nullptr});
  }
  wall_active_.clear();
  for (const auto& w : ctx.walls) wall_active_.push_back(w.active(0.0) ? 1 : 0);
}

void GridFiles::output(RunContext& ctx, const MacroStep& step) {
  if (step.index == 0) return;
  for (std::size_t g = 0; g < grids_.size(); ++g) {
    if (!vtk_[g] || !files_[g].due(step.index)) continue;
    if (grids_[g]->samples_pending() > 0) {
      const CellFields f = grids_[g]->mean_since_last_take();
      vtk_[g]->write(step.t, *grids_[g], f);
      csv_[g]->write(step.t, *grids_[g], f);
    }
    files_[g].advance(step.index);
  }
  refresh_accessible(ctx, step.t);
}

void GridFiles::refresh_accessible(RunContext& ctx, double t) {
  // walls that appear or disappear (an outlet plug) change the accessible
  // volume: recompute it when the set of active walls changes
  bool changed = false;
  for (std::size_t w = 0; w < ctx.walls.size(); ++w) {
    const char now = ctx.walls[w].active(t) ? 1 : 0;
    changed = changed || now != wall_active_[w];
    wall_active_[w] = now;
  }
  if (!changed) return;
  for (auto& s : ctx.samplers()) s.grid->set_accessible(ctx.walls, t);
}

void GridFiles::finish(RunContext& ctx, nlohmann::json& summary) {
  for (std::size_t g = 0; g < grids_.size(); ++g) {
    if (!vtk_[g]) continue;
    if (grids_[g]->samples_pending() > 0) {
      const CellFields f = grids_[g]->mean_since_last_take();
      vtk_[g]->write(ctx.end_time, *grids_[g], f);
      csv_[g]->write(ctx.end_time, *grids_[g], f);
    }
    summary["outputs"]["grids"][setups_[g].spec.name] = {{"series", setups_[g].spec.name + ".pvd"},
                                                         {"profile", setups_[g].spec.name + "_profile.csv"}};
  }
}

void GridFiles::save(ArchiveWriter& w, const std::string& prefix) {
  for (std::size_t g = 0; g < grids_.size(); ++g) {
    const std::string p = prefix + std::to_string(g) + "/";
    grids_[g]->save(w, p);
    save_fields(w, p + "files/", [&](CheckpointFields& f) { file_fields(f, g, 0); });
  }
}

void GridFiles::file_fields(CheckpointFields& f, std::size_t g, std::uint64_t first) {
  std::uint64_t index = files_[g].index(), csv_bytes = csv_[g] ? csv_[g]->size() : 0u;
  double period = files_[g].period();
  std::vector<double> times = vtk_[g] ? vtk_[g]->frame_times() : std::vector<double>{};
  f("index", index);
  f("period", period);
  f("csv_bytes", csv_bytes);
  f("vtk_times", times);
  if (!f.loading()) return;
  files_[g].restore(index, period, first);
  if (vtk_[g]) {
    vtk_[g]->resume(times);
    if (csv_bytes > 0) csv_[g]->resume(csv_bytes);
  }
}

void GridFiles::load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) {
  for (std::size_t g = 0; g < grids_.size(); ++g) {
    const std::string p = prefix + std::to_string(g) + "/";
    grids_[g]->load(r, p);
    load_fields(r, p + "files/", [&](CheckpointFields& f) { file_fields(f, g, ctx.first); });
  }
  // the walls' activity as the run last looked at it
  const double t_before = ctx.first > 0 ? static_cast<double>(ctx.first - 1) * ctx.macro : 0.0;
  for (std::size_t w = 0; w < ctx.walls.size(); ++w) wall_active_[w] = ctx.walls[w].active(t_before) ? 1 : 0;
}

}  // namespace domel::platform
