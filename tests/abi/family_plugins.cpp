// SPDX-License-Identifier: MIT
//
// A valid plugin library for the ABI tests of the two families declared in
// ABI 2 whose host-side use in a run is later work (issue 14 and the fluid
// issue): one `controller` and one `fluid_coupler`, written with the C++
// layer. Their laws are test laws, chosen so the test can check by hand that
// every view the host hands over was read and every output written:
//  - abi_test_controller: per control interval, each particle of level 0 gets
//    F_x = gain m (u_x of the level-1 cell containing it - v_x) (a P velocity
//    controller towards the other level's average, located with that level's
//    grid geometry); each particle of level 1 gets
//    F_z = -m (u_max_z - u_min_z) of its own cell in its own grid, and
//    F_y = the number of calls so far (the instance keeps state). It logs
//    one line per call through the host.
//  - abi_test_drag: F = 6 pi mu r (u_f - v) along x, times (1 - phi) of the
//    particle's cell when a grid is given. A level without particles is
//    reported through the host's error service, then refused.
#include <domel/sdk/plugin.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

namespace {

class TestController {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_CONTROLLER;
  static constexpr const char* kName = "abi_test_controller";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "ABI test controller: P velocity control between two levels";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "properties": { "gain": { "type": "number", "minimum": 0, "x-unit": "1/s", "description": "gain k_p" } },
  "required": ["gain"],
  "additionalProperties": false
})json";

  explicit TestController(const domel::sdk::Params& p) : gain_(p.number("gain")), host_(p.host()) {}

  void control(domel_control_step_v1& step) {
    ++calls_;
    host_.info("control call " + std::to_string(calls_) + " at t = " + std::to_string(step.time));
    if (step.level_count < 2) throw std::runtime_error("needs two levels, got " + std::to_string(step.level_count));
    domel_level_v1& fine = *step.levels[0];
    domel_level_v1& coarse = *step.levels[1];
    const domel_cell_grid_v1& g = *coarse.cells;
    domel_particles_v1& pf = *fine.particles;
    for (size_t k = 0; k < pf.n; ++k) {
      const auto ix = static_cast<uint32_t>(std::floor((pf.x[k] - g.origin[0]) / g.spacing[0]));
      const auto iy = static_cast<uint32_t>(std::floor((pf.y[k] - g.origin[1]) / g.spacing[1]));
      const auto iz = static_cast<uint32_t>(std::floor((pf.z[k] - g.origin[2]) / g.spacing[2]));
      if (ix >= g.nx || iy >= g.ny || iz >= g.nz) continue;
      const size_t c = ix + static_cast<size_t>(g.nx) * (iy + static_cast<size_t>(g.ny) * iz);
      pf.fx[k] += gain_ * pf.mass[k] * (g.ux[c] - pf.vx[k]);
    }
    domel_particles_v1& pc = *coarse.particles;
    for (size_t k = 0; k < pc.n; ++k) {
      const uint32_t c = pc.cell[k];
      if (c == UINT32_MAX) continue;
      pc.fz[k] += -pc.mass[k] * (g.u_max_z[c] - g.u_min_z[c]);
      pc.fy[k] += static_cast<double>(calls_);
    }
  }

 private:
  double gain_;
  domel::sdk::Host host_;
  int calls_ = 0;
};

class TestDrag {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_FLUID_COUPLER;
  static constexpr const char* kName = "abi_test_drag";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "ABI test fluid coupler: Stokes drag in a uniform flow along x";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "properties": {
    "viscosity": { "type": "number", "minimum": 0, "x-unit": "Pa s", "description": "fluid viscosity mu" },
    "flow_x": { "type": "number", "x-unit": "m/s", "description": "fluid velocity along x" }
  },
  "required": ["viscosity", "flow_x"],
  "additionalProperties": false
})json";

  explicit TestDrag(const domel::sdk::Params& p)
      : mu_(p.number("viscosity")), u_(p.number("flow_x")), host_(p.host()) {}

  void exchange(domel_fluid_exchange_v1& ex) {
    domel_particles_v1* p = ex.level->particles;
    if (p == nullptr || p->n == 0) {
      host_.error(std::string("level '") + ex.level->name + "' handed no particles to couple");
      throw std::runtime_error("nothing to couple");
    }
    const domel_cell_grid_v1* g = ex.level->cells;
    for (size_t k = 0; k < p->n; ++k) {
      double f = 6.0 * M_PI * mu_ * p->radius[k] * (u_ - p->vx[k]);
      if (g != nullptr && p->cell[k] != UINT32_MAX) f *= 1.0 - g->volume_fraction[p->cell[k]];
      p->fx[k] += f;
    }
  }

 private:
  double mu_, u_;
  domel::sdk::Host host_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("abi_families", "1.0.0", TestController, TestDrag)
