// SPDX-License-Identifier: MIT
// FluidCoupling: the exchange with a fluid_coupler plugin, the per-step fluid
// force of each level (its post_force hook) and the output of the coupler's
// fields.
#include "fluid/fluid_coupling.hpp"

#include "core/abi_views.hpp"
#include "core/archive.hpp"
#include "core/error.hpp"
#include "core/particle_store.hpp"
#include "io/cell_grid_output.hpp"
#include "loop/ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace domel::platform {

FluidCoupling::FluidCoupling(FluidSpec spec, std::vector<std::unique_ptr<Subdomain>>& subdomains)
    : spec_(std::move(spec)), net_force_(spec_.levels.size(), std::array<double, 3>{0, 0, 0}) {
  for (std::size_t L = 0; L < spec_.levels.size(); ++L) {
    Subdomain& sd = *subdomains[spec_.levels[L]];
    const std::size_t a = sd.store().add_aux(kArrays);
    aux_.push_back(a);
    names_.push_back(sd.name());
    // held + beta (u - v) with this step's velocity; the velocity integral
    // for the next exchange's mean velocity (midpoint rule over the step)
    sd.add_hook(Phase::post_force, {"fluid force", [a](StepContext& c) {
                                      ParticleStore& s = c.store;
                                      auto& x = s.aux;
                                      const double* beta = x[a + kBeta].data();
                                      const double *ux = x[a + kUx].data(), *uy = x[a + kUy].data(),
                                                   *uz = x[a + kUz].data();
                                      const double *hx = x[a + kFx].data(), *hy = x[a + kFy].data(),
                                                   *hz = x[a + kFz].data();
                                      double *sx = x[a + kSx].data(), *sy = x[a + kSy].data(),
                                             *sz = x[a + kSz].data(), *st = x[a + kSt].data();
                                      double *lx = x[a + kLx].data(), *ly = x[a + kLy].data(),
                                             *lz = x[a + kLz].data();
                                      const double dt = c.dt;
                                      for (std::size_t k = 0; k < s.size(); ++k) {
                                        const double vx = s.vx[k], vy = s.vy[k], vz = s.vz[k];
                                        lx[k] = hx[k] + beta[k] * (ux[k] - vx);
                                        ly[k] = hy[k] + beta[k] * (uy[k] - vy);
                                        lz[k] = hz[k] + beta[k] * (uz[k] - vz);
                                        s.fx[k] += lx[k];
                                        s.fy[k] += ly[k];
                                        s.fz[k] += lz[k];
                                        sx[k] += vx * dt;
                                        sy[k] += vy * dt;
                                        sz[k] += vz * dt;
                                        st[k] += dt;
                                      }
                                    }});
  }
}

FluidCoupling::~FluidCoupling() = default;

void FluidCoupling::exchange(double t, std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  const std::size_t nl = spec_.levels.size();
  std::vector<domel_particles_v1> particles(nl);
  std::vector<domel_level_v1> levels(nl);
  std::vector<domel_fluid_drag_v1> drags(nl);
  std::vector<std::vector<double>> v_mean(nl);
  std::vector<domel_level_v1*> level_ptrs(nl);
  std::vector<domel_fluid_drag_v1*> drag_ptrs(nl);
  std::vector<const double*> mean_ptrs(nl);
  // spread over ranks: the coupler sees every rank's particles, gathered
  std::vector<GatheredParticles> gathered(nl);
  for (std::size_t L = 0; L < nl; ++L) {
    Subdomain& sd = *subdomains[spec_.levels[L]];
    gathered[L] = ranks_->gather(sd, true);
    ParticleStore& s = *gathered[L];
    auto& x = s.aux;
    const std::size_t a = aux_[L], n = s.size();
    for (std::size_t q = kBeta; q <= kFz; ++q) std::fill(x[a + q].begin(), x[a + q].end(), 0.0);
    std::vector<double>& vm = v_mean[L];
    vm.resize(3 * n);
    for (std::size_t k = 0; k < n; ++k) {
      const double T = x[a + kSt][k];
      vm[3 * k] = T > 0 ? x[a + kSx][k] / T : s.vx[k];
      vm[3 * k + 1] = T > 0 ? x[a + kSy][k] / T : s.vy[k];
      vm[3 * k + 2] = T > 0 ? x[a + kSz][k] / T : s.vz[k];
    }
    for (std::size_t q = kSx; q <= kSt; ++q) std::fill(x[a + q].begin(), x[a + q].end(), 0.0);
    domel_particles_v1& p = particles[L];
    p = particles_view(s, nullptr, x[a + kFx].data(), x[a + kFy].data(), x[a + kFz].data());
    levels[L] = domel_level_v1{sizeof(domel_level_v1), 0, sd.name().c_str(), sd.coarse_grain(), nullptr, &p};
    drags[L] = domel_fluid_drag_v1{sizeof(domel_fluid_drag_v1), 0, n, x[a + kBeta].data(), x[a + kUx].data(),
                                   x[a + kUy].data(), x[a + kUz].data()};
    level_ptrs[L] = &levels[L];
    drag_ptrs[L] = &drags[L];
    mean_ptrs[L] = vm.data();
  }
  domel_fluid_exchange_v1 ex{};
  ex.struct_size = sizeof ex;
  ex.time = t;
  ex.interval = spec_.interval;
  if (spec_.run_macro_steps > 0) {  // the last exchange ends with the run (scenario/build_schedules.cpp)
    const double macro = spec_.interval / static_cast<double>(spec_.interval_macro);
    const auto index = static_cast<std::uint64_t>(std::llround(t / macro));
    if (index < spec_.run_macro_steps && spec_.run_macro_steps - index < spec_.interval_macro)
      ex.interval = static_cast<double>(spec_.run_macro_steps - index) * macro;
  }
  ex.level = level_ptrs[0];
  for (int d = 0; d < 3; ++d) ex.gravity[d] = spec_.gravity[d];
  ex.level_count = static_cast<uint32_t>(nl);
  ex.host_flags = DOMEL_FLUID_HOST_DRAG | DOMEL_FLUID_HOST_MEAN_VELOCITY;
  ex.levels = level_ptrs.data();
  ex.drag = drag_ptrs.data();
  ex.v_mean = mean_ptrs.data();
  const auto t0 = std::chrono::steady_clock::now();
  try {
    if (spec_.one_level_per_call) {
      for (std::size_t L = 0; L < nl; ++L) {
        domel_fluid_exchange_v1 one = ex;
        one.level = level_ptrs[L];
        one.level_count = 1;
        one.levels = &level_ptrs[L];
        one.drag = &drag_ptrs[L];
        one.v_mean = &mean_ptrs[L];
        spec_.model->exchange(one);
      }
    } else {
      spec_.model->exchange(ex);
    }
    domel_fluid_limits_v1 lim{};
    if (spec_.model->fluid_limits(lim)) {
      has_limits_ = true;
      last_limits_ = lim;
      last_limit_ = lim.limit ? lim.limit : "";
      if (lim.has_books) {
        has_books_ = true;
        max_momentum_residual_ = std::max(max_momentum_residual_, lim.momentum_residual);
        for (int d = 0; d < 3; ++d) wall_shear_[d] = lim.wall_shear[d];
      }
    }
  } catch (const PluginError& e) {
    std::ostringstream os;
    os << spec_.where << ": the fluid coupler failed at t = " << t << " s: " << e.what();
    throw RuntimeError(os.str());
  }
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++exchanges_;
  if (has_limits_ && last_limits_.max_interval > 0 && spec_.interval > last_limits_.max_interval * (1 + 1e-9)) {
    std::ostringstream os;
    os << spec_.where << "/interval: the coupling interval " << spec_.interval
       << " s is longer than the fluid's stable interval " << last_limits_.max_interval << " s at t = " << t
       << " s (" << (last_limit_.empty() ? std::string("the coupler's stability limit") : last_limit_)
       << "); shorten the interval";
    throw RuntimeError(os.str());
  }
  // The refreshed drag is an explicit relaxation v <- v + dt beta/m (u - v)
  // per step: monotone (and stable) for dt beta/m < 1.
  for (std::size_t L = 0; L < nl; ++L) {
    Subdomain& sd = *subdomains[spec_.levels[L]];
    ParticleStore& s = sd.store();
    auto& x = s.aux;
    const std::size_t a = aux_[L];
    const double dt = sd.time_step();
    const std::size_t n = sd.owned();
    // this rank's particles take their drag from the whole set (on ranks a
    // gathered copy in id order; on one process the store, where each
    // particle already has its own)
    const ParticleStore& all = *gathered[L];
    const std::vector<std::size_t> at = ranks_->where_in_gathered(sd, all, spec_.where);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t g = at[k];
      for (std::size_t q = kBeta; q <= kFz; ++q) x[a + q][k] = all.aux[a + q][g];
      for (std::size_t q = kSx; q <= kSt; ++q) x[a + q][k] = 0.0;
    }
    std::array<double, 3> net{0, 0, 0};
    for (std::size_t k = 0; k < n; ++k) {
      const double beta = x[a + kBeta][k];
      if (!(beta >= 0) || !std::isfinite(beta)) {
        std::ostringstream os;
        os << spec_.where << ": the fluid coupler gave particle " << s.id[k] << " of subdomain '" << sd.name()
           << "' the drag coefficient " << beta << " kg/s at t = " << t << " s; expected a finite value >= 0";
        throw RuntimeError(os.str());
      }
      if (!s.fixed(k) && beta * dt * s.inv_mass[k] >= 1.0) {
        std::ostringstream os;
        os << spec_.where << ": the drag relaxation time m/beta = " << s.mass[k] / beta << " s of particle "
           << s.id[k] << " in subdomain '" << sd.name() << "' is not longer than the subdomain's time step " << dt
           << " s at t = " << t << " s; the drag refreshed every step is stable only for dt < m/beta: "
           << "shorten the time step";
        throw RuntimeError(os.str());
      }
      const double f[3] = {x[a + kFx][k] + beta * (x[a + kUx][k] - s.vx[k]),
                           x[a + kFy][k] + beta * (x[a + kUy][k] - s.vy[k]),
                           x[a + kFz][k] + beta * (x[a + kUz][k] - s.vz[k])};
      // the force the next first half kick uses: the new fluid force replaces the last one
      s.fx[k] += f[0] - x[a + kLx][k];
      s.fy[k] += f[1] - x[a + kLy][k];
      s.fz[k] += f[2] - x[a + kLz][k];
      x[a + kLx][k] = f[0], x[a + kLy][k] = f[1], x[a + kLz][k] = f[2];
      for (int d = 0; d < 3; ++d) net[d] += f[d];
    }
    const std::vector<double> total = ranks_->sum_in_rank_order({net[0], net[1], net[2]});
    net = {total[0], total[1], total[2]};
    net_force_[L] = net;
  }
}

void FluidCoupling::write_fields(std::uint64_t tick, double t, bool final, const std::filesystem::path& out) {
  if (spec_.write_interval <= 0) return;
  if (!final && !fields_.due(tick)) return;
  fields_.advance(tick);
  domel_fluid_fields_v1 f{};
  try {
    if (!spec_.model->fluid_fields(f)) return;
  } catch (const PluginError& e) {
    std::ostringstream os;
    os << spec_.where << ": the fluid coupler's fields failed at t = " << t << " s: " << e.what();
    throw RuntimeError(os.str());
  }
  if (ranks_->rank() != 0) return;  // every rank asked the coupler alike (its state); rank 0 writes
  if (!fields_out_) fields_out_ = std::make_unique<io::FieldImageSeries>(out, "fluid");
  io::FieldImage image;
  image.cells = {f.nx, f.ny, f.nz};
  for (int d = 0; d < 3; ++d) {
    image.origin[d] = f.origin[d];
    image.spacing[d] = f.spacing[d];
  }
  for (uint32_t k = 0; k < f.field_count; ++k) {
    if (f.names == nullptr || f.names[k] == nullptr || f.data == nullptr || f.data[k] == nullptr ||
        f.components == nullptr || (f.components[k] != 1 && f.components[k] != 3))
      throw RuntimeError(spec_.where + ": the fluid coupler's field " + std::to_string(k) +
                         " lacks a name or data, or has components other than 1 or 3");
    image.fields.push_back({f.names[k], static_cast<int>(f.components[k]), f.data[k]});
  }
  fields_out_->write(t, image);
}

void FluidCoupling::fields(CheckpointFields& f, const std::filesystem::path& out) {
  const bool load = f.loading();
  std::string state;
  if (!load) {
    const auto bytes = spec_.model->save_state();
    state.assign(bytes.begin(), bytes.end());
  }
  f("coupler_state", state);
  if (load) {
    try {
      spec_.model->load_state(std::vector<unsigned char>(state.begin(), state.end()));
    } catch (const PluginError& e) {
      f.reader().fail(f.prefix() + "coupler_state", std::string("holds a state the fluid coupler refuses: ") + e.what());
    }
  }
  std::uint64_t levels = spec_.levels.size(), fields_written = fields_.index(), iterations = last_limits_.solver_iterations;
  f("levels", levels);
  if (load && levels != spec_.levels.size())
    f.reader().fail(f.prefix() + "levels", "does not hold the state of a fluid shared by " +
                                               std::to_string(spec_.levels.size()) + " level(s)");
  f("exchanges", exchanges_);
  f("has_limits", has_limits_);
  f("solver_iterations", iterations);
  f("fields_written", fields_written);
  f("seconds", seconds_);
  f("max_interval", last_limits_.max_interval);
  f("solver_residual", last_limits_.solver_residual);
  std::vector<double> net;
  for (const auto& v : net_force_) net.insert(net.end(), v.begin(), v.end());
  f("net_force", net);
  f("limit", last_limit_);
  std::vector<double> times = fields_out_ ? fields_out_->frame_times() : std::vector<double>{};
  f("field_times", times);
  if (!load) return;
  if (net.size() != 3 * net_force_.size()) f.reader().fail(f.prefix() + "net_force", "holds another number of levels");
  for (std::size_t L = 0; L < net_force_.size(); ++L)
    for (int d = 0; d < 3; ++d) net_force_[L][d] = net[3 * L + d];
  last_limits_.solver_iterations = static_cast<uint32_t>(iterations);
  fields_.resume(fields_written);
  if (!times.empty() && ranks_->rank() == 0) {  // rank 0 writes the fields
    fields_out_ = std::make_unique<io::FieldImageSeries>(out, "fluid");
    fields_out_->resume(times);
  }
}

void FluidCoupling::save(ArchiveWriter& w, const std::string& p) {
  save_fields(w, p, [&](CheckpointFields& f) { fields(f, {}); });
}

void FluidCoupling::load(const ArchiveReader& r, const std::string& p, const std::filesystem::path& out) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f, out); });
}

nlohmann::json FluidCoupling::summary() const {
  nlohmann::json levels = nlohmann::json::array();
  for (std::size_t L = 0; L < spec_.levels.size(); ++L)
    levels.push_back({{"subdomain", names_[L]},
                      {"net_fluid_force_N", {net_force_[L][0], net_force_[L][1], net_force_[L][2]}}});
  nlohmann::json j = {{"model", spec_.used},
                      {"interval_s", spec_.interval},
                      {"exchanges", exchanges_},
                      {"coupler_seconds", seconds_},
                      {"coupler_seconds_per_exchange", exchanges_ ? seconds_ / static_cast<double>(exchanges_) : 0.0},
                      {"levels", levels}};
  if (has_limits_)
    j["limits"] = {{"max_interval_s", last_limits_.max_interval},
                   {"limit", last_limit_},
                   {"solver_iterations", last_limits_.solver_iterations},
                   {"solver_residual", last_limits_.solver_residual}};
  if (has_books_) {
    j["momentum_residual"] = max_momentum_residual_;
    j["wall_shear_N"] = {wall_shear_[0], wall_shear_[1], wall_shear_[2]};
  }
  if (fields_out_) j["fields"] = "fluid.pvd";
  return j;
}

void FluidCoupling::setup(RunContext& ctx) {
  exchanges_due_ = Cadence::in_ticks(spec_.interval_macro);
  fields_ = Cadence::in_time(spec_.write_interval, 0.0, ctx.macro);
}

void FluidCoupling::before_macro(RunContext& ctx, const MacroStep& step) {
  if (exchanges_due_.on(step.index)) exchange(step.t, ctx.subdomains);
}

void FluidCoupling::output(RunContext& ctx, const MacroStep& step) {
  if (!step.last) write_fields(step.index, step.t, false, ctx.out);
}

void FluidCoupling::finish(RunContext& ctx, nlohmann::json& out) {
  write_fields(ctx.end_index, ctx.end_time, true, ctx.out);
  out["fluid"] = summary();
  if (out["fluid"].contains("fields")) out["outputs"]["fluid"] = "fluid.pvd";
}

}  // namespace domel::platform
