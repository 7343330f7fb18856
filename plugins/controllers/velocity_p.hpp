// SPDX-License-Identifier: MIT
// Controller "velocity_p": the velocity controller of the coarse level where
// it overlaps the fine region, coarse <- fine, after LIGGGHTS-PFM's fix
// forcecontrol/region with ctrlPV velocity (docs/physics.md §5.4, with the
// cell averages of §5.2). It drives the coarse particles of each listed cell
// towards the fine level's mean velocity in the congruent cell, corrected
// for the mismatch of the two volume fractions (so the coarse mass flow
// follows the fine one).
//
// Levels: levels[0] is the FINE level (it sets the target), levels[1] the
// COARSE level (it is pushed: "actual"); both grids have the same geometry,
// and cell c of one is cell c of the other (anything else is refused).
// step.interval is the control interval T: the forces written are held by
// the host for the next T.
//
// Per call, for each listed cell c (physics.md §5.4):
//   empty cell (count 0 on either level, or no coarse particle of c in the
//   view): reset the integral, no force
//   PV = u_bar_coarse,  c_mf = clamp(phi_fine/phi_coarse, bounds) or 1,  SP = c_mf u_bar_fine
//   e = SP - PV;  I += e T;  u = kp e + ki I   (a velocity increment per coarse step)
//   F_i = m_i u / dt (dt the coarse step, from the setup) on each coarse particle of c, scaled per particle
//   and component by the velocity limiter (common.hpp) against the fine
//   cell's velocity range
// With kp = 1/N and T = N dt, the force held over T changes each
// particle's velocity by exactly e: the loop closes in one interval.
// The clamp of c_mf (default [0.5, 2]) is domel's: the reference corrects
// without bounds, so a nearly empty coarse cell could command any velocity.
#pragma once

#include "common.hpp"

#include <domel/sdk/plugin.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

namespace domel::plugins::controller {

/// The state velocity_p keeps per listed cell (the integral per component
/// x, y, z), and what its last call computed, for tests and diagnostics.
struct VelocityPCellState {
  std::array<double, 3> integral{};  ///< I [m]: the integral of the velocity error
  bool controlled = false;           ///< the last call ran the law (both cells occupied)
  double correction = 0.0;           ///< c_mf of the last call [-]
  std::array<double, 3> setpoint{};  ///< SP [m/s]
  std::array<double, 3> process{};   ///< PV [m/s]
  std::array<double, 3> error{};     ///< e [m/s]
  std::array<double, 3> command{};   ///< u [m/s], the velocity increment per coarse step
};

class VelocityP {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_CONTROLLER;
  static constexpr const char* kName = "velocity_p";
  static constexpr const char* kVersion = "2.0.0";
  static constexpr const char* kSummary =
      "P(I) velocity controller of the coarse level over the fine region: drives levels[1] (COARSE) particles "
      "towards levels[0] (FINE) mean velocity in the congruent cell (grids of both levels must match)";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Coarse-overlap velocity controller after LIGGGHTS-PFM fix forcecontrol/region, ctrlPV velocity (docs/controllers.md). levels[0] is the fine level, which sets the target; levels[1] the coarse level, which is pushed; both grids must have the same geometry. Each control interval every coarse particle of a listed cell gets F = m u / time_step, u the controller's velocity increment towards the fine mean velocity (times the volume-fraction ratio phi_fine/phi_coarse, clamped).",
  "properties": {
    "cells": { "type": "array", "minItems": 1, "items": { "type": "integer", "minimum": 0, "maximum": 4294967294 },
               "description": "indices ix + nx (iy + ny iz) of the cells to control (the coarse cells covered by the fine region), each listed once (default: every cell of the coupling's grid)" },
    "kp": { "type": "number", "minimum": 0, "x-unit": "1",
            "description": "proportional gain k_p per coarse step (default 1/N for a control interval of N coarse steps, as the reference's examples: the error then closes in one interval)" },
    "ki": { "type": "number", "minimum": 0, "default": 0, "x-unit": "1/s",
            "description": "integral gain k_i (0 in the reference examples)" },
    "mass_flow_correction": { "oneOf": [ { "type": "boolean" }, { "type": "array", "minItems": 1, "items": { "type": "boolean" } } ],
                              "default": true,
                              "description": "multiply the target velocity by phi_fine/phi_coarse so that the coarse mass flux matches the fine one (docs/physics.md §5.4): true or false for every cell, or one boolean per entry of cells; false: plain velocity matching" },
    "velocity_limit": { "type": "number", "minimum": 0, "default": 0.2, "x-unit": "1",
                        "description": "relative velocity limit r: a pushed particle's velocity, predicted over the control interval, stays within the fine cell's particle velocity range widened by r (0: no limit)" },
    "correction_bounds": { "type": "array", "minItems": 2, "maxItems": 2, "default": [0.5, 2], "x-unit": "1",
                           "items": { "type": "number", "exclusiveMinimum": 0, "x-unit": "1" },
                           "description": "[lower, upper] clamp of the correction phi_fine/phi_coarse (a domel choice: a nearly empty coarse cell cannot command a huge velocity); lower <= 1 <= upper" }
  },
  "required": [],
  "additionalProperties": false
})json";

  explicit VelocityP(const sdk::Params& p)
      : host_(p.host()),
        cells_(parse_cells(p.json(), kName)),
        has_kp_(p.json().contains("kp")),
        kp_(non_negative(p.json(), "kp", kName, false, 0.0)),
        ki_(non_negative(p.json(), "ki", kName, false, 0.0)),
        velocity_limit_(non_negative(p.json(), "velocity_limit", kName, false, 0.2)) {
    const std::string who = std::string(kName) + ": ";
    correction_.assign(cells_.size(), true);
    if (const auto it = p.json().find("mass_flow_correction"); it != p.json().end() && it->is_boolean()) {
      all_corrected_ = it->get<bool>();
      correction_.assign(cells_.size(), all_corrected_);
    } else if (it != p.json().end()) {
      if (!it->is_array() || it->size() != cells_.size())
        throw sdk::ParameterError(who +
                                  "'mass_flow_correction' must be true, false or an array of booleans with one entry "
                                  "per entry of 'cells' (" + std::to_string(cells_.size()) + "), got " + it->dump());
      for (std::size_t a = 0; a < it->size(); ++a) {
        if (!(*it)[a].is_boolean())
          throw sdk::ParameterError(who + "mass_flow_correction[" + std::to_string(a) + "] must be true or false");
        correction_[a] = (*it)[a].get<bool>();
      }
    }
    if (const auto it = p.json().find("correction_bounds"); it != p.json().end()) {
      if (!it->is_array() || it->size() != 2 || !(*it)[0].is_number() || !(*it)[1].is_number())
        throw sdk::ParameterError(who + "'correction_bounds' must be [lower, upper], got " + it->dump());
      bounds_ = {(*it)[0].get<double>(), (*it)[1].get<double>()};
    }
    if (!std::isfinite(bounds_[0]) || !std::isfinite(bounds_[1]) || !(bounds_[0] > 0.0) || bounds_[0] > 1.0 ||
        bounds_[1] < 1.0) {
      std::ostringstream m;
      m << who << "'correction_bounds' [" << bounds_[0] << ", " << bounds_[1]
        << "] must satisfy 0 < lower <= 1 <= upper (finite)";
      throw sdk::ParameterError(m.str());
    }
    state_.resize(cells_.size());
  }

  /// The coupling's derived values (ABI 2.5): the coarse level's time step
  /// dt of F = m u/dt, the default kp = 1/N for N coarse steps per control
  /// interval and the default cells (all), checked against the grid.
  void setup(const domel_control_setup_v1& s) {
    const SetupLevels lv = checked_setup(s, kName);
    dt_ = lv.coarse->time_step;
    if (!has_kp_) kp_ = 1.0 / static_cast<double>(lv.coarse->steps_per_interval);  // the reference's examples
    if (cells_.empty()) {
      for (std::size_t c = 0; c < s.n_cells; ++c) cells_.push_back(static_cast<uint32_t>(c));
      correction_.assign(cells_.size(), all_corrected_);
      state_.assign(cells_.size(), VelocityPCellState{});
    }
    check_cells_in_setup(cells_, s, kName);
    std::ostringstream m;
    m << "kp = " << kp_ << (has_kp_ ? "" : " (1/N)") << " with N = " << lv.coarse->steps_per_interval
      << " steps of " << dt_ << " s of '" << lv.coarse->name << "' per control interval; " << cells_.size()
      << " cell(s) controlled";
    host_.info(m.str());
  }

  void control(domel_control_step_v1& step) {
    if (!(dt_ > 0.0)) fail(kName, "the coarse time step comes from the host's setup (ABI 2.5), and setup was not called");
    const LevelPair lv = fine_and_coarse(step, kName);
    const domel_cell_grid_v1& gf = *lv.fine->cells;    // target
    const domel_cell_grid_v1& gc = *lv.coarse->cells;  // actual
    domel_particles_v1& pc = checked_particles(*lv.coarse, 1, kName);
    check_cells_in_grid(cells_, gc.n_cells, kName);
    members_.build(pc, cells_, gc.n_cells);

    const double T = step.interval;
    const double* u_f[3] = {gf.ux, gf.uy, gf.uz};
    const double* u_c[3] = {gc.ux, gc.uy, gc.uz};
    const double* u_min[3] = {gf.u_min_x, gf.u_min_y, gf.u_min_z};
    const double* u_max[3] = {gf.u_max_x, gf.u_max_y, gf.u_max_z};
    const double* vel[3] = {pc.vx, pc.vy, pc.vz};
    double* force[3] = {pc.fx, pc.fy, pc.fz};

    for (std::size_t a = 0; a < cells_.size(); ++a) {
      const uint32_t c = cells_[a];
      VelocityPCellState& s = state_[a];
      s.controlled = false;
      s.correction = 0.0;
      s.setpoint = s.process = s.error = s.command = {};
      // nothing to follow or nothing to push (also: the averages saw coarse
      // particles the view no longer has in the cell; integrating would wind up)
      if (gf.count[c] == 0 || gc.count[c] == 0 || members_.size(a) == 0) {
        s.integral = {};
        continue;
      }
      s.controlled = true;
      // §5.4: c_mf = phi_fine/phi_coarse when the correction is on (clamped: domel)
      double c_mf = 1.0;
      if (correction_[a]) {
        const double phi_c = gc.volume_fraction[c];
        c_mf = phi_c > 0.0 ? std::clamp(gf.volume_fraction[c] / phi_c, bounds_[0], bounds_[1]) : bounds_[1];
      }
      s.correction = c_mf;
      for (int k = 0; k < 3; ++k) {
        const double pv = u_c[k][c];          // §5.4 PV = coarse Favre velocity
        const double sp = c_mf * u_f[k][c];   // §5.4 SP = c_mf fine Favre velocity
        const double e = sp - pv;
        s.integral[k] += e * T;
        const double u = kp_ * e + ki_ * s.integral[k];  // a velocity increment per coarse step
        s.setpoint[k] = sp;
        s.process[k] = pv;
        s.error[k] = e;
        s.command[k] = u;
        if (u == 0.0) continue;
        const VelocityBounds b = relative_bounds(u_min[k][c], u_max[k][c], velocity_limit_);
        const double dv = T * u / dt_;  // (T/m) F with F = m u/dt: the same for every particle
        for (const std::size_t* it = members_.begin(a); it != members_.end(a); ++it) {
          const std::size_t i = *it;
          double f = pc.mass[i] * u / dt_;  // §5.4 F_i = m_i u/dt
          if (velocity_limit_ > 0.0) f *= limit_factor(vel[k][i], dv, b);
          force[k][i] += f;
        }
      }
    }
  }

  /// Checkpoints (abi.h, ABI 2.3): per controlled cell the integral and the
  /// last call's figures (what state() shows).
  void save_state(sdk::StateWriter& w) const {
    w.put<std::uint64_t>(state_.size());
    for (const VelocityPCellState& s : state_) {
      w.put(s.integral), w.put(static_cast<std::uint8_t>(s.controlled)), w.put(s.correction);
      w.put(s.setpoint), w.put(s.process), w.put(s.error), w.put(s.command);
    }
  }
  void load_state(sdk::StateReader& r) {
    const auto n = r.get<std::uint64_t>();
    if (n != state_.size())
      throw std::runtime_error("the saved state has " + std::to_string(n) + " cells, this controller controls " +
                               std::to_string(state_.size()));
    for (VelocityPCellState& s : state_) {
      s.integral = r.get<decltype(s.integral)>();
      s.controlled = r.get<std::uint8_t>() != 0;
      s.correction = r.get<double>();
      s.setpoint = r.get<decltype(s.setpoint)>(), s.process = r.get<decltype(s.process)>();
      s.error = r.get<decltype(s.error)>(), s.command = r.get<decltype(s.command)>();
    }
  }

  const std::vector<uint32_t>& cells() const { return cells_; }
  /// The state of each listed cell, in the order of `cells`.
  const std::vector<VelocityPCellState>& state() const { return state_; }

 private:
  sdk::Host host_;
  std::vector<uint32_t> cells_;
  bool has_kp_;
  double kp_, ki_, dt_ = 0.0, velocity_limit_;
  bool all_corrected_ = true;  ///< a boolean mass_flow_correction, for the default cells
  std::vector<bool> correction_;
  std::array<double, 2> bounds_{0.5, 2.0};
  std::vector<VelocityPCellState> state_;
  CellMembers members_;
};

}  // namespace domel::plugins::controller
