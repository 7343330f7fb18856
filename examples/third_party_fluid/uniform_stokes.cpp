// SPDX-License-Identifier: MIT
//
// Fluid coupler "uniform_stokes": a steady, uniform flow of a viscous fluid
// acting on the particles through Stokes drag and buoyancy, one way (the
// particles do not change the flow). The smallest complete fluid_coupler: a
// third-party plugin built against the INSTALLED domel SDK only
// (CMakeLists.txt, README.md; docs/sdk-guide.md, "Fluid couplers").
//
// Per particle of radius r (a parcel of ratio alpha: r = alpha r_0) and
// velocity v, in a fluid of viscosity mu, density rho_f and velocity u:
//   drag      F_d = beta (u - v),  beta = 3 pi mu d            (Stokes 1851)
//   buoyancy  F_b = -V rho_f g                                 (the pressure
//             gradient of the fluid at rest under gravity, -V grad p with
//             grad p = rho_f g; it holds for a uniform flow too)
// Coarse-grain scaling ("coarse_grain_scaling": true, the default): a parcel
// of diameter d = alpha d_0 stands for alpha^3 originals that each feel the
// Stokes drag of their own diameter d_0, so
//   beta = alpha^3 3 pi mu (d / alpha) = alpha^2 3 pi mu d
// (Sakai & Koshizuka 2009; docs/physics.md §6.3), and the parcel falls at
// the original particle's terminal velocity. With false, the parcel feels
// the drag of one sphere of its own diameter and falls alpha^2 times faster.
// The drag is handed back linearised (domel_fluid_drag_v1: beta and u), so
// domel refreshes it with the particle's velocity at every step; the
// buoyancy is a held force. Valid for particle Reynolds numbers
// rho_f |u - v| d_0 / mu well below 1: the coupler warns, once, when a
// particle exceeds 1.
// Fields: with a "grid", the fluid velocity and the hydrostatic pressure
// relative to the grid's top centre on its cells, for ParaView.
#include <domel/sdk/plugin.hpp>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

class UniformStokes {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_FLUID_COUPLER;
  static constexpr const char* kName = "uniform_stokes";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "steady uniform flow, Stokes drag and buoyancy, one way (SDK example)";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "A steady uniform flow acting on the particles by Stokes drag 3 pi mu d (u - v) and buoyancy -V rho_f g, one way.",
  "properties": {
    "viscosity": { "type": "number", "exclusiveMinimum": 0, "x-unit": "Pa s", "description": "dynamic viscosity mu of the fluid" },
    "density": { "type": "number", "minimum": 0, "default": 0, "x-unit": "kg/m^3", "description": "fluid density rho_f (buoyancy; the Reynolds-number check)" },
    "velocity": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3, "default": [0, 0, 0], "x-unit": "m/s", "description": "the uniform fluid velocity u" },
    "coarse_grain_scaling": { "type": "boolean", "default": true, "description": "a parcel of ratio alpha feels alpha^3 times the drag of one original particle of diameter d/alpha (Sakai & Koshizuka 2009); false: the drag of one sphere of the parcel's diameter" },
    "grid": { "type": "object", "description": "a box on which the fields are reported for output",
              "properties": { "min": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3, "x-unit": "m" },
                              "max": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3, "x-unit": "m" },
                              "cells": { "type": "array", "items": { "type": "integer", "minimum": 1 }, "minItems": 3, "maxItems": 3 } },
              "required": ["min", "max", "cells"], "additionalProperties": false }
  },
  "required": ["viscosity"],
  "additionalProperties": false
})json";

  explicit UniformStokes(const domel::sdk::Params& p)
      : mu_(p.number("viscosity")), rho_(p.number_or("density", 0.0)),
        scaling_(p.boolean_or("coarse_grain_scaling", true)), host_(p.host()) {
    if (p.has("velocity"))
      for (int d = 0; d < 3; ++d) u_[d] = p.json()["velocity"][d].get<double>();
    if (p.json().contains("grid")) {
      const auto& g = p.json()["grid"];
      for (int d = 0; d < 3; ++d) {
        const double lo = g["min"][d].get<double>(), hi = g["max"][d].get<double>();
        n_[d] = g["cells"][d].get<uint32_t>();
        if (!(hi > lo)) throw domel::sdk::ParameterError("grid: max must exceed min along every axis");
        origin_[d] = lo;
        spacing_[d] = (hi - lo) / n_[d];
      }
    }
  }

  void exchange(domel_fluid_exchange_v1& ex) {
    // The ABI 2.2 members (several levels, the linearised drag, gravity) lie
    // beyond the struct_size of an older host's exchange: then one level, a
    // held drag, and no gravity given.
    const bool v22 = ex.struct_size >= offsetof(domel_fluid_exchange_v1, v_mean) + sizeof(ex.v_mean);
    const bool linearised = v22 && (ex.host_flags & DOMEL_FLUID_HOST_DRAG) != 0;
    const uint32_t levels = v22 ? ex.level_count : 1;
    const double zero[3] = {0, 0, 0};
    const double* gravity = v22 ? ex.gravity : zero;
    for (uint32_t L = 0; L < levels; ++L) {
      domel_level_v1& level = v22 ? *ex.levels[L] : *ex.level;
      domel_particles_v1& p = *level.particles;
      const double alpha = level.coarse_grain;
      for (size_t k = 0; k < p.n; ++k) {
        const double r = p.radius[k];
        const double d0 = 2 * r / alpha;  // the original particle's diameter
        const double beta = scaling_ ? alpha * alpha * alpha * 3 * M_PI * mu_ * d0 : 3 * M_PI * mu_ * 2 * r;
        const double volume = 4.0 / 3.0 * M_PI * r * r * r;
        if (linearised) {
          domel_fluid_drag_v1& drag = *ex.drag[L];
          drag.beta[k] = beta;
          drag.ux[k] = u_[0], drag.uy[k] = u_[1], drag.uz[k] = u_[2];
        } else {  // held over the interval with the velocity at the exchange
          p.fx[k] += beta * (u_[0] - p.vx[k]);
          p.fy[k] += beta * (u_[1] - p.vy[k]);
          p.fz[k] += beta * (u_[2] - p.vz[k]);
        }
        p.fx[k] -= volume * rho_ * gravity[0];
        p.fy[k] -= volume * rho_ * gravity[1];
        p.fz[k] -= volume * rho_ * gravity[2];
        const double slip = std::hypot(u_[0] - p.vx[k], u_[1] - p.vy[k], u_[2] - p.vz[k]);
        const double re = rho_ * slip * (scaling_ ? d0 : 2 * r) / mu_;
        if (re > 1 && !warned_) {
          warned_ = true;
          host_.warn("particle " + std::to_string(p.id[k]) + " of '" + level.name + "' has Reynolds number " +
                        std::to_string(re) + " > 1: outside Stokes drag's range (the drag is underestimated)");
        }
      }
    }
    for (int d = 0; d < 3; ++d) g_[d] = gravity[d];
  }

  // Checkpoints (ABI 2.3): what the next call depends on that the
  // parameters do not give: the gravity learnt at the last exchange (the
  // fields use it) and whether the Reynolds warning was given.
  void save_state(domel::sdk::StateWriter& w) const {
    for (double g : g_) w.put(g);
    w.put(static_cast<unsigned char>(warned_));
  }
  void load_state(domel::sdk::StateReader& r) {
    for (double& g : g_) g = r.get<double>();
    warned_ = r.get<unsigned char>() != 0;
  }

  void fields(domel_fluid_fields_v1& out) {
    const size_t cells = static_cast<size_t>(n_[0]) * n_[1] * n_[2];
    velocity_.assign(3 * cells, 0.0);
    pressure_.assign(cells, 0.0);
    for (uint32_t iz = 0; iz < n_[2]; ++iz)
      for (uint32_t iy = 0; iy < n_[1]; ++iy)
        for (uint32_t ix = 0; ix < n_[0]; ++ix) {
          const size_t c = ix + static_cast<size_t>(n_[0]) * (iy + static_cast<size_t>(n_[1]) * iz);
          const double x[3] = {origin_[0] + (ix + 0.5) * spacing_[0], origin_[1] + (iy + 0.5) * spacing_[1],
                               origin_[2] + (iz + 0.5) * spacing_[2]};
          const double top[3] = {origin_[0] + 0.5 * n_[0] * spacing_[0], origin_[1] + 0.5 * n_[1] * spacing_[1],
                                 origin_[2] + n_[2] * spacing_[2]};
          for (int d = 0; d < 3; ++d) {
            velocity_[3 * c + d] = u_[d];
            pressure_[c] += rho_ * g_[d] * (x[d] - top[d]);
          }
        }
    static const char* const names[] = {"velocity", "pressure"};
    static const char* const units[] = {"m/s", "Pa"};
    static const uint32_t components[] = {3, 1};
    data_[0] = velocity_.data();
    data_[1] = pressure_.data();
    out.field_count = cells ? 2 : 0;
    out.nx = n_[0], out.ny = n_[1], out.nz = n_[2];
    for (int d = 0; d < 3; ++d) out.origin[d] = origin_[d], out.spacing[d] = spacing_[d];
    out.names = names;
    out.units = units;
    out.components = components;
    out.data = data_;
  }

  void limits(domel_fluid_limits_v1& out) {
    out.max_interval = 0;  // a steady, uniform flow: any interval
    out.limit = "none (steady uniform flow)";
  }

 private:
  double mu_, rho_;
  bool scaling_;
  double u_[3] = {0, 0, 0};
  double g_[3] = {0, 0, 0};
  uint32_t n_[3] = {0, 0, 0};
  double origin_[3] = {0, 0, 0}, spacing_[3] = {0, 0, 0};
  std::vector<double> velocity_, pressure_;
  const double* data_[2] = {nullptr, nullptr};
  bool warned_ = false;
  domel::sdk::Host host_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("third_party_fluid", "1.0.0", UniformStokes)
