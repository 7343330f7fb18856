// SPDX-License-Identifier: MIT
// Contact frames (contact_frames.hpp).
#include "outputs/contact_frames.hpp"

#include "core/archive.hpp"
#include "outputs/contact_sample.hpp"

#include <spdlog/spdlog.h>

namespace domel::platform {

void ContactFrames::setup(RunContext& ctx) {
  frames_ = Cadence::in_time(interval_, 0.0, ctx.macro);
  if (interval_ > 0 && ctx.writer) vtk_ = std::make_unique<io::ContactSeriesWriter>(ctx.out, "contacts");
}

void ContactFrames::output(RunContext& ctx, const MacroStep& step) {
  if (!frames_.take(step.index) || !vtk_) return;  // another rank writes
  const double t = step.t;
  const std::vector<io::ContactRow>* rows = sample_.rows_at(t, kTimeTolerance * ctx.macro);
  if (!rows) spdlog::warn("contacts: no contacts were recorded for t = {:.6g} s; its file is empty", t);
  vtk_->write(t, rows ? *rows : std::vector<io::ContactRow>{});
}

void ContactFrames::finish(RunContext&, nlohmann::json& summary) {
  summary["outputs"]["contacts"] = vtk_ ? "contacts.pvd" : "";
}

void ContactFrames::fields(CheckpointFields& f, std::uint64_t first) {
  std::uint64_t index = frames_.index();
  double period = frames_.period();
  std::vector<double> times = vtk_ ? vtk_->frame_times() : std::vector<double>{};
  f("index", index);
  f("period", period);
  f("times", times);
  if (!f.loading()) return;
  frames_.restore(index, period, first);
  if (vtk_) vtk_->resume(times);
}

void ContactFrames::save(ArchiveWriter& w, const std::string& p) {
  save_fields(w, p, [&](CheckpointFields& f) { fields(f, 0); });
}

void ContactFrames::load(RunContext& ctx, const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f, ctx.first); });
}

}  // namespace domel::platform
