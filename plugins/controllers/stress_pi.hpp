// SPDX-License-Identifier: MIT
// Controller "stress_pi": the PI stress (granular pressure) controller on the
// boundary of a fine region, fine <- coarse, after LIGGGHTS-PFM's fix
// forcecontrol/region with ctrlPV stress (docs/physics.md §5.3, with the cell
// averages of §5.2). It pushes the fine particles of each controlled
// boundary cell so that the normal stress they carry matches the stress the
// coarse level carries in the congruent cell.
//
// Levels: levels[0] is the FINE level (it is pushed: "actual"), levels[1]
// the COARSE level (it sets the target); both grids have the same geometry,
// and cell c of one is cell c of the other (anything else is refused).
// step.interval is the control interval T: the forces written are held by
// the host for the next T. Stress in the view: compression negative.
//
// Per call, for each controlled cell c and each component k with dir_k != 0
// (physics.md §5.3; the comments in control() name each line's source):
//   empty cell (count 0 on either level): reset I_k, forget PV_old
//   phi_t <= phi_a / 2: skip, keep the state
//   rho3 = (cg_a/cg_t)^3, c_phi = phi_a/phi_t, pre_t = V_c/(2 rbar_a), pre_a = pre_t c_phi
//   PV_k = -pre_a S^a_kk / N_a,  SP_k = -pre_t S^t_kk / (N_t/rho3), both >= 0
//   e_k = SP_k - PV_k;  I_k += e_k T;  u_k = kp e_k + ki I_k - kd (PV_k - PV_old,k)/T
//   u_k < 0: undo the integration, no force (push inward only)
//   F = dir_k u_k on each fine particle of c in the forcing layer (full over
//   the outer 1 - fade_fraction of it, sin^2 ramp to 0 over the inner part),
//   scaled per particle by the velocity limiter (common.hpp), which predicts
//   v + h F/m over the horizon h (limit_horizon, default one fine step)
//   mean applied |F| per controlled particle < u_k/2: undo the integration
// Units: PV, SP, e, u in N (a mean normal force per particle), I in N s.
#pragma once

#include "common.hpp"

#include <domel/sdk/plugin.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace domel::plugins::controller {

/// What stress_pi did with one controlled cell in its last call.
enum class StressPiOutcome {
  kNotRun,      ///< no call yet
  kEmpty,       ///< a cell with no particle on either level: state reset, no force
  kSkipped,     ///< phi_target <= phi_actual / 2: no force, state kept
  kControlled,  ///< the PI law ran for every component with dir_k != 0
};

/// The state stress_pi keeps per controlled cell (the integral and the last
/// PV, per component x, y, z), and what its last call computed, for tests
/// and diagnostics (0 where nothing was computed).
struct StressPiCellState {
  std::array<double, 3> integral{};     ///< I_k [N s]
  std::array<double, 3> pv_old{};       ///< PV_k of the previous call [N]
  std::array<bool, 3> has_pv_old{};     ///< false on the first call and after a reset: no derivative term
  StressPiOutcome outcome = StressPiOutcome::kNotRun;
  // the last call
  std::array<double, 3> setpoint{};     ///< SP_k [N]
  std::array<double, 3> process{};      ///< PV_k [N]
  std::array<double, 3> error{};        ///< e_k [N]
  std::array<double, 3> command{};      ///< u_k [N]
  std::array<std::size_t, 3> pushed{};  ///< particles of the cell in the forcing layer (0 when u_k <= 0)
  std::array<double, 3> applied_mean{}; ///< mean applied |F_k| over those particles [N]
  std::array<bool, 3> unwound{};        ///< the integration was undone (a priori or a posteriori)
};

class StressPi {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_CONTROLLER;
  static constexpr const char* kName = "stress_pi";
  static constexpr const char* kVersion = "2.0.0";
  static constexpr const char* kSummary =
      "PI stress controller on the fine region's boundary cells: pushes levels[0] (FINE) particles so their normal "
      "stress matches levels[1] (COARSE) in the congruent cell (grids of both levels must match)";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Fine-boundary stress controller after LIGGGHTS-PFM fix forcecontrol/region, ctrlPV stress (docs/controllers.md). levels[0] is the fine level, which is pushed; levels[1] the coarse level, which sets the target; both grids must have the same geometry. Each control interval it compares the mean normal force per particle from the normal stress of each controlled fine cell with the coarse level's in the congruent cell, and pushes the fine particles in a layer against one face of the cell.",
  "properties": {
    "cells": { "type": "array", "minItems": 1, "items": { "type": "integer", "minimum": 0, "maximum": 4294967294 },
               "description": "indices ix + nx (iy + ny iz) of the cells to control (the active boundary cells), each listed once, with directions (default: the coupling's inflow cells, those touching a face where material enters the fine level)" },
    "directions": { "type": "array", "minItems": 1,
                    "items": { "type": "array", "minItems": 3, "maxItems": 3, "items": { "type": "integer", "enum": [-1, 0, 1] } },
                    "description": "one per entry of cells, given with cells: the direction [x, y, z] the force pushes in, components -1, 0 or 1 (e.g. [0, 0, -1] for a cell under a top inflow face); components 0 are not controlled (default: the inward normal of the inflow face(s) each inflow cell touches)" },
    "kp": { "type": "number", "minimum": 0, "x-unit": "1",
            "description": "proportional gain k_p (default 1/N for a control interval of N fine steps, as the reference's examples)" },
    "ki": { "type": "number", "minimum": 0, "x-unit": "1/s",
            "description": "integral gain k_i (default 1/(N dt_fine), as the reference's examples)" },
    "kd": { "type": "number", "minimum": 0, "default": 0, "x-unit": "s",
            "description": "derivative gain k_d, on the process value, not on the error" },
    "layer_diameters": { "type": "number", "exclusiveMinimum": 0, "default": 1.4, "x-unit": "1",
                         "description": "thickness of the forcing layer against the pushing face, in units of the fine level's largest particle diameter (LIGGGHTS-PFM code: 1.4; its documentation: 1.3 + 0.25)" },
    "fade_fraction": { "type": "number", "minimum": 0, "maximum": 1, "default": 0.125, "x-unit": "1",
                       "description": "inner share of the forcing layer over which the force fades to zero with a sin^2 ramp" },
    "velocity_limit": { "type": "number", "minimum": 0, "default": 0.2, "x-unit": "1",
                        "description": "relative velocity limit r: a pushed particle's velocity, predicted over the limit horizon, stays within the coarse cell's particle velocity range widened by r (LIGGGHTS-PFM velocity_limit on: 0.2; 0: no limit)" },
    "limit_horizon": { "type": "number", "exclusiveMinimum": 0, "x-unit": "s",
                       "description": "time over which the velocity limiter predicts the force's effect, v + horizon F/m (default: one fine time step). The reference predicts one (half) step with the contact force included; a particle pressed into a bed has its push balanced by its contacts, which this view does not carry, so a horizon of a whole control interval throttles the push far below what the bed needs" }
  },
  "required": [],
  "additionalProperties": false
})json";

  explicit StressPi(const sdk::Params& p)
      : host_(p.host()),
        cells_(parse_cells(p.json(), kName)),
        has_kp_(p.json().contains("kp")),
        has_ki_(p.json().contains("ki")),
        kp_(non_negative(p.json(), "kp", kName, false, 0.0)),
        ki_(non_negative(p.json(), "ki", kName, false, 0.0)),
        kd_(non_negative(p.json(), "kd", kName, false, 0.0)),
        layer_diameters_(non_negative(p.json(), "layer_diameters", kName, false, 1.4)),
        fade_fraction_(non_negative(p.json(), "fade_fraction", kName, false, 0.125)),
        velocity_limit_(non_negative(p.json(), "velocity_limit", kName, false, 0.2)),
        limit_horizon_(non_negative(p.json(), "limit_horizon", kName, false, 0.0)) {
    const std::string who = std::string(kName) + ": ";
    if (!(layer_diameters_ > 0.0)) throw sdk::ParameterError(who + "'layer_diameters' must be > 0");
    if (fade_fraction_ > 1.0) throw sdk::ParameterError(who + "'fade_fraction' must lie in [0, 1]");
    if (p.json().contains("limit_horizon") && !(limit_horizon_ > 0.0))
      throw sdk::ParameterError(who + "'limit_horizon' must be > 0");
    if (cells_.empty() != !p.json().contains("directions"))
      throw sdk::ParameterError(who + "give 'cells' and 'directions' together (one direction per cell), or neither "
                                      "(the coupling's inflow cells with their inward normals)");
    if (!cells_.empty()) directions_ = parse_directions(p.json(), cells_.size());
    state_.resize(cells_.size());
  }

  /// The coupling's derived values (ABI 2.5): the defaults of kp, ki, the
  /// limit horizon and the cells from the fine level's step and the steps
  /// per interval, and the cells checked against the grid.
  void setup(const domel_control_setup_v1& s) {
    const SetupLevels lv = checked_setup(s, kName);
    const double n = static_cast<double>(lv.fine->steps_per_interval), dt = lv.fine->time_step;
    if (!has_kp_) kp_ = 1.0 / n;         // the reference's examples: 1/N
    if (!has_ki_) ki_ = 1.0 / (n * dt);  // and 1/(N dt_fine)
    if (!(limit_horizon_ > 0.0)) limit_horizon_ = dt;
    if (cells_.empty()) {
      if (s.n_inflow_cells == 0 || s.inflow_cell == nullptr || s.inflow_direction == nullptr)
        throw sdk::ParameterError(std::string(kName) + ": the coupling has no inflow cell to control: give 'cells' and "
                                                       "'directions'");
      for (std::size_t a = 0; a < s.n_inflow_cells; ++a) {
        cells_.push_back(s.inflow_cell[a]);
        directions_.push_back({s.inflow_direction[3 * a], s.inflow_direction[3 * a + 1], s.inflow_direction[3 * a + 2]});
      }
      state_.assign(cells_.size(), StressPiCellState{});
    }
    check_cells_in_setup(cells_, s, kName);
    set_up_ = true;
    std::ostringstream m;
    m << "kp = " << kp_ << (has_kp_ ? "" : " (1/N)") << ", ki = " << ki_ << " 1/s" << (has_ki_ ? "" : " (1/(N dt))")
      << " with N = " << lv.fine->steps_per_interval << " steps of " << dt << " s of '" << lv.fine->name
      << "' per control interval; " << cells_.size() << " cell(s) controlled";
    host_.info(m.str());
  }

  void control(domel_control_step_v1& step) {
    if (!set_up_ && (!has_kp_ || !has_ki_ || cells_.empty()))
      fail(kName, "kp, ki or cells were left to their defaults, which come from the host's setup (ABI 2.5), and "
                  "setup was not called");
    const LevelPair lv = fine_and_coarse(step, kName);
    const domel_cell_grid_v1& ga = *lv.fine->cells;    // actual
    const domel_cell_grid_v1& gt = *lv.coarse->cells;  // target
    domel_particles_v1& pa = checked_particles(*lv.fine, 0, kName);
    check_cells_in_grid(cells_, ga.n_cells, kName);
    members_.build(pa, cells_, ga.n_cells);

    const double T = step.interval;
    const double horizon = limit_horizon_ > 0.0 ? limit_horizon_ : T;  // the velocity limiter's look-ahead
    const double volume = ga.spacing[0] * ga.spacing[1] * ga.spacing[2];  // V_c
    // physics.md §5.3 "Where the force acts": used = 1.4 d_max, d_max the
    // largest fine diameter (the reference's 2 r_max cg_a/cg_max); over the
    // whole fine level, as r_max is over all atoms there.
    double r_max = 0.0;
    for (std::size_t k = 0; k < pa.n; ++k) r_max = std::max(r_max, pa.radius[k]);
    const double used = layer_diameters_ * 2.0 * r_max;
    const double ratio = lv.fine->coarse_grain / lv.coarse->coarse_grain;
    const double rho3 = ratio * ratio * ratio;  // (cg_a/cg_t)^3, §5.3
    const double* pos[3] = {pa.x, pa.y, pa.z};
    const double* vel[3] = {pa.vx, pa.vy, pa.vz};
    double* force[3] = {pa.fx, pa.fy, pa.fz};
    const double* u_min[3] = {gt.u_min_x, gt.u_min_y, gt.u_min_z};
    const double* u_max[3] = {gt.u_max_x, gt.u_max_y, gt.u_max_z};

    for (std::size_t a = 0; a < cells_.size(); ++a) {
      const uint32_t c = cells_[a];
      StressPiCellState& s = state_[a];
      clear_last(s);
      // §5.3: "if either cell is empty: reset integral and previous PV". A
      // cell the averages call occupied but with no particle in the view
      // has nobody to push and no mean radius: treated as empty too.
      if (ga.count[c] == 0 || gt.count[c] == 0 || members_.size(a) == 0) {
        s.integral = {};
        s.pv_old = {};
        s.has_pv_old = {};
        s.outcome = StressPiOutcome::kEmpty;
        continue;
      }
      const double phi_a = ga.volume_fraction[c], phi_t = gt.volume_fraction[c];
      if (phi_t <= 0.5 * phi_a) {  // §5.3: skip if phi_target <= 0.5 phi_actual
        s.outcome = StressPiOutcome::kSkipped;
        continue;
      }
      s.outcome = StressPiOutcome::kControlled;
      double r_sum = 0.0;
      for (const std::size_t* i = members_.begin(a); i != members_.end(a); ++i) r_sum += pa.radius[*i];
      const double r_bar = r_sum / static_cast<double>(members_.size(a));  // §5.2 arithmetic mean radius
      const double pre_t = 0.5 * volume / r_bar;                           // §5.3 pre_t = V_c/(2 rbar_a)
      const double pre_a = pre_t * (phi_a / phi_t);                        // §5.3 pre_a = pre_t c
      const double n_a = static_cast<double>(ga.count[c]);
      const double n_t = static_cast<double>(gt.count[c]) / rho3;  // target count in fine particles
      const uint32_t ix = c % ga.nx, iy = (c / ga.nx) % ga.ny, iz = c / (ga.nx * ga.ny);
      const uint32_t idx[3] = {ix, iy, iz};

      for (int k = 0; k < 3; ++k) {
        const int dir = directions_[a][k];
        if (dir == 0) continue;
        // §5.3: PV_k = -pre_a S^a_kk / N_a, SP_k = -pre_t S^t_kk / (N_t/rho3),
        // clipped at >= 0; SP_k <= 0 also resets the integral.
        const double pv = std::max(0.0, -pre_a * ga.stress[6 * static_cast<std::size_t>(c) + k] / n_a);
        double sp = -pre_t * gt.stress[6 * static_cast<std::size_t>(c) + k] / n_t;
        if (!(sp > 0.0)) {
          sp = 0.0;
          s.integral[k] = 0.0;
        }
        const double e = sp - pv;  // (SP - PV) |dir_k|, |dir_k| = 1 here
        s.integral[k] += e * T;
        // derivative on PV, not on the error (§5.3); none without a previous PV
        const double d = s.has_pv_old[k] ? -(pv - s.pv_old[k]) / T : 0.0;
        const double u = kp_ * e + ki_ * s.integral[k] + kd_ * d;
        s.setpoint[k] = sp;
        s.process[k] = pv;
        s.error[k] = e;
        s.command[k] = u;
        s.pv_old[k] = pv;
        s.has_pv_old[k] = true;
        if (u < 0.0) {  // a-priori anti-windup: push inward only, undo this integration
          s.integral[k] -= e * T;
          s.unwound[k] = true;
          continue;
        }
        if (!(u > 0.0)) continue;

        // The forcing layer against the face the force pushes from (§5.3):
        // dir -1 pushes down from the upper face hi_k, dir +1 up from lo_k.
        const double lo = ga.origin[k] + static_cast<double>(idx[k]) * ga.spacing[k];
        const double hi = lo + ga.spacing[k];
        const VelocityBounds bounds = relative_bounds(u_min[k][c], u_max[k][c], velocity_limit_);
        std::size_t pushed = 0;
        double applied = 0.0;
        for (const std::size_t* it = members_.begin(a); it != members_.end(a); ++it) {
          const std::size_t i = *it;
          const double depth = dir < 0 ? hi - pos[k][i] : pos[k][i] - lo;
          const double w = layer_weight(depth, used, fade_fraction_);
          if (!(w > 0.0)) continue;
          ++pushed;
          double f = static_cast<double>(dir) * u * w;
          if (velocity_limit_ > 0.0) {
            const double m = pa.mass[i];
            f *= m > 0.0 ? limit_factor(vel[k][i], horizon * f / m, bounds) : 0.0;
          }
          force[k][i] += f;
          applied += std::fabs(f);
        }
        s.pushed[k] = pushed;
        s.applied_mean[k] = pushed > 0 ? applied / static_cast<double>(pushed) : 0.0;
        // a-posteriori anti-windup (§5.3): the particles took less than half
        // of the commanded force (limited, or none in the layer): undo
        if (s.applied_mean[k] < 0.5 * u) {
          s.integral[k] -= e * T;
          s.unwound[k] = true;
        }
      }
    }
  }

  /// Weight of the force at `depth` from the pushing face, for a layer of
  /// thickness `used` whose inner share `fade` ramps to zero (§5.3): 1 over
  /// the outer (1 - fade) used, then sin^2((pi/2)(used - depth)/(fade used)),
  /// 0 beyond the layer. A depth below 0 (rounding at the face) counts as 1.
  static double layer_weight(double depth, double used, double fade) {
    if (!(used > 0.0) || depth >= used) return 0.0;
    if (depth <= (1.0 - fade) * used) return 1.0;
    const double s = std::sin(0.5 * kPi * (used - depth) / (fade * used));
    return s * s;
  }

  /// Checkpoints (abi.h, ABI 2.3): per controlled cell the integral, the
  /// previous PV and whether there is one, and the last call's outcome and
  /// figures (what state() shows).
  void save_state(sdk::StateWriter& w) const {
    w.put<std::uint64_t>(state_.size());
    for (const StressPiCellState& s : state_) {
      w.put(s.integral), w.put(s.pv_old), w.put(s.has_pv_old), w.put(s.outcome);
      w.put(s.setpoint), w.put(s.process), w.put(s.error), w.put(s.command), w.put(s.pushed);
      w.put(s.applied_mean), w.put(s.unwound);
    }
  }
  void load_state(sdk::StateReader& r) {
    const auto n = r.get<std::uint64_t>();
    if (n != state_.size())
      throw std::runtime_error("the saved state has " + std::to_string(n) + " cells, this controller controls " +
                               std::to_string(state_.size()));
    for (StressPiCellState& s : state_) {
      s.integral = r.get<decltype(s.integral)>(), s.pv_old = r.get<decltype(s.pv_old)>();
      s.has_pv_old = r.get<decltype(s.has_pv_old)>(), s.outcome = r.get<StressPiOutcome>();
      s.setpoint = r.get<decltype(s.setpoint)>(), s.process = r.get<decltype(s.process)>();
      s.error = r.get<decltype(s.error)>(), s.command = r.get<decltype(s.command)>();
      s.pushed = r.get<decltype(s.pushed)>(), s.applied_mean = r.get<decltype(s.applied_mean)>();
      s.unwound = r.get<decltype(s.unwound)>();
    }
  }

  const std::vector<uint32_t>& cells() const { return cells_; }
  /// The state of each controlled cell, in the order of `cells`.
  const std::vector<StressPiCellState>& state() const { return state_; }

 private:
  static constexpr double kPi = 3.14159265358979323846;

  static std::vector<std::array<int, 3>> parse_directions(const nlohmann::json& j, std::size_t n_cells) {
    const std::string who = std::string(kName) + ": ";
    const auto it = j.find("directions");
    if (it == j.end())
      throw sdk::ParameterError(who +
                                "missing required 'directions' (one [x, y, z] with components -1, 0, 1 per cell)");
    if (!it->is_array() || it->size() != n_cells)
      throw sdk::ParameterError(who + "'directions' must be an array with one entry per cell (" +
                                std::to_string(n_cells) + "), got " +
                                (it->is_array() ? std::to_string(it->size()) + " entries" : it->dump()));
    std::vector<std::array<int, 3>> out;
    for (std::size_t a = 0; a < it->size(); ++a) {
      const nlohmann::json& d = (*it)[a];
      const std::string where = "directions[" + std::to_string(a) + "]";
      if (!d.is_array() || d.size() != 3)
        throw sdk::ParameterError(who + where + " must be a 3-vector [x, y, z], got " + d.dump());
      std::array<int, 3> v{};
      for (int k = 0; k < 3; ++k) {
        const nlohmann::json& x = d[static_cast<std::size_t>(k)];
        if (!x.is_number_integer() || x.get<int64_t>() < -1 || x.get<int64_t>() > 1)
          throw sdk::ParameterError(who + where + " has component " + x.dump() + "; each must be -1, 0 or 1");
        v[static_cast<std::size_t>(k)] = static_cast<int>(x.get<int64_t>());
      }
      if (v[0] == 0 && v[1] == 0 && v[2] == 0)
        throw sdk::ParameterError(who + where + " is [0, 0, 0]: that cell would never be pushed; leave it out of "
                                  "'cells' or give it a direction");
      out.push_back(v);
    }
    return out;
  }

  static void clear_last(StressPiCellState& s) {
    s.setpoint = {};
    s.process = {};
    s.error = {};
    s.command = {};
    s.pushed = {};
    s.applied_mean = {};
    s.unwound = {};
  }

  sdk::Host host_;
  std::vector<uint32_t> cells_;
  std::vector<std::array<int, 3>> directions_;
  bool has_kp_, has_ki_;
  double kp_, ki_, kd_;
  double layer_diameters_, fade_fraction_, velocity_limit_;
  double limit_horizon_;  ///< 0 until setup: the control interval
  bool set_up_ = false;
  std::vector<StressPiCellState> state_;
  CellMembers members_;
};

}  // namespace domel::plugins::controller
