// SPDX-License-Identifier: MIT
// The couplings' run component (level_couplings.hpp).
#include "coupling/level_couplings.hpp"

#include <algorithm>

namespace domel::platform {

void LevelCouplings::init(RunContext& ctx) {
  for (auto& c : couplings_) c->set_ranks(ctx.ranks);
}

void LevelCouplings::setup(RunContext& ctx) {
  levels_.clear();
  for (auto& c : couplings_) {
    c->start(ctx.subdomains, ctx.walls, ctx.writer ? ctx.out : std::filesystem::path());
    ctx.samplers().push_back({&c->fine_grid(), c->spec().fine, &c->timing().averaging});
    ctx.samplers().push_back({&c->coarse_grid(), c->spec().coarse, &c->timing().averaging});
    for (std::size_t k : {c->spec().fine, c->spec().coarse})
      if (std::find(levels_.begin(), levels_.end(), k) == levels_.end()) levels_.push_back(k);
  }
  if (ctx.restart) return;  // what the start refined is in the checkpoint
  // Material in a fine region at the start is refined, coarser levels first:
  // a coupling whose coarse level is the fine level of one not yet done waits
  // for it, so that nested levels fill from the coarsest down.
  std::vector<Coupling*> todo;
  for (auto& c : couplings_) todo.push_back(c.get());
  while (!todo.empty()) {
    auto ready = std::find_if(todo.begin(), todo.end(), [&](const Coupling* c) {
      return std::none_of(todo.begin(), todo.end(),
                          [&](const Coupling* o) { return o != c && o->spec().fine == c->spec().coarse; });
    });
    if (ready == todo.end()) ready = todo.begin();  // a cycle (refused when the scenario is built): as listed
    (*ready)->refine_at_start(ctx.subdomains, flow_);
    todo.erase(ready);
  }
}

void LevelCouplings::before_macro(RunContext& ctx, const MacroStep& step) {
  if (!control_.on(step.index)) return;
  // the external forces are rebuilt from zero by every coupling's controllers
  for (std::size_t k : levels_) {
    ParticleStore& s = ctx.subdomains[k]->store();
    std::fill(s.ext_fx.begin(), s.ext_fx.end(), 0.0);
    std::fill(s.ext_fy.begin(), s.ext_fy.end(), 0.0);
    std::fill(s.ext_fz.begin(), s.ext_fz.end(), 0.0);
  }
  for (auto& c : couplings_) c->exchange(step.t, ctx.subdomains, ctx.walls, flow_);
}

void LevelCouplings::output(RunContext&, const MacroStep& step) {
  if (step.index == 0) return;
  for (auto& c : couplings_) c->write_grids(step.index, step.t, false);
}

void LevelCouplings::finish(RunContext& ctx, nlohmann::json& summary) {
  if (couplings_.empty()) return;
  for (auto& c : couplings_) c->write_grids(ctx.end_index, ctx.end_time, true);
  nlohmann::json cj = nlohmann::json::object();
  for (auto& c : couplings_) {
    const std::string& name = c->spec().name;
    cj[name] = c->summary(ctx.subdomains, ctx.particles(c->spec().fine, ctx.end_time), flow_);
    if (c->spec().grid_interval > 0)
      summary["outputs"]["couplings"][name] = {{"balance", name + "_balance.csv"},
                                               {"fine_grid", name + "_fine.pvd"},
                                               {"coarse_grid", name + "_coarse.pvd"}};
    else
      summary["outputs"]["couplings"][name] = {{"balance", name + "_balance.csv"}};
  }
  summary["couplings"] = cj;
}

void LevelCouplings::save(ArchiveWriter& w, const std::string& prefix) {
  for (std::size_t k = 0; k < couplings_.size(); ++k) couplings_[k]->save(w, prefix + std::to_string(k) + "/");
}

void LevelCouplings::load(RunContext&, const ArchiveReader& r, const std::string& prefix) {
  for (std::size_t k = 0; k < couplings_.size(); ++k) couplings_[k]->load(r, prefix + std::to_string(k) + "/");
}

}  // namespace domel::platform
