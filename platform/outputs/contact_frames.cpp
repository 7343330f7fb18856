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

void ContactFrames::save(ArchiveWriter& w, const std::string& p) {
  w.put_scalar<std::uint64_t>(p + "index", frames_.index());
  w.put_scalar(p + "period", frames_.period());
  w.put(p + "times", vtk_ ? vtk_->frame_times() : std::vector<double>{});
}

void ContactFrames::load(RunContext& ctx, const ArchiveReader& r, const std::string& p) {
  frames_.restore(r.scalar<std::uint64_t>(p + "index"), r.scalar<double>(p + "period"), ctx.first);
  if (vtk_) vtk_->resume(r.get<double>(p + "times"));
}

}  // namespace domel::platform
