// SPDX-License-Identifier: MIT
// Particle and wall frames (particle_frames.hpp).
#include "outputs/particle_frames.hpp"

#include "core/archive.hpp"
#include "outputs/probes.hpp"
#include "subdomain/subdomain.hpp"

namespace domel::platform {

void ParticleFrames::setup(RunContext& ctx) {
  frames_ = Cadence::in_time(interval_, 0.0, ctx.macro);
  if (interval_ <= 0 || !ctx.writer) return;
  vtk_ = std::make_unique<io::VtkSeriesWriter>(ctx.out, "particles");
  vtk_->set_material_names(materials_);
  if (wall_surfaces_ && !ctx.walls.empty()) walls_ = std::make_unique<io::WallSurfaceSeries>(ctx.out, "walls");
}

void ParticleFrames::output(RunContext& ctx, const MacroStep& step) {
  if (!frames_.take(step.index)) return;
  const double t = step.t;
  std::vector<io::ParticleSet> sets;  // gathered on every rank: collective
  for (std::size_t k = 0; k < ctx.subdomains.size(); ++k)
    sets.push_back({&ctx.particles(k, t), static_cast<int>(k), &ctx.subdomains[k]->materials()});
  if (!vtk_) return;
  vtk_->write(t, sets);
  if (walls_) walls_->write(t, ctx.walls, lo_.data(), hi_.data());
  if (probes_) probes_->flush();  // probes.csv reaches the frame just written
}

void ParticleFrames::finish(RunContext&, nlohmann::json& summary) {
  summary["outputs"]["particles"] = interval_ > 0 ? "particles.pvd" : "";
  summary["outputs"]["walls"] = walls_ ? "walls.pvd" : "";
}

void ParticleFrames::fields(CheckpointFields& f, std::uint64_t first) {
  std::uint64_t index = frames_.index();
  double period = frames_.period();
  std::vector<double> times = vtk_ ? vtk_->frame_times() : std::vector<double>{};
  std::vector<double> wall_times = walls_ ? walls_->frame_times() : std::vector<double>{};
  f("index", index);
  f("period", period);
  f("times", times);
  f("wall_times", wall_times);
  if (!f.loading()) return;
  frames_.restore(index, period, first);
  if (vtk_) vtk_->resume(times);
  if (walls_) walls_->resume(wall_times);
}

void ParticleFrames::save(ArchiveWriter& w, const std::string& p) {
  save_fields(w, p, [&](CheckpointFields& f) { fields(f, 0); });
}

void ParticleFrames::load(RunContext& ctx, const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f, ctx.first); });
}

}  // namespace domel::platform
