// SPDX-License-Identifier: MIT
// The run's schedules checked against the step they are counted in (issue
// 41): every periodic action given in simulated time is due at macro steps
// (core/cadence.hpp: at most once per macro step), so an interval below one
// macro step cannot be kept and is refused at its pointer; an interval that
// makes more than kManyActions actions in one run (a typo of an exponent,
// most often) is warned about with the count. The list below is every
// schedule a scenario can give in seconds; those in steps (grid samples,
// control intervals, transfers) are integers of at least one step.
#include "scenario/build.hpp"

#include "core/cadence.hpp"
#include "loop/macro_step.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace domel::platform::scenario_detail {

namespace {

/// More actions than this in one run draw a warning.
constexpr double kManyActions = 1e5;

struct Schedule {
  std::string pointer;
  double interval;
  std::string what;  ///< what the interval spaces, for the messages
};

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", s);
  return buf;
}

/// Every schedule the document gives in seconds, with its pointer.
std::vector<Schedule> given_schedules(const json& d) {
  std::vector<Schedule> list;
  auto given = [&](const json* block, const char* key, const std::string& pointer, const char* what) {
    if (const json* v = block ? member(*block, key) : nullptr; v && v->is_number())
      list.push_back({pointer, v->get<double>(), what});
  };
  const json* run = member(d, "run");
  const json* deletions = member(d, "deletion_regions");
  if (deletions && deletions->is_array() && !deletions->empty())  // the checks run only with regions
    given(run, "deletion_interval", "/run/deletion_interval", "deletion-region checks");
  given(run, "checkpoint_interval", "/run/checkpoint_interval", "checkpoints");
  const json* out = member(d, "output");
  given(out, "vtk_interval", "/output/vtk_interval", "particle files");
  given(out, "probe_interval", "/output/probe_interval", "rows of probes.csv");
  given(out ? member(*out, "contacts") : nullptr, "interval", "/output/contacts/interval", "contact files");
  if (const json* grids = out ? member(*out, "grids") : nullptr; grids && grids->is_array())
    for (std::size_t k = 0; k < grids->size(); ++k)
      given(&(*grids)[k], "write_interval", "/output/grids/" + std::to_string(k) + "/write_interval", "grid files");
  if (const json* sds = member(d, "subdomains"); sds && sds->is_array())
    for (std::size_t k = 0; k < sds->size(); ++k)
      if (const json* pours = member((*sds)[k], "pour"); pours && pours->is_array())
        for (std::size_t j = 0; j < pours->size(); ++j)
          given(&(*pours)[j], "interval",
                "/subdomains/" + std::to_string(k) + "/pour/" + std::to_string(j) + "/interval", "pour events");
  if (const json* cs = member(d, "couplings"); cs && cs->is_array())
    for (std::size_t k = 0; k < cs->size(); ++k)
      given(&(*cs)[k], "grid_interval", "/couplings/" + std::to_string(k) + "/grid_interval", "grid files");
  const json* fluid = member(d, "fluid");
  given(fluid, "interval", "/fluid/interval", "fluid exchanges");
  given(fluid, "write_interval", "/fluid/write_interval", "fluid field files");
  return list;
}

/// The fluid's coupling interval against the run: an exchange advances the
/// fluid over an interval, so one longer than the run is refused (issue 45:
/// 0.05 s in a 0.02 s run advanced the fluid past the run's end); where the
/// run is not a whole number of intervals, the last exchange covers what is
/// left (FluidSpec::run_macro_steps), said once.
void check_fluid_interval(Build& b, double macro) {
  const json* fluid = member(b.doc, "fluid");
  const json* v = fluid ? member(*fluid, "interval") : nullptr;
  if (!v || !v->is_number() || !(v->get<double>() > 0) || !(b.sim.duration > 0)) return;
  // as build_fluid rounds it: whole macro steps; counted as doubles first, so
  // that a duration of 1e300 s (refused by build_duration: more macro steps
  // than a run counts; the run-time fuzzer) converts no huge count
  const double n_every = std::max(1.0, std::round(v->get<double>() / macro));
  const double n_total = std::ceil(b.sim.duration / macro - kTimeTolerance);
  if (!(n_total >= 1.0) || !(n_total <= 1e15)) return;
  const double interval = n_every * macro;
  if (n_every > n_total) {
    b.ck.add("/fluid/interval",
             "expected a coupling interval of at most the run's duration, " + seconds(b.sim.duration) +
                 " s (an exchange advances the fluid over a whole interval: it would carry it past the run's end), "
                 "found " + seconds(interval) + " s",
             "give " + seconds(b.sim.duration) + " s or less");
    return;
  }
  const auto every = static_cast<std::uint64_t>(n_every), total = static_cast<std::uint64_t>(n_total);
  if (total % every == 0) return;
  spdlog::info("/fluid/interval: the run's {} s is {:.6g} coupling intervals of {} s: the last exchange advances the "
               "fluid {} s, to the run's end", seconds(b.sim.duration), static_cast<double>(total) / every,
               seconds(interval), seconds(static_cast<double>(total % every) * macro));
}

}  // namespace

void check_schedules(Build& b) {
  const double macro = macro_step_of(b.sim.subdomains);
  if (!(macro > 0)) return;  // no subdomain was built: its own problems are reported
  for (const Schedule& s : given_schedules(b.doc)) {
    if (!(s.interval > 0)) continue;  // 0 switches it off where the schema allows it
    if (const std::string why = schedule_refusal(s.interval, macro, s.what); !why.empty()) {
      b.ck.add(s.pointer, why, "give " + seconds(macro) + " s for one per macro step");
      continue;
    }
    const double count = b.sim.duration / s.interval;
    if (count > kManyActions)
      spdlog::warn("{}: {} s makes {:.3g} {} in a run of {} s (more than {:.0e}); was a larger interval meant?",
                   s.pointer, seconds(s.interval), count, s.what, seconds(b.sim.duration), kManyActions);
  }
  check_fluid_interval(b, macro);
}


}  // namespace domel::platform::scenario_detail
