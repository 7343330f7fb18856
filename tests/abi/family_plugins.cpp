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
//  - abi_test_band (ABI 2.5): a controller with parameters of its own names
//    (gain, band) that takes its coupling's derived values from setup();
//    see the class.
//  - abi_test_drag: F = 6 pi mu r (u_f - v) along x, times (1 - phi) of the
//    particle's cell when a grid is given. A level without particles is
//    reported through the host's error service, then refused.
//  - abi_test_linear_drag (ABI 2.2): every particle of every level gets the
//    linearised drag beta = m / relaxation_time towards the uniform "flow"
//    (refreshed by the host every step) and the held force m "held"; it logs
//    each level's first particle's interval-mean velocity; its limits
//    callback reports "max_interval" (after the first exchange
//    "max_interval_later" when given); its fields callback a 1x1x2 grid
//    over [-1, 1.5] x [-1, 1.5] x [-1, 4] m with the exchange count and the
//    flow.
#include <domel/sdk/plugin.hpp>

#include <cmath>
#include <cstdio>
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

// abi_test_band: a controller with parameters of its own names, set up by
// the host (ABI 2.5). Per control interval each particle of level 1 (the
// coarse one) in a cell where level 0 (the fine one) has particles gets
// F_k = gain m (u_k - v_k) per component k whose |u_k - v_k| exceeds band,
// u the level-0 cell's mean velocity. setup() logs what it was handed; each
// call logs how many particles it pushed. It keeps the call count as state.
class TestBandController {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_CONTROLLER;
  static constexpr const char* kName = "abi_test_band";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "ABI test controller: a dead-band P velocity law with gain and band";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "properties": {
    "gain": { "type": "number", "minimum": 0, "x-unit": "1/s", "description": "relaxation rate of level 1 towards level 0's cell velocity" },
    "band": { "type": "number", "minimum": 0, "default": 0, "x-unit": "m/s", "description": "velocity differences up to this get no force" }
  },
  "required": ["gain"],
  "additionalProperties": false
})json";

  explicit TestBandController(const domel::sdk::Params& p)
      : gain_(p.number("gain")), band_(p.has("band") ? p.number("band") : 0.0), host_(p.host()) {}

  void setup(const domel_control_setup_v1& s) {
    if (s.level_count != 2) throw domel::sdk::ParameterError("needs two levels");
    char line[512];
    std::snprintf(line, sizeof line,
                  "setup: gain %.17g band %.17g interval %.17g grid %u %u %u (%zu cells) inflow cells %zu", gain_,
                  band_, s.interval, s.nx, s.ny, s.nz, s.n_cells, s.n_inflow_cells);
    host_.info(line);
    for (uint32_t l = 0; l < 2; ++l) {
      std::snprintf(line, sizeof line, "setup: level %u '%s' alpha %.17g dt %.17g steps %llu", l, s.levels[l].name,
                    s.levels[l].coarse_grain, s.levels[l].time_step,
                    static_cast<unsigned long long>(s.levels[l].steps_per_interval));
      host_.info(line);
    }
    for (size_t a = 0; a < s.n_inflow_cells; ++a) {
      std::snprintf(line, sizeof line, "setup: inflow cell %u direction %d %d %d", s.inflow_cell[a],
                    s.inflow_direction[3 * a], s.inflow_direction[3 * a + 1], s.inflow_direction[3 * a + 2]);
      host_.info(line);
    }
  }

  void control(domel_control_step_v1& step) {
    ++calls_;
    const domel_cell_grid_v1& g = *step.levels[0]->cells;
    domel_particles_v1& pc = *step.levels[1]->particles;
    const double* u[3] = {g.ux, g.uy, g.uz};
    const double* v[3] = {pc.vx, pc.vy, pc.vz};
    double* f[3] = {pc.fx, pc.fy, pc.fz};
    size_t pushed = 0;
    for (size_t k = 0; k < pc.n; ++k) {
      const uint32_t c = pc.cell[k];
      if (c == UINT32_MAX || g.count[c] == 0) continue;
      bool any = false;
      for (int a = 0; a < 3; ++a) {
        const double dv = u[a][c] - v[a][k];
        if (std::fabs(dv) <= band_) continue;
        f[a][k] += gain_ * pc.mass[k] * dv;
        any = true;
      }
      pushed += any ? 1 : 0;
    }
    host_.info("band call " + std::to_string(calls_) + ": pushed " + std::to_string(pushed));
  }
  void save_state(domel::sdk::StateWriter& w) const { w.put(calls_); }
  void load_state(domel::sdk::StateReader& r) { calls_ = r.get<int>(); }

 private:
  double gain_, band_;
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

class TestLinearDrag {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_FLUID_COUPLER;
  static constexpr const char* kName = "abi_test_linear_drag";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "ABI test fluid coupler: linearised drag m/tau (u - v) and a held force";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "properties": {
    "relaxation_time": { "type": "number", "exclusiveMinimum": 0, "x-unit": "s", "description": "tau: beta = m / tau" },
    "flow": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3, "default": [0, 0, 0], "x-unit": "m/s", "description": "uniform flow u" },
    "held": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3, "default": [0, 0, 0], "x-unit": "m/s^2", "description": "held force per unit mass" },
    "max_interval": { "type": "number", "minimum": 0, "default": 0, "x-unit": "s", "description": "reported stable interval (0: none)" },
    "max_interval_later": { "type": "number", "minimum": 0, "default": 0, "x-unit": "s", "description": "reported instead once an exchange has run (0: max_interval)" }
  },
  "required": ["relaxation_time"],
  "additionalProperties": false
})json";

  explicit TestLinearDrag(const domel::sdk::Params& p)
      : tau_(p.number("relaxation_time")), max_interval_(p.number_or("max_interval", 0.0)),
        max_later_(p.number_or("max_interval_later", 0.0)), host_(p.host()) {
    for (int d = 0; d < 3; ++d) {
      u_[d] = p.json()["flow"][d].get<double>();
      a_[d] = p.json()["held"][d].get<double>();
    }
  }

  void exchange(domel_fluid_exchange_v1& ex) {
    if (!(ex.host_flags & DOMEL_FLUID_HOST_DRAG) || !(ex.host_flags & DOMEL_FLUID_HOST_MEAN_VELOCITY))
      throw std::runtime_error("the host offers no linearised drag or mean velocity");
    ++calls_;
    for (uint32_t L = 0; L < ex.level_count; ++L) {
      domel_particles_v1& p = *ex.levels[L]->particles;
      domel_fluid_drag_v1& drag = *ex.drag[L];
      if (drag.n != p.n) throw std::runtime_error("drag arrays do not match the particles");
      for (size_t k = 0; k < p.n; ++k) {
        drag.beta[k] = p.mass[k] / tau_;
        drag.ux[k] = u_[0], drag.uy[k] = u_[1], drag.uz[k] = u_[2];
        p.fx[k] += p.mass[k] * a_[0], p.fy[k] += p.mass[k] * a_[1], p.fz[k] += p.mass[k] * a_[2];
      }
      if (p.n > 0) {
        char line[160];
        std::snprintf(line, sizeof line, "exchange %d t %.17g level %s v_mean_z %.17g v_z %.17g", calls_, ex.time,
                      ex.levels[L]->name, ex.v_mean[L][2], p.vz[0]);
        host_.debug(line);
      }
    }
  }

  void limits(domel_fluid_limits_v1& out) {
    out.max_interval = calls_ > 0 && max_later_ > 0 ? max_later_ : max_interval_;
    out.limit = "test limit";
    out.solver_iterations = static_cast<uint32_t>(calls_);
  }

  void fields(domel_fluid_fields_v1& out) {
    count_[0] = count_[1] = calls_;
    for (int c = 0; c < 2; ++c)
      for (int d = 0; d < 3; ++d) flow_[3 * c + d] = u_[d];
    static const char* const names[] = {"exchanges", "velocity"};
    static const char* const units[] = {"1", "m/s"};
    static const uint32_t components[] = {1, 3};
    data_[0] = count_;
    data_[1] = flow_;
    out.field_count = 2;
    out.nx = 1, out.ny = 1, out.nz = 2;
    // the fluid's whole domain: it holds every test scenario's particles
    for (int d = 0; d < 3; ++d) out.origin[d] = -1.0, out.spacing[d] = 2.5;
    out.names = names, out.units = units, out.components = components, out.data = data_;
  }

 private:
  double tau_, max_interval_, max_later_;
  double u_[3], a_[3];
  double count_[2] = {0, 0}, flow_[6] = {0, 0, 0, 0, 0, 0};
  const double* data_[2] = {nullptr, nullptr};
  int calls_ = 0;
  domel::sdk::Host host_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("abi_families", "1.0.0", TestController, TestBandController, TestDrag, TestLinearDrag)
