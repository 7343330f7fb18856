// SPDX-License-Identifier: MIT
// Shared pieces of the built-in controllers (stress_pi, velocity_p): the
// checks of a control step handed over through the ABI (exactly two levels,
// levels[0] FINE and levels[1] COARSE, on congruent grids, so that cell c of
// one is cell c of the other), the parameter readers both models share (the
// list of controlled cells, non-negative gains), the particles of each
// controlled cell gathered once per call, and the velocity limiter of
// LIGGGHTS-PFM's fix forcecontrol/region (docs/physics.md §5.3, "Velocity
// limit") in the form domel needs: the host holds a controller's force for
// the whole control interval T, so the predicted velocity is v + (T/m) F.
#pragma once

#include <domel/sdk/plugin.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace domel::plugins::controller {

constexpr uint32_t kOutside = UINT32_MAX;  ///< domel_particles_v1::cell of a particle outside the grid

/// The two levels of a control step: levels[0] is the fine level, levels[1]
/// the coarse one (the convention of every built-in controller).
struct LevelPair {
  domel_level_v1* fine;
  domel_level_v1* coarse;
};

/// Throws std::runtime_error "<model>: <what>".
[[noreturn]] inline void fail(const char* model, const std::string& what) {
  throw std::runtime_error(std::string(model) + ": " + what);
}

inline std::string level_label(const domel_level_v1& l, int index) {
  return "levels[" + std::to_string(index) + "] ('" + std::string(l.name ? l.name : "?") + "')";
}

/// Refuses a grid without the fields the controllers read.
inline void check_grid_fields(const domel_level_v1& l, int index, const char* model) {
  const domel_cell_grid_v1* g = l.cells;
  if (g == nullptr) fail(model, level_label(l, index) + " has no cell grid; the controller works on cell averages");
  if (g->n_cells != static_cast<std::size_t>(g->nx) * g->ny * g->nz)
    fail(model, level_label(l, index) + " has n_cells " + std::to_string(g->n_cells) + " but nx ny nz = " +
                    std::to_string(static_cast<std::size_t>(g->nx) * g->ny * g->nz));
  const void* fields[] = {g->count,   g->volume_fraction, g->ux,      g->uy,      g->uz,     g->u_min_x,
                          g->u_min_y, g->u_min_z,         g->u_max_x, g->u_max_y, g->u_max_z, g->stress};
  if (g->n_cells > 0)
    for (const void* f : fields)
      if (f == nullptr) fail(model, level_label(l, index) + " has a cell grid with a missing field (null array)");
}

/// Refuses two grids that differ in cell counts, origin or spacing (beyond
/// a relative 1e-9 of the spacing, i.e. rounding in the host's geometry).
inline void check_congruent(const domel_level_v1& a, const domel_level_v1& b, const char* model) {
  const domel_cell_grid_v1& ga = *a.cells;
  const domel_cell_grid_v1& gb = *b.cells;
  std::ostringstream m;
  m.precision(17);
  if (ga.nx != gb.nx || ga.ny != gb.ny || ga.nz != gb.nz)
    m << "cells per axis " << ga.nx << "x" << ga.ny << "x" << ga.nz << " vs " << gb.nx << "x" << gb.ny << "x" << gb.nz;
  for (int k = 0; k < 3 && m.tellp() == 0; ++k) {
    const double h = std::max(std::fabs(ga.spacing[k]), std::fabs(gb.spacing[k]));
    const double tol = 1e-9 * h;
    if (!(std::fabs(ga.spacing[k] - gb.spacing[k]) <= tol))
      m << "spacing[" << k << "] " << ga.spacing[k] << " vs " << gb.spacing[k];
    else if (!(std::fabs(ga.origin[k] - gb.origin[k]) <= tol))
      m << "origin[" << k << "] " << ga.origin[k] << " vs " << gb.origin[k];
  }
  if (m.tellp() != 0)
    fail(model, "the grids of " + level_label(a, 0) + " and " + level_label(b, 1) + " differ (" + m.str() +
                    "); the controller pairs cell c of the fine level with cell c of the coarse level, so both "
                    "levels need the same grid geometry (cell counts, origin, spacing)");
}

/// The fine and coarse level of a step, after checking the step: exactly
/// two levels, a finite interval T > 0, both grids complete and congruent,
/// finite coarse-grain ratios > 0.
inline LevelPair fine_and_coarse(const domel_control_step_v1& step, const char* model) {
  if (step.level_count != 2)
    fail(model, "needs exactly 2 levels (levels[0] the fine level, levels[1] the coarse level), got " +
                    std::to_string(step.level_count));
  if (step.levels == nullptr || step.levels[0] == nullptr || step.levels[1] == nullptr)
    fail(model, "the control step has a null level");
  if (!std::isfinite(step.interval) || !(step.interval > 0.0)) {
    std::ostringstream m;
    m << "the control interval must be finite and > 0 s, got " << step.interval;
    fail(model, m.str());
  }
  const LevelPair p{step.levels[0], step.levels[1]};
  check_grid_fields(*p.fine, 0, model);
  check_grid_fields(*p.coarse, 1, model);
  check_congruent(*p.fine, *p.coarse, model);
  for (int i = 0; i < 2; ++i) {
    const domel_level_v1& l = *step.levels[i];
    if (!std::isfinite(l.coarse_grain) || !(l.coarse_grain > 0.0))
      fail(model, level_label(l, i) + " has a coarse-grain ratio that is not > 0");
  }
  return p;
}

/// The two levels of a setup (ABI 2.5), checked as fine_and_coarse checks a
/// step: exactly two levels, levels[0] fine and levels[1] coarse, each with
/// a finite time step > 0 and at least one step per control interval, and a
/// grid of at least one cell. Refuses with sdk::ParameterError.
struct SetupLevels {
  const domel_control_level_setup_v1* fine;
  const domel_control_level_setup_v1* coarse;
};
inline SetupLevels checked_setup(const domel_control_setup_v1& s, const char* model) {
  const std::string who = std::string(model) + ": ";
  if (s.level_count != 2 || s.levels == nullptr)
    throw sdk::ParameterError(who + "needs exactly 2 levels (levels[0] the fine level, levels[1] the coarse level), got " +
                              std::to_string(s.level_count));
  for (int i = 0; i < 2; ++i) {
    const domel_control_level_setup_v1& l = s.levels[i];
    if (!std::isfinite(l.time_step) || !(l.time_step > 0.0) || l.steps_per_interval == 0)
      throw sdk::ParameterError(who + "levels[" + std::to_string(i) + "] ('" + (l.name ? l.name : "?") +
                                "') needs a time step > 0 and at least one step per control interval");
  }
  if (s.n_cells == 0) throw sdk::ParameterError(who + "the coupling's grid has no cell");
  return {&s.levels[0], &s.levels[1]};
}

/// Refuses (sdk::ParameterError) a listed cell index beyond the grid of a setup.
inline void check_cells_in_setup(const std::vector<uint32_t>& cells, const domel_control_setup_v1& s,
                                 const char* model) {
  for (std::size_t a = 0; a < cells.size(); ++a)
    if (cells[a] >= s.n_cells)
      throw sdk::ParameterError(std::string(model) + ": cells[" + std::to_string(a) + "] = " +
                                std::to_string(cells[a]) + " lies outside the coupling's grid (" +
                                std::to_string(s.nx) + " x " + std::to_string(s.ny) + " x " + std::to_string(s.nz) +
                                " = " + std::to_string(s.n_cells) + " cells; index ix + nx (iy + ny iz))");
}

/// The particles of a level the controller writes to, after checking that
/// every array it reads or writes is there.
inline domel_particles_v1& checked_particles(domel_level_v1& l, int index, const char* model) {
  domel_particles_v1* p = l.particles;
  if (p == nullptr) fail(model, level_label(l, index) + " has no particle view");
  if (p->n > 0) {
    const void* fields[] = {p->x, p->y, p->z, p->vx, p->vy, p->vz, p->mass, p->radius, p->cell, p->fx, p->fy, p->fz};
    for (const void* f : fields)
      if (f == nullptr) fail(model, level_label(l, index) + " has a particle view with a missing array (null)");
  }
  return *p;
}

/// Refuses a controlled cell index outside the grid.
inline void check_cells_in_grid(const std::vector<uint32_t>& cells, std::size_t n_cells, const char* model) {
  for (std::size_t a = 0; a < cells.size(); ++a)
    if (cells[a] >= n_cells)
      fail(model, "cells[" + std::to_string(a) + "] = " + std::to_string(cells[a]) + " lies outside the grid (" +
                      std::to_string(n_cells) + " cells; index ix + nx (iy + ny iz))");
}

/// The particles of each controlled cell, gathered in one pass over a
/// level's particles: members(a) are the indices k with cell[k] == cells[a].
/// Kept in the model between calls so the per-grid-cell lookup is
/// allocated once.
class CellMembers {
 public:
  void build(const domel_particles_v1& p, const std::vector<uint32_t>& cells, std::size_t n_cells) {
    if (slot_.size() != n_cells) {
      slot_.assign(n_cells, -1);
      for (std::size_t a = 0; a < cells.size(); ++a) slot_[cells[a]] = static_cast<int64_t>(a);
    }
    offset_.assign(cells.size() + 1, 0);
    for (std::size_t k = 0; k < p.n; ++k) {
      const int64_t a = lookup(p.cell[k]);
      if (a >= 0) ++offset_[static_cast<std::size_t>(a) + 1];
    }
    for (std::size_t a = 0; a < cells.size(); ++a) offset_[a + 1] += offset_[a];
    index_.resize(offset_.back());
    std::vector<std::size_t> fill(offset_.begin(), offset_.end() - 1);
    for (std::size_t k = 0; k < p.n; ++k) {
      const int64_t a = lookup(p.cell[k]);
      if (a >= 0) index_[fill[static_cast<std::size_t>(a)]++] = k;
    }
  }
  std::size_t size(std::size_t a) const { return offset_[a + 1] - offset_[a]; }
  const std::size_t* begin(std::size_t a) const { return index_.data() + offset_[a]; }
  const std::size_t* end(std::size_t a) const { return index_.data() + offset_[a + 1]; }

 private:
  int64_t lookup(uint32_t c) const { return c < slot_.size() ? slot_[c] : -1; }  // kOutside too
  std::vector<int64_t> slot_;  // per grid cell: its entry in `cells`, or -1
  std::vector<std::size_t> offset_, index_;
};

/// Lower and upper velocity limit of one component [m/s].
struct VelocityBounds {
  double lo, hi;
};

/// The relative velocity limit of fix forcecontrol/region (docs/physics.md
/// §5.3, "Velocity limit"): from the target cell's smallest and largest
/// particle velocity, widened by the fraction r and sign-aware, so that the
/// band always grows: hi = u_max (1 + r) if u_max >= 0 else u_max (1 - r);
/// lo = u_min (1 - r) if u_min >= 0 else u_min (1 + r).
inline VelocityBounds relative_bounds(double u_min, double u_max, double r) {
  return {u_min >= 0.0 ? u_min * (1.0 - r) : u_min * (1.0 + r), u_max >= 0.0 ? u_max * (1.0 + r) : u_max * (1.0 - r)};
}

/// The factor lambda in [0, 1] by which a particle's controller force is
/// scaled so that its predicted velocity v + lambda dv stays inside the
/// bounds on the side the force pushes to (physics.md §5.3). dv = (T/m) F is
/// the change the force would make over the control interval T, because the
/// host holds the force for all of T (the reference predicts half a step,
/// (dt/2m)(f + F), since it re-applies the force every step; domel's choice,
/// docs/controllers.md). A particle already at or beyond the limit in the
/// direction of the force gets lambda = 0.
inline double limit_factor(double v, double dv, const VelocityBounds& b) {
  if (dv > 0.0) {
    if (!(v < b.hi)) return 0.0;
    const double room = b.hi - v;
    return room < dv ? room / dv : 1.0;
  }
  if (dv < 0.0) {
    if (!(v > b.lo)) return 0.0;
    const double room = b.lo - v;  // negative
    return room > dv ? room / dv : 1.0;
  }
  return 1.0;
}

// ---------------------------------------------------------------- parameters

/// A finite number >= 0 (a gain or limit); `fallback` when absent and not
/// required. Refuses with sdk::ParameterError naming the model and the key.
inline double non_negative(const nlohmann::json& j, const char* key, const char* model, bool required,
                           double fallback = 0.0) {
  const auto it = j.find(key);
  if (it == j.end()) {
    if (required) throw sdk::ParameterError(std::string(model) + ": missing required number '" + key + "'");
    return fallback;
  }
  if (!it->is_number()) throw sdk::ParameterError(std::string(model) + ": '" + key + "' must be a number");
  const double v = it->get<double>();
  if (!std::isfinite(v) || v < 0.0) {
    std::ostringstream m;
    m << model << ": '" << key << "' must be a finite number >= 0, got " << v;
    throw sdk::ParameterError(m.str());
  }
  return v;
}

/// The list `cells`: distinct grid-cell indices (integers >= 0); empty
/// when absent (the model then takes its default from the setup).
inline std::vector<uint32_t> parse_cells(const nlohmann::json& j, const char* model) {
  const std::string who = std::string(model) + ": ";
  const auto it = j.find("cells");
  if (it == j.end()) return {};
  if (!it->is_array() || it->empty())
    throw sdk::ParameterError(who + "'cells' must be a non-empty array of cell indices");
  std::vector<uint32_t> cells;
  for (std::size_t a = 0; a < it->size(); ++a) {
    const nlohmann::json& c = (*it)[a];
    if (!c.is_number_integer() || c.get<int64_t>() < 0 || c.get<int64_t>() >= static_cast<int64_t>(kOutside))
      throw sdk::ParameterError(who + "cells[" + std::to_string(a) + "] must be an integer cell index >= 0, got " +
                                c.dump());
    const auto v = static_cast<uint32_t>(c.get<int64_t>());
    const auto dup = std::find(cells.begin(), cells.end(), v);
    if (dup != cells.end())
      throw sdk::ParameterError(who + "cell " + std::to_string(v) + " is listed twice (cells[" +
                                std::to_string(dup - cells.begin()) + "] and cells[" + std::to_string(a) + "])");
    cells.push_back(v);
  }
  return cells;
}

}  // namespace domel::plugins::controller
