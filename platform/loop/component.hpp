// SPDX-License-Identifier: MIT
// The run loop's one extension point (docs/architecture.md, "The run loop").
// Everything that acts during a run besides the subdomains' own steps is a
// Component: the particle flow (pours, deletion regions, mass-flow planes),
// the couplings between levels, the fluid coupling, servo walls, the
// contact sample, and every output (probes, particle and wall frames,
// contact frames, cell grids, state files). A component says at which
// points of the loop it acts (points(), a mask, as LAMMPS's
// Fix::setmask()), and has one life cycle:
//
//   init(ctx)        before the subdomains' set-up (ask them to record their
//                    first force evaluation's contacts, say)
//   setup(ctx)       after it, fresh run or restart alike: open files, take
//                    the state at t = 0 (a fresh run) -- LAMMPS's setup()
//   load(ctx, r, p)  a restart, after setup(): its checkpoint sections
//   for every macro step m (all levels stand at t = m x macro at its start):
//     [checkpoint]   the loop's own, when due
//     before_macro   (kBeforeMacro) exchanges that need every level at t:
//                    pours and deletions, couplings, the fluid
//     output         (kOutput) files due at t; also at the final time
//     before_steps   (kBeforeSteps) what the coming steps must record
//     each subdomain steps its sub-steps; the cell grids registered with
//                    the context sample on their due steps, and
//                    records_contacts()/after_step() (kStep) see each step
//     after_macro    (kAfterMacro) every level at t + macro: servo walls
//   finish(ctx, summary)  after the last step: final files, summary.json
//   save(w, p)       into a checkpoint, at a macro-step start, on the
//                    process that writes it (rank 0): what every rank holds alike
//
// init, setup, load, finish and save reach every component; points() gates
// the others.
//
// Within a point, components act in the order they were registered
// (Simulation::components); the order is the run's contract: the builder
// registers the flow, probes, frames, contact frames, the output grids, the
// couplings, the fluid, the contact sample, servos and state files in that
// order (scenario/builders.cpp, register_components). Everything a component needs from the scenario it gets when it
// is built; everything of the run (the folder, the ranks, the macro step)
// from the RunContext.
#pragma once

#include "core/cadence.hpp"
#include "core/particle_store.hpp"
#include "loop/macro_step.hpp"
#include "loop/ranks.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

class Subdomain;
class CellGrid;
class RunRanks;
class ArchiveWriter;
class ArchiveReader;
struct WallPrimitive;
struct SubdomainStats;

/// A cell grid that samples one subdomain on its due steps; the loop asks
/// the subdomain to record its contacts for those steps.
struct GridSampler {
  CellGrid* grid = nullptr;
  std::size_t subdomain = 0;
  double* seconds = nullptr;  ///< where the sampling time goes (a coupling's clock); may be null
};

/// What a component sees of the run. Built by Simulation::run().
class RunContext {
 public:
  RunContext(std::vector<std::unique_ptr<Subdomain>>& subdomains, std::vector<WallPrimitive>& walls,
             std::filesystem::path out, RunRanks& ranks, double macro, std::uint64_t first, std::uint64_t stop,
             bool restart);
  ~RunContext();

  std::vector<std::unique_ptr<Subdomain>>& subdomains;
  std::vector<WallPrimitive>& walls;
  const std::filesystem::path out;  ///< the output folder
  RunRanks& ranks;                  ///< the processes the run is on (loop/ranks.hpp: one, or MPI ranks)
  const bool writer;                ///< this process writes the files (one process, or rank 0)
  const double macro;               ///< [s]
  const std::uint64_t first;        ///< the macro index the run starts at (a restart's checkpoint's)
  const std::uint64_t stop;         ///< the macro index the run ends at
  const bool restart;               ///< the run goes on from a checkpoint
  /// Where the run stopped (its end, or an interrupt), set before finish():
  /// the macro index and its time [s]
  std::uint64_t end_index = 0;
  double end_time = 0;

  /// Every particle of subdomain k at time t: its store on one process; on
  /// ranks, every rank's gathered to rank 0 in id order (empty elsewhere),
  /// once per time whoever asks. Collective on ranks.
  const ParticleStore& particles(std::size_t k, double t);
  /// Subdomain k's statistics at time t, over all ranks. Collective on ranks.
  SubdomainStats stats(std::size_t k, double t);
  /// The cell grids that sample during the steps, in registration order.
  std::vector<GridSampler>& samplers() { return samplers_; }

 private:
  std::vector<GatheredParticles> gathered_;
  std::vector<double> gathered_at_;
  std::vector<GridSampler> samplers_;
};

class Component {
 public:
  /// The points of the loop a component acts at (points()).
  enum Point : unsigned {
    kBeforeMacro = 1u << 0,
    kOutput = 1u << 1,
    kBeforeSteps = 1u << 2,
    kStep = 1u << 3,
    kAfterMacro = 1u << 4,
  };

  virtual ~Component() = default;
  /// The points it acts at: a mask of Point.
  virtual unsigned points() const = 0;
  /// The prefix of its checkpoint sections ("probes/"); empty: it keeps no state.
  virtual std::string section() const { return {}; }

  virtual void init(RunContext&) {}
  virtual void setup(RunContext&) {}
  virtual void before_macro(RunContext&, const MacroStep&) {}
  virtual void output(RunContext&, const MacroStep&) {}
  virtual void before_steps(RunContext&, const MacroStep&) {}
  /// kStep: whether subdomain k's coming step (its `last` of the macro step
  /// or not) must record its contacts for this component.
  virtual bool records_contacts(std::size_t /*k*/, bool /*last*/) const { return false; }
  /// kStep: after each step of subdomain k.
  virtual void after_step(RunContext&, std::size_t /*k*/, bool /*last*/) {}
  virtual void after_macro(RunContext&, const MacroStep&) {}
  virtual void finish(RunContext&, nlohmann::json& /*summary*/) {}
  virtual void save(ArchiveWriter&, const std::string& /*prefix*/) {}
  virtual void load(RunContext&, const ArchiveReader&, const std::string& /*prefix*/) {}
};

/// A component made of functions (tests, programs that embed the platform):
/// before and after every macro step that is stepped.
class HookComponent final : public Component {
 public:
  using Hook = std::function<void(const MacroStep&)>;
  HookComponent(Hook before, Hook after) : before_(std::move(before)), after_(std::move(after)) {}
  unsigned points() const override { return (before_ ? kBeforeMacro : 0u) | (after_ ? kAfterMacro : 0u); }
  void before_macro(RunContext&, const MacroStep& s) override { before_(s); }
  void after_macro(RunContext&, const MacroStep& s) override { after_(s); }

 private:
  Hook before_, after_;
};

/// A component that adds columns to probes.csv (output.probe_interval) and
/// its values to every row, in the order the probes were given them.
class ProbeSource {
 public:
  virtual ~ProbeSource() = default;
  virtual void probe_columns(std::vector<std::string>& names) const = 0;
  /// Its values at time t appended to a row. Collective on ranks: every
  /// rank calls it for every row.
  virtual void probe_values(RunContext& ctx, double t, std::vector<double>& row) = 0;
};

}  // namespace domel::platform
