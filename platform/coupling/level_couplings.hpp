// SPDX-License-Identifier: MIT
// The couplings between levels of a run (coupling.hpp) as one run
// component on one control clock: every control interval (a whole number
// of macro steps, resolved by the builder), at a macro-step start where all
// levels stand at the same time, the external forces of every coupled level
// are zeroed and each coupling exchanges in turn, adding its controllers'
// forces. Each coupling's two grids sample with the run's samplers; its grid
// files follow the output grids' (the accessible volumes are refreshed
// before them, outputs/grid_files.hpp).
#pragma once

#include "coupling/coupling.hpp"
#include "loop/component.hpp"

#include <memory>
#include <vector>

namespace domel::platform {

class LevelCouplings final : public Component {
 public:
  /// `couplings` and `flow` outlive this component (the Simulation's).
  LevelCouplings(std::vector<std::unique_ptr<Coupling>>& couplings, std::uint64_t control_macro, ParticleFlow& flow)
      : couplings_(couplings), control_(Cadence::in_ticks(control_macro, control_macro)), flow_(flow) {}

  unsigned points() const override { return couplings_.empty() ? 0u : kBeforeMacro | kOutput; }
  std::string section() const override { return couplings_.empty() ? "" : "coupling"; }
  void init(RunContext& ctx) override;
  void setup(RunContext& ctx) override;
  void before_macro(RunContext& ctx, const MacroStep& step) override;
  void output(RunContext& ctx, const MacroStep& step) override;
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  /// Each coupling under "<prefix><k>/" (Coupling::save).
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) override;

 private:
  std::vector<std::unique_ptr<Coupling>>& couplings_;
  Cadence control_;
  ParticleFlow& flow_;
  std::vector<std::size_t> levels_;  ///< every coupled subdomain, once
};

}  // namespace domel::platform
