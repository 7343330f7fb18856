// SPDX-License-Identifier: MIT
// Servo walls (walls[].motion[].servo): after every macro step each servo
// measures the force F that the particles of all subdomains put on its wall
// against its direction u, and sets the wall's velocity along u for the
// next macro step to
//
//   v = clamp(gain (F_target - F), -max_velocity, +max_velocity),
//
// a proportional controller on the velocity, so on the displacement an
// integral one: the wall comes to rest where F = F_target (the control law
// of LIGGGHTS' servo walls, fix mesh/surface/stress/servo, reduced to its
// proportional term). The travel itself is geometry/wall_motion.hpp's
// ServoState, shared with the wall's primitives.
#pragma once

#include "geometry/wall_motion.hpp"
#include "loop/component.hpp"

#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

class Subdomain;
class RunRanks;
class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

struct WallServo {
  std::string name;        ///< the wall's name (probes.csv columns)
  std::size_t wall = 0;    ///< index of the scenario wall
  double direction[3] = {0, 0, -1};  ///< unit: the wall presses on the particles along it
  double force = 0;        ///< [N] target
  double gain = 0;         ///< [m/(s N)]
  double start = 0, end = std::numeric_limits<double>::infinity();
  std::shared_ptr<ServoState> state;
  double measured = std::numeric_limits<double>::quiet_NaN();  ///< [N] F at the last update
};

/// A run component: update() after every macro step, the servos' columns in
/// probes.csv. Their travel is part of the world a checkpoint holds (save
/// and load, called by scheduler/checkpoint.cpp before the subdomains,
/// which place their walls with it), not a component section.
class WallServos final : public Component, public ProbeSource {
 public:
  std::vector<WallServo> servos;

  unsigned points() const override { return servos.empty() ? 0u : kAfterMacro; }
  void after_macro(RunContext& ctx, const MacroStep& step) override { update(step.t, ctx.subdomains, ctx.ranks); }
  void probe_columns(std::vector<std::string>& names) const override {
    for (const auto& c : columns()) names.push_back(c);
  }
  void probe_values(RunContext&, double t, std::vector<double>& row) override { append_values(t, row); }

  bool empty() const { return servos.empty(); }
  /// After a macro step ending at t: measure and set the velocities. Spread
  /// over ranks, the loads are summed over them (every rank moves the wall alike).
  void update(double t, const std::vector<std::unique_ptr<Subdomain>>& subdomains, RunRanks& ranks);
  /// probes.csv: <name>.servo_force [N] (F at the last update) and <name>.servo_travel [m] (along the direction).
  std::vector<std::string> columns() const;
  void append_values(double t, std::vector<double>& row) const;

  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load (core/archive.hpp).
  void fields(CheckpointFields& f);
};

}  // namespace domel::platform
