// SPDX-License-Identifier: MIT
// The builder of the fluid block (build.hpp).
#include "scenario/build.hpp"

#include "fluid/fluid_coupling.hpp"
#include "geometry/region.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace domel::platform::scenario_detail {

/// fluid: the fluid_coupler instance, the levels that share the fluid and
/// the coupling interval in whole macro steps. The FluidCoupling itself is
/// made once the outputs are known (its default write interval).
std::optional<FluidSpec> build_fluid(Build& b) {
  if (!b.doc.contains("fluid")) return std::nullopt;
  const json& fj = b.doc["fluid"];
  Simulation& sim = b.sim;
  FluidSpec spec;
  const std::string model = fj["model"].get<std::string>();
  const RegisteredModel* m = b.registry.find(DOMEL_KIND_FLUID_COUPLER, model);
  if (m == nullptr) return std::nullopt;  // check_models reported it
  std::vector<std::string> names;
  for (const auto& sd : sim.subdomains) names.push_back(sd->name());
  if (fj.contains("subdomains")) {
    const json& list = fj["subdomains"];
    for (std::size_t q = 0; q < list.size(); ++q) {
      const std::string want = list[q].get<std::string>();
      const auto it = std::find(names.begin(), names.end(), want);
      if (it == names.end()) {
        b.ck.add(idx("/fluid/subdomains", q), "unknown subdomain '" + want + "'", suggest(want, names));
        continue;
      }
      const std::size_t k = static_cast<std::size_t>(it - names.begin());
      if (std::find(spec.levels.begin(), spec.levels.end(), k) != spec.levels.end())
        b.ck.add(idx("/fluid/subdomains", q), "subdomain '" + want + "' is listed twice");
      else
        spec.levels.push_back(k);
    }
  } else {
    for (std::size_t k = 0; k < names.size(); ++k) spec.levels.push_back(k);
  }
  const double macro = sim.macro_step();
  const double asked = fj["interval"].get<double>();
  spec.interval_macro = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(asked / macro)));
  spec.interval = static_cast<double>(spec.interval_macro) * macro;
  if (std::abs(spec.interval - asked) > 1e-9 * asked)
    spdlog::info("/fluid/interval: coupling interval {:.6g} s (asked {:.6g} s): {} macro step(s) of {:.4g} s, so "
                 "that every exchange falls on a step of every level",
                 spec.interval, asked, spec.interval_macro, macro);
  spec.write_interval = fj.contains("write_interval") ? fj["write_interval"].get<double>() : -1.0;
  for (int d = 0; d < 3; ++d) spec.gravity[d] = sim.gravity[d];
  try {
    spec.model = std::make_shared<ModelInstance>(*m, plugin_params(fj, DOMEL_KIND_FLUID_COUPLER), "/fluid");
  } catch (const PluginError& e) {
    b.ck.add("/fluid", e.what());
    return std::nullopt;
  }
  // The coupler's limit from its initial state (inlet velocities, grid): an
  // interval above it is refused before anything runs.
  try {
    domel_fluid_limits_v1 lim{};
    if (spec.model->fluid_limits(lim) && lim.max_interval > 0 && spec.interval > lim.max_interval * (1 + 1e-9))
      b.ck.add("/fluid/interval",
               "expected a coupling interval of at most " + fmt_num(lim.max_interval) + " s (" +
                   (lim.limit ? lim.limit : "the coupler's stability limit") + "), found " + fmt_num(spec.interval) +
                   " s",
               "shorten the interval, or let the coupler sub-step its fluid if it can");
  } catch (const PluginError& e) {
    b.ck.add("/fluid", e.what());
  }
  // The coupler's grid (from its fields, when it reports them) must hold
  // where the particles start: every insertion and pour region of its
  // levels, and the walls' box when they enclose the domain.
  try {
    domel_fluid_fields_v1 f{};
    if (spec.model->fluid_fields(f) && f.nx > 0 && f.ny > 0 && f.nz > 0) {
      const double glo[3] = {f.origin[0], f.origin[1], f.origin[2]};
      const double ghi[3] = {f.origin[0] + f.nx * f.spacing[0], f.origin[1] + f.ny * f.spacing[1],
                             f.origin[2] + f.nz * f.spacing[2]};
      auto check = [&](const double lo[3], const double hi[3], const std::string& what) {
        for (int a = 0; a < 3; ++a)
          if (lo[a] < glo[a] - 1e-12 || hi[a] > ghi[a] + 1e-12) {
            b.ck.add("/fluid", "the fluid grid [" + fmt_num(glo[a]) + ", " + fmt_num(ghi[a]) + "] m along " +
                                   std::string(1, "xyz"[a]) + " does not cover " + what + " ([" + fmt_num(lo[a]) +
                                   ", " + fmt_num(hi[a]) + "] m)",
                     "enlarge the coupler's grid to the particles' whole domain");
            return;
          }
      };
      for (std::size_t k : spec.levels) {
        const json& sd = b.doc["subdomains"][k];
        const std::string base = idx("/subdomains", k);
        double lo[3], hi[3];
        if (sd.contains("insert"))
          for (std::size_t q = 0; q < sd["insert"].size(); ++q)
            if (sd["insert"][q].contains("region")) {
              region_box(make_region(sd["insert"][q]["region"]), lo, hi);
              check(lo, hi, "the insertion region " + idx(base + "/insert", q));
            }
        if (sd.contains("pour"))
          for (std::size_t q = 0; q < sd["pour"].size(); ++q) {
            region_box(make_region(sd["pour"][q]["insert"]["region"]), lo, hi);
            check(lo, hi, "the pour region " + idx(base + "/pour", q));
          }
      }
      bool enclosed = false;
      for (const auto& w : sim.walls)
        enclosed = enclosed || w.shape == WallPrimitive::Shape::cylinder_inside ||
                   w.shape == WallPrimitive::Shape::cone_inside || w.shape == WallPrimitive::Shape::mesh;
      double lo[3], hi[3];
      const bool deletions = b.doc.contains("deletion_regions") && !b.doc["deletion_regions"].empty();
      if (enclosed && !deletions && domain_bounds(b, lo, hi))
        check(lo, hi, "the walls' domain");
    }
  } catch (const PluginError& e) {
    b.ck.add("/fluid", e.what());
  }
  spec.one_level_per_call = b.registry.libraries()[m->library].abi_minor < 2;
  spec.used = {{"model", model},
               {"version", m->version},
               {"library", b.registry.libraries()[m->library].name},
               {"library_version", b.registry.libraries()[m->library].version}};
  return spec;
}

}  // namespace domel::platform::scenario_detail
