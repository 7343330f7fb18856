// SPDX-License-Identifier: MIT
// The fluid-coupler host (the scenario's `fluid` block): every coupling
// interval, at a macro-step boundary where all levels stand at the same
// time, the subdomains that share the fluid hand their particles to a
// fluid_coupler plugin (abi.h, domel_fluid_exchange_v1) and get back, per
// particle, a held force (pressure gradient and whatever the coupler does not
// linearise) and a linearised drag beta (u - v). Between exchanges each
// level's post_force hook adds  held + beta (u - v)  with the particle's
// velocity of that step (the half-step velocity of velocity Verlet, as
// LAMMPS' fix viscous reads it), so a drag whose relaxation time m/beta is
// far shorter than the coupling interval stays stable; the same hook
// integrates each particle's velocity over the interval for the next
// exchange's mean velocity. At an exchange the force each particle carries
// into the next step's first half kick is updated too (the old fluid force
// taken out, the new one put in), so the new fluid state acts from the
// exchange's instant. The coupler's grid fields are written as a
// ParaView series of VTK image data.
#pragma once

#include "loader/plugin_registry.hpp"
#include "loop/component.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

class Subdomain;
class RunRanks;

class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

namespace io {
class FieldImageSeries;
}

struct FluidSpec {
  std::string where = "/fluid";          ///< the block's JSON pointer, for messages
  std::shared_ptr<ModelInstance> model;  ///< the fluid_coupler plugin instance
  nlohmann::json used;                   ///< {model, version, library, library_version} for summary.json
  std::vector<std::size_t> levels;       ///< subdomain indices sharing the fluid
  std::uint64_t interval_macro = 1;      ///< exchange every this many macro steps
  double interval = 0;                   ///< = interval_macro x the macro step [s]
  double write_interval = 0;             ///< fields output interval [s]; 0: none
  /// The scenario's run in macro steps (run.duration; 0: not known): the
  /// exchange that would carry the fluid past it covers only what is left.
  std::uint64_t run_macro_steps = 0;
  double gravity[3] = {0, 0, 0};         ///< [m/s^2]
  /// The plugin was built for ABI 2.1, which knows one level per exchange
  /// and no linearised drag: it is called once per level.
  bool one_level_per_call = false;
};

/// A run component: the exchange before the macro steps it is due at, the
/// fields among the outputs, the summary at the end.
class FluidCoupling final : public Component {
 public:
  /// Gives each level's particles the coupling's per-particle arrays and
  /// registers the post_force hook that applies the fluid force.
  FluidCoupling(FluidSpec spec, std::vector<std::unique_ptr<Subdomain>>& subdomains);
  ~FluidCoupling();
  FluidCoupling(const FluidCoupling&) = delete;
  FluidCoupling& operator=(const FluidCoupling&) = delete;

  const FluidSpec& spec() const { return spec_; }

  // Component
  unsigned points() const override { return kBeforeMacro | kOutput; }
  std::string section() const override { return "fluid/"; }
  void init(RunContext& ctx) override { set_ranks(ctx.ranks); }
  void setup(RunContext& ctx) override;
  void before_macro(RunContext& ctx, const MacroStep& step) override;
  void output(RunContext& ctx, const MacroStep& step) override;
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  void load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) override { load(r, prefix, ctx.out); }

  /// One exchange at time t. Throws RuntimeError naming the block when the
  /// plugin fails, when its stable interval is shorter than the coupling
  /// interval, or when a particle's drag relaxation time m/beta is shorter
  /// than its level's time step.
  void exchange(double t, std::vector<std::unique_ptr<Subdomain>>& subdomains);
  /// A run spread over ranks: every rank gathers each level's particles
  /// (every rank's, in id order) and gives the coupler the same question, so
  /// the fluid is the same on every rank; each rank keeps its own particles'
  /// drag. Null: one process.
  void set_ranks(RunRanks& ranks) { ranks_ = &ranks; }

  /// Write the coupler's fields when due at macro step `tick`, time t (or,
  /// `final`, at the end whatever the interval) into
  /// <out>/fluid_<NNNNNN>.vti and fluid.pvd. Spread over ranks, every rank
  /// calls it (the coupler is asked alike everywhere) and rank 0 writes.
  void write_fields(std::uint64_t tick, double t, bool final, const std::filesystem::path& out);

  /// Checkpoints (docs/checkpoint.md): the coupler's state (ABI 2.3
  /// save_state), the exchange count, the last limits, the fields' schedule
  /// and frames. The per-particle arrays (drag, held force, velocity
  /// integrals) are the particle store's and saved with it.
  void save(ArchiveWriter& w, const std::string& prefix) override;
  /// On a restart, before the first exchange; `out` is the run's folder.
  void load(const ArchiveReader& r, const std::string& prefix, const std::filesystem::path& out);
  /// Both directions of save and load (core/archive.hpp); `out`: the run's folder (loading).
  void fields(CheckpointFields& f, const std::filesystem::path& out);

  /// summary.json's "fluid" block: model, levels, interval, exchanges, time
  /// spent in the plugin, the last limit and solver figures, the net fluid
  /// force on each level at the last exchange.
  nlohmann::json summary() const;

 private:
  RunRanks* ranks_ = &one_process();
  // aux array offsets within each level's block (ParticleStore::aux)
  // beta and u; the held force; the velocity integral and its time; the
  // fluid force last applied (replaced in f at an exchange)
  enum : std::size_t { kBeta, kUx, kUy, kUz, kFx, kFy, kFz, kSx, kSy, kSz, kSt, kLx, kLy, kLz, kArrays };
  FluidSpec spec_;
  std::vector<std::size_t> aux_;  ///< per level: the index of its first aux array
  std::vector<std::string> names_;  ///< per level: the subdomain's name
  std::uint64_t exchanges_ = 0;
  double seconds_ = 0;
  Cadence exchanges_due_;  ///< every interval_macro macro steps, from 0
  Cadence fields_;         ///< the fields' files, every write_interval from 0
  bool has_limits_ = false;
  domel_fluid_limits_v1 last_limits_{};
  std::string last_limit_;  ///< last_limits_.limit's text
  /// The coupler's momentum books (ABI 2.6, domel_fluid_limits_v1.has_books):
  /// the largest residual of the exchanges since the run (or its restart)
  /// began, and the no-slip walls' force on the fluid at the last exchange.
  bool has_books_ = false;
  double max_momentum_residual_ = 0;
  std::array<double, 3> wall_shear_{0, 0, 0};
  std::vector<std::array<double, 3>> net_force_;  ///< per level, at the last exchange [N]
  std::unique_ptr<io::FieldImageSeries> fields_out_;
};

}  // namespace domel::platform
