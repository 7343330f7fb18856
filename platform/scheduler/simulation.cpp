// SPDX-License-Identifier: MIT
// The run loop: multi-rate stepping of subdomains, outputs and progress.
// Longer than ~600 lines because run() is one scope on purpose: its output
// writers, schedules and samplers are locals that its lambdas share, and
// the order of their calls within a macro step is the run's contract.
#include "scheduler/simulation.hpp"

#include <sys/resource.h>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "geometry/region.hpp"
#include "io/atomic_file.hpp"
#include "io/cell_grid_output.hpp"
#include "io/csv_series.hpp"
#include "io/output_folder.hpp"
#include "io/particle_state.hpp"
#include "io/contact_writer.hpp"
#include "io/vtk_writer.hpp"
#include "io/wall_surfaces.hpp"
#include "scheduler/checkpoint.hpp"
#include "scheduler/gathered_contacts.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <optional>
#include <ctime>
#include <unistd.h>

namespace domel::platform {

double Simulation::macro_step() const { return macro_step_of(subdomains); }

namespace {

/// The per-subdomain columns of probes.csv, "<subdomain>.<name>", in this
/// order: one table gives both the header and the values of a row.
struct ProbeColumn {
  const char* name;
  const char* unit;  ///< SI, "1" for counts and ratios
  double (*value)(const SubdomainStats&);
};
const ProbeColumn kProbeColumns[] = {
    {"particles", "1", [](const SubdomainStats& s) { return static_cast<double>(s.particles); }},
    {"ke_translational", "J", [](const SubdomainStats& s) { return s.kinetic_translational; }},
    {"ke_rotational", "J", [](const SubdomainStats& s) { return s.kinetic_rotational; }},
    {"mean_angular_speed", "rad/s", [](const SubdomainStats& s) { return s.mean_angular_speed; }},
    {"median_angular_speed", "rad/s", [](const SubdomainStats& s) { return s.median_angular_speed; }},
    {"trimmed_mean_angular_speed", "rad/s", [](const SubdomainStats& s) { return s.trimmed_mean_angular_speed; }},
    {"max_overlap_ratio", "1", [](const SubdomainStats& s) { return s.max_overlap_ratio; }},
    {"contacts", "1", [](const SubdomainStats& s) { return static_cast<double>(s.contacts); }},
    {"wall_contacts", "1", [](const SubdomainStats& s) { return static_cast<double>(s.wall_contacts); }},
};

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.0f s", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%.0f min %02.0f s", std::floor(s / 60), std::fmod(s, 60));
  else std::snprintf(buf, sizeof buf, "%.0f h %02.0f min", std::floor(s / 3600), std::fmod(s / 60, 60));
  return buf;
}

std::string iso_time_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

/// output.region_mass: kilograms and count of the particles inside the
/// region, and (when com is given) their centre of mass; subdomain d's
/// particles are store_of(d) (its store, or its particles gathered from the ranks).
template <class StoreOf>
std::pair<double, std::size_t> mass_in_region(const std::vector<std::unique_ptr<Subdomain>>& subdomains,
                                              StoreOf&& store_of, const RegionMassProbe& rm,
                                              double* com = nullptr) {
  double kg = 0;
  std::size_t n = 0;
  double mx = 0, my = 0, mz = 0;
  const double v2max = rm.max_speed ? *rm.max_speed * *rm.max_speed : 0.0;
  for (std::size_t d = 0; d < subdomains.size(); ++d) {
    if (rm.subdomain != kAllSubdomains && rm.subdomain != d) continue;
    const ParticleStore& s = store_of(d);
    // the material's local index in this subdomain (none: it has no such particles)
    int local = -1;
    if (rm.material) {
      const auto& mats = subdomains[d]->materials();
      const auto it = std::find(mats.begin(), mats.end(), *rm.material);
      if (it == mats.end()) continue;
      local = static_cast<int>(it - mats.begin());
    }
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (local >= 0 && s.material[k] != local) continue;
      if (!region_contains(rm.region, s.x[k], s.y[k], s.z[k])) continue;
      if (rm.max_speed && s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k] + s.vz[k] * s.vz[k] >= v2max) continue;
      kg += s.mass[k];
      mx += s.mass[k] * s.x[k];
      my += s.mass[k] * s.y[k];
      mz += s.mass[k] * s.z[k];
      ++n;
    }
  }
  if (com) {
    com[0] = n ? mx / kg : std::nan("");
    com[1] = n ? my / kg : std::nan("");
    com[2] = n ? mz / kg : std::nan("");
  }
  return {kg, n};
}

}  // namespace

std::string probe_column_unit(const std::string& column) {
  if (column == "time") return "s";
  const auto dot = column.rfind('.');
  const std::string name = dot == std::string::npos ? column : column.substr(dot + 1);
  for (const auto& c : kProbeColumns)
    if (name == c.name) return c.unit;
  // the region-mass, repose, deletion and plane columns (Simulation::run, ParticleFlow::columns)
  if (name == "repose_angle_deg") return "deg";
  if (name == "mass_kg" || name == "removed_kg") return "kg";
  if (name == "rate_kg_s") return "kg/s";
  if (name == "force_x" || name == "force_y" || name == "force_z") return "N";  // output.wall_loads
  if (name == "torque") return "N m";
  if (name == "com_x" || name == "com_y" || name == "com_z") return "m";  // output.region_mass
  if (name == "servo_force") return "N";  // walls[].motion[].servo
  if (name == "servo_travel") return "m";
  return "";
}

std::string Simulation::why_no_checkpoint() const {
  const ModelInstance* stateless = nullptr;
  for (const auto& c : couplings)
    for (const ControllerSetup* cs : {&c->spec().stress, &c->spec().velocity})
      if (!stateless && cs->enabled && !cs->model->has_state()) stateless = cs->model.get();
  if (!stateless && fluid && !fluid->spec().model->has_state()) stateless = fluid->spec().model.get();
  if (!stateless) return "";
  return stateless->context() + " cannot save its state (its library lacks ABI 2.3's save_state and load_state, "
                                "docs/sdk-guide.md), so this run cannot be checkpointed";
}

RunResult Simulation::run(const RunOptions& options, const PluginRegistry& registry) {
  RunResult result;
  // Spread over ranks: every rank runs this function on the same scenario;
  // rank 0 alone writes files and reports (scheduler/run_ranks.hpp).
  RunRanks* const ranks = options.ranks && options.ranks->size() > 1 ? options.ranks : nullptr;
  const bool writer = ranks == nullptr || ranks->rank() == 0;
  // Levels on rank groups (subdomains[].rank_share), checked before anything is written.
  std::vector<RankGroup> groups;
  if (ranks && !rank_shares.empty()) {
    if (static_cast<std::size_t>(ranks->size()) < subdomains.size())
      throw ConfigError({Diagnostic{scenario_file.string(), "/subdomains/0/rank_share",
                                    "the subdomains run on rank groups of their own (rank_share), which needs a rank "
                                    "for each of the " + std::to_string(subdomains.size()) + " subdomains; mpirun "
                                    "started " + std::to_string(ranks->size()),
                                    "run on at least " + std::to_string(subdomains.size()) + " ranks (mpirun -np " +
                                        std::to_string(subdomains.size()) + "), or remove every rank_share"}});
    groups = rank_groups(rank_shares, ranks->size());
  }
  if (!ranks && !rank_shares.empty())
    spdlog::info("one process: the subdomains' rank_share apply to runs under mpirun only");
  const std::filesystem::path out = options.output_directory.empty() ? output_directory : options.output_directory;
  result.output_directory = out;
  // A restart is checked against this scenario before anything is written.
  const std::string why_not = why_no_checkpoint();
  const bool checkpoints_possible = why_not.empty();
  std::optional<OpenedCheckpoint> ck;
  if (!options.restart.empty()) {
    if (!checkpoints_possible)
      throw ConfigError({Diagnostic{scenario_file.string(), "", "cannot restart: " + why_not, ""}});
    ck = open_checkpoint(options.restart, *this);
    for (const auto& c : ck->allowed_changes) spdlog::info("restart: scenario changed, allowed: {}", c);
  }
  if (checkpoint_interval > 0 && !checkpoints_possible)
    throw ConfigError({Diagnostic{scenario_file.string(), "/run/checkpoint_interval",
                                  why_not + "; remove run.checkpoint_interval", ""}});
  std::optional<io::ManifestScope> manifest;  // lists every file written below (io/output_folder.hpp)
  if (writer) {
    std::filesystem::create_directories(out);
    manifest.emplace(out);
  }
  const int threads_requested =
      options.threads > 0 ? options.threads : (threads > 0 ? threads : default_thread_count());

  // Multi-rate: the macro step is the largest subdomain step; finer subdomains
  // sub-cycle with dt_k = macro / n_k (n_k rounded up, so no step grows).
  const double macro = macro_step();
  std::vector<int> substeps;
  for (auto& sd : subdomains) {
    const int n = substeps_of(macro, sd->time_step());
    if (std::fabs(macro / n - sd->time_step()) > 1e-12 * macro) {
      spdlog::info("subdomain '{}': time step adjusted from {:.6g} s to {:.6g} s = macro step / {}", sd->name(),
                   sd->time_step(), macro / n, n);
      sd->set_time_step(macro / n);
    }
    substeps.push_back(n);
    sd->set_threads(threads_requested);
    sd->set_record_contacts(!ck && contact_sample.enabled());  // the outputs at t = 0 (wall loads, contacts)
    if (ranks) {
      const std::size_t k = substeps.size() - 1;
      if (groups.empty()) {
        ranks->distribute(*sd);
      } else {
        ranks->distribute(*sd, groups[k].first, groups[k].count);
        if (writer)
          spdlog::info("subdomain '{}' on rank{} {}{}", sd->name(), groups[k].count > 1 ? "s" : "", groups[k].first,
                       groups[k].count > 1 ? "-" + std::to_string(groups[k].first + groups[k].count - 1) : "");
      }
    }
    if (!ck) sd->setup();
  }
  // Wall loads and contact rows from subdomain k's recorded contacts; spread
  // over ranks, from every rank's particles and records, gathered on every
  // rank (the same sums everywhere: a servo moves its wall alike on all).
  auto take_contact_sample = [&](std::size_t k) {
    Subdomain& sd = *subdomains[k];
    if (!ranks) return contact_sample.take(k, sd, walls);
    const ParticleStore all = ranks->gather(sd, true);
    const std::vector<ContactRecord> records = gather_contact_records(*ranks, sd, all);
    contact_sample.take(k, sd, all, {&records}, walls);
  };
  if (!ck && contact_sample.enabled()) {
    contact_sample.begin(0.0);
    for (std::size_t k = 0; k < subdomains.size(); ++k) {
      take_contact_sample(k);
      subdomains[k]->set_record_contacts(false);
    }
  }
  flow.set_ranks(ranks);
  if (fluid) fluid->set_ranks(ranks);
  if (ck) {
    const int ranks_now = ranks ? ranks->size() : 1;
    if (ck->loop.ranks != ranks_now) {
      if (writer)
        spdlog::warn("restart on {} rank(s), the checkpoint was written on {}: the particles are shared out anew and "
                     "the forces summed in another order, so the run differs from an uninterrupted one by round-off",
                     ranks_now, ck->loop.ranks);
      restore_checkpoint(*ck, *this, ranks);
    } else if (!restore_checkpoint(*ck, *this, ranks) && writer) {
      spdlog::warn("restart on {} thread(s), the checkpoint was written on {}: the forces are summed in another "
                   "order, so the run differs from an uninterrupted one by round-off", threads_requested,
                   ck->loop.threads);
    }
    spdlog::info("restart from {}: t = {:.6g} s, macro step {}", options.restart.string(), ck->loop.time,
                 ck->loop.macro_index);
  }
  const std::uint64_t total_macro = static_cast<std::uint64_t>(std::ceil(duration / macro - kTimeTolerance));

  // Outputs.
  std::vector<std::string> columns = {"time"};
  for (const auto& sd : subdomains)
    for (const auto& c : kProbeColumns) columns.push_back(sd->name() + "." + c.name);
  if (repose_probe)
    for (const auto& sd : subdomains) columns.push_back(sd->name() + ".repose_angle_deg");
  for (const auto& rm : region_mass) {
    columns.push_back(rm.name + ".mass_kg");
    columns.push_back(rm.name + ".particles");
    if (rm.centre_of_mass)
      for (const char* c : {".com_x", ".com_y", ".com_z"}) columns.push_back(rm.name + c);
  }
  for (const auto& c : flow.columns()) columns.push_back(c);
  for (const auto& c : contact_sample.columns()) columns.push_back(c);
  for (const auto& c : servos.columns()) columns.push_back(c);
  if (!ck) flow.start(subdomains);

  // Cell grids: accessible volume from the walls present at the start.
  grids.clear();
  std::vector<std::unique_ptr<io::CellGridVtkSeries>> grid_vtk;
  std::vector<std::unique_ptr<io::CellGridProfileCsv>> grid_csv;
  std::vector<Interval> grid_files;
  for (const auto& g : grid_setups) {
    grids.push_back(std::make_unique<CellGrid>(g.spec));
    grids.back()->set_accessible(walls, 0.0);
    grids.back()->set_periodic(subdomains[g.subdomain]->periodic());
    const bool files = writer && g.spec.write_interval > 0;  // every rank samples, rank 0 writes
    grid_vtk.push_back(files ? std::make_unique<io::CellGridVtkSeries>(out, g.spec.name) : nullptr);
    grid_csv.push_back(files ? std::make_unique<io::CellGridProfileCsv>(out, g.spec.name, g.profile_axis) : nullptr);
    grid_files.emplace_back(g.spec.write_interval, g.spec.write_interval, macro);
  }
  // Every grid that samples a subdomain: the output grids and both levels of each coupling.
  // A coupling's grids also add their sampling time to the coupling's clock.
  struct Sampler {
    CellGrid* grid;
    std::size_t subdomain;
    double* seconds;  ///< where the sampling time goes; null for the output grids
  };
  std::vector<Sampler> samplers;
  for (std::size_t g = 0; g < grids.size(); ++g) samplers.push_back({grids[g].get(), grid_setups[g].subdomain, nullptr});
  for (auto& c : couplings) {
    c->set_ranks(ranks);
    c->start(subdomains, walls, writer ? out : std::filesystem::path());
    samplers.push_back({&c->fine_grid(), c->spec().fine, &c->timing().averaging});
    samplers.push_back({&c->coarse_grid(), c->spec().coarse, &c->timing().averaging});
  }
  // One step of subdomain k; `for_outputs`: its contacts go to the contact
  // sample of the outputs at the step's end (wall loads, contact files).
  auto step_subdomain = [&](std::size_t k, bool for_outputs) {
    Subdomain& sd = *subdomains[k];
    bool record = for_outputs;
    for (const auto& s : samplers) record = record || (s.subdomain == k && s.grid->due(sd.steps() + 1));
    sd.set_record_contacts(record);
    sd.step_deferred();  // finished by the next step or by the first observer (store(), stats())
    if (!record) return;
    if (ranks) {
      // every rank samples its grids from its own particles and records,
      // the per-cell sums reduced over the ranks (CellGrid::sample); the
      // outputs' contact sample reads every rank's, gathered
      const CellGrid::RankReduction reduce = [&](std::vector<double>& sums, std::vector<double>& maxima) {
        ranks->reduce_in_rank_order(sums, maxima);
      };
      for (const auto& s : samplers) {
        if (s.subdomain != k || !s.grid->due(sd.steps())) continue;
        const auto t0 = std::chrono::steady_clock::now();
        s.grid->sample(sd.store(), sd.owned(), sd.contact_records(), sd.time(), reduce);
        if (s.seconds) *s.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      }
      if (for_outputs) take_contact_sample(k);
      sd.set_record_contacts(false);
      return;
    }
    const auto records = sd.contact_records();
    for (const auto& s : samplers) {
      if (s.subdomain != k || !s.grid->due(sd.steps())) continue;
      const auto t0 = std::chrono::steady_clock::now();
      s.grid->sample(sd.store(), records, sd.time());
      if (s.seconds) *s.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    if (for_outputs) contact_sample.take(k, sd, walls);
    sd.set_record_contacts(false);
  };
  // The couplings' exchange, after the flow's own before-step work: at every
  // control_macro-th macro step all levels stand at the same time t, the
  // external forces are rebuilt from zero by every coupling's controllers.
  MacroHooks run_hooks = hooks;
  if (!couplings.empty()) {
    std::vector<std::size_t> levels;
    for (const auto& c : couplings)
      for (std::size_t k : {c->spec().fine, c->spec().coarse})
        if (std::find(levels.begin(), levels.end(), k) == levels.end()) levels.push_back(k);
    run_hooks.before.push_back([this, levels](const MacroStep& step) {
      if (step.index == 0 || step.index % control_macro != 0) return;
      for (std::size_t k : levels) {
        ParticleStore& s = subdomains[k]->store();
        std::fill(s.ext_fx.begin(), s.ext_fx.end(), 0.0);
        std::fill(s.ext_fy.begin(), s.ext_fy.end(), 0.0);
        std::fill(s.ext_fz.begin(), s.ext_fz.end(), 0.0);
      }
      for (auto& c : couplings) c->exchange(step.t, subdomains, walls, flow);
    });
  }
  // Servo walls: the loads of the macro step's last force evaluation set
  // the velocities of the next one.
  if (!servos.empty())
    run_hooks.after.push_back([this, ranks](const MacroStep& step) { servos.update(step.t, subdomains, ranks); });
  // The fluid exchange: all levels stand at the same time at a macro-step start.
  if (fluid)
    run_hooks.before.push_back([this](const MacroStep& step) {
      if (fluid->due(step.index)) fluid->exchange(step.t, subdomains);
    });
  // Walls that appear or disappear (an outlet plug) change the accessible
  // volume: recompute it when the set of active walls changes.
  std::vector<char> wall_active;
  for (const auto& w : walls) wall_active.push_back(w.active(0.0) ? 1 : 0);
  auto refresh_accessible = [&](double t) {
    bool changed = false;
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const char now = walls[w].active(t) ? 1 : 0;
      changed = changed || now != wall_active[w];
      wall_active[w] = now;
    }
    if (!changed) return;
    for (auto& g : grids) g->set_accessible(walls, t);
    for (auto& c : couplings) {
      c->fine_grid().set_accessible(walls, t);
      c->coarse_grid().set_accessible(walls, t);
    }
  };
  auto write_grids = [&](double t, bool final) {
    for (std::size_t g = 0; g < grids.size(); ++g) {
      if (!grid_vtk[g] || (!final && !grid_files[g].due(t))) continue;
      if (grids[g]->samples_pending() > 0) {
        const CellFields f = grids[g]->mean_since_last_take();
        grid_vtk[g]->write(t, *grids[g], f);
        grid_csv[g]->write(t, *grids[g], f);
      }
      grid_files[g].advance(t);
    }
  };
  // Spread over ranks, the outputs read each subdomain's particles gathered
  // on rank 0 in id order (once per output time) and its contact counts
  // summed over the ranks; otherwise the subdomain itself.
  std::vector<ParticleStore> gathered(subdomains.size());
  std::vector<double> gathered_at(subdomains.size(), std::nan(""));
  auto particles_of = [&](std::size_t k, double t) -> const ParticleStore& {
    if (!ranks) return subdomains[k]->store();
    if (!(gathered_at[k] == t)) {
      gathered[k] = ranks->gather(*subdomains[k]);
      gathered_at[k] = t;
    }
    return gathered[k];
  };
  auto stats_of = [&](std::size_t k, double t) {
    SubdomainStats st = subdomains[k]->stats();
    if (!ranks) return st;
    const SubdomainStats local = st;
    st = kinetic_stats(particles_of(k, t));
    std::vector<std::uint64_t> counts{local.contacts, local.wall_contacts};
    ranks->sum(counts);
    st.contacts = counts[0];
    st.wall_contacts = counts[1];
    st.max_overlap_ratio = ranks->max(local.max_overlap_ratio);
    return st;
  };
  auto particles_now = [&]() {
    std::vector<std::uint64_t> n{0};
    for (const auto& sd : subdomains) n[0] += sd->owned();
    if (ranks) ranks->sum(n);
    return static_cast<std::size_t>(n[0]);
  };
  std::unique_ptr<io::CsvSeries> probes;
  const bool probing = probe_interval > 0;  // on every rank: the rows' statistics are collective
  if (probing && writer) probes = std::make_unique<io::CsvSeries>(out / "probes.csv", columns);
  std::unique_ptr<io::VtkSeriesWriter> vtk;
  const bool framing = vtk_interval > 0;
  if (framing && writer) {
    vtk = std::make_unique<io::VtkSeriesWriter>(out, "particles");
    std::vector<std::string> names;
    for (const Material& m : materials) names.push_back(m.name);
    vtk->set_material_names(std::move(names));
  }
  std::unique_ptr<io::WallSurfaceSeries> wall_vtk;
  if (vtk && wall_surfaces && !walls.empty()) wall_vtk = std::make_unique<io::WallSurfaceSeries>(out, "walls");
  std::unique_ptr<io::ContactSeriesWriter> contact_vtk;
  const bool contact_framing = contact_sample.wants_rows() && contact_interval > 0;  // on every rank: collective
  if (contact_framing && writer)
    contact_vtk = std::make_unique<io::ContactSeriesWriter>(out, "contacts");
  auto write_probes = [&](double t) {
    std::vector<double> row = {t};
    for (std::size_t k = 0; k < subdomains.size(); ++k) {
      const SubdomainStats st = stats_of(k, t);
      for (const auto& c : kProbeColumns) row.push_back(c.value(st));
    }
    auto at_t = [&](std::size_t k) -> const ParticleStore& { return particles_of(k, t); };
    if (repose_probe)
      for (std::size_t k = 0; k < subdomains.size(); ++k)
        row.push_back(repose_angle(at_t(k), *repose_probe).value_or(std::nan("")));
    for (const auto& rm : region_mass) {
      double com[3];
      const auto [kg, n] = mass_in_region(subdomains, at_t, rm, com);
      row.push_back(kg);
      row.push_back(static_cast<double>(n));
      if (rm.centre_of_mass) row.insert(row.end(), com, com + 3);
    }
    flow.check_planes(subdomains);
    flow.append_row(t, row);
    contact_sample.append_values(t, kTimeTolerance * macro, row);
    servos.append_values(t, row);
    if (probes) probes->append(row);
  };
  auto write_vtk = [&](double t) {
    std::vector<io::ParticleSet> sets;
    for (std::size_t k = 0; k < subdomains.size(); ++k)
      sets.push_back({&particles_of(k, t), static_cast<int>(k), &subdomains[k]->materials()});
    if (!vtk) return;
    vtk->write(t, sets);
    if (wall_vtk) wall_vtk->write(t, walls, scene_lo, scene_hi);
    if (probes) probes->flush();  // probes.csv reaches the frame just written
  };
  auto write_contacts = [&](double t) {
    if (!contact_vtk) return;  // another rank writes
    const std::vector<io::ContactRow>* rows = contact_sample.rows_at(t, kTimeTolerance * macro);
    if (!rows) spdlog::warn("contacts: no contacts were recorded for t = {:.6g} s; its file is empty", t);
    contact_vtk->write(t, rows ? *rows : std::vector<io::ContactRow>{});
  };

  const std::size_t particles = particles_now();
  if (writer)
    spdlog::info("running '{}': {} particles in {} subdomain(s), {:.6g} s simulated in {} macro steps of {:.4g} s, "
                 "{} thread(s){} -> {}",
                 name, particles, subdomains.size(), duration, total_macro, macro, threads_requested,
                 ranks ? " on each of " + std::to_string(ranks->size()) + " ranks" : std::string(), out.string());

  Interval probe_rows(probing ? probe_interval : 0.0, 0.0, macro);
  Interval vtk_frames(framing ? vtk_interval : 0.0, 0.0, macro);
  Interval contact_frames(contact_framing ? contact_interval : 0.0, 0.0, macro);
  Interval checkpoints(checkpoint_interval, checkpoint_interval, macro);
  std::uint64_t m = 0;
  if (ck) {
    // Go on where the checkpointed run stood: its schedules (re-derived when
    // an interval changed), its files cut back to what it had written then.
    m = ck->loop.macro_index;
    const double t_before = m > 0 ? static_cast<double>(m - 1) * macro : -1.0;
    auto resume = [&](Interval& iv, std::uint64_t k, double period) {
      if (period == iv.period()) iv.resume(k);
      else if (t_before >= 0) iv.advance(t_before);
    };
    resume(probe_rows, ck->loop.probe_rows, ck->loop.probe_period);
    resume(vtk_frames, ck->loop.vtk_frames, ck->loop.vtk_period);
    resume(checkpoints, ck->loop.checkpoints, checkpoint_interval);
    if (probes && ck->loop.probe_bytes > 0) probes->resume(ck->loop.probe_bytes);
    if (vtk) vtk->resume(ck->loop.vtk_times);
    const ArchiveReader& r = *ck->archive;
    // the contact sample and files (sections absent when the checkpointed run had none)
    if (contact_sample.enabled() && r.has("contacts/time")) contact_sample.load(r, "contacts/");
    if (contact_framing && r.has("contacts/frames")) {  // the schedule on every rank: it decides a gather
      resume(contact_frames, r.scalar<std::uint64_t>("contacts/frames"), r.scalar<double>("contacts/period"));
      if (contact_vtk) contact_vtk->resume(r.get<double>("contacts/frame_times"));
    }
    if (wall_vtk && r.has("walls/frame_times")) wall_vtk->resume(r.get<double>("walls/frame_times"));
    for (std::size_t g = 0; g < grids.size(); ++g) {
      const std::string p = "grid" + std::to_string(g) + "/";
      grids[g]->load(r, p);
      const auto files = r.get<std::uint64_t>(p + "files");
      if (files.size() != 2) r.fail(p + "files", "does not hold a grid's file state");
      resume(grid_files[g], files[0], r.scalar<double>(p + "write_interval"));
      if (grid_vtk[g]) {
        grid_vtk[g]->resume(r.get<double>(p + "vtk_times"));
        if (files[1] > 0) grid_csv[g]->resume(files[1]);
      }
    }
    for (std::size_t k = 0; k < couplings.size(); ++k) couplings[k]->load(r, "coupling" + std::to_string(k) + "/");
    if (fluid) fluid->load(r, "fluid/", out);
    // the walls' activity as the run last looked at it (refresh_accessible)
    for (std::size_t w = 0; w < walls.size(); ++w) wall_active[w] = walls[w].active(t_before >= 0 ? t_before : 0.0) ? 1 : 0;
  }
  const std::uint64_t first_macro = m;
  auto save_checkpoint = [&](std::uint64_t at) {
    const auto t0 = std::chrono::steady_clock::now();
    LoopState ls;
    ls.macro_index = at;
    ls.time = static_cast<double>(at) * macro;
    ls.probe_rows = probe_rows.index();
    ls.vtk_frames = vtk_frames.index();
    ls.checkpoints = checkpoints.index();
    ls.probe_period = probe_rows.period();
    ls.vtk_period = vtk_frames.period();
    if (probes) {
      probes->flush();
      ls.probe_bytes = probes->size();
    }
    if (vtk) ls.vtk_times = vtk->frame_times();
    ls.threads = threads_requested;
    write_checkpoint(out / kCheckpointFile, *this, ls, registry, [&](ArchiveWriter& w) {
      for (std::size_t g = 0; g < grids.size(); ++g) {
        const std::string p = "grid" + std::to_string(g) + "/";
        grids[g]->save(w, p);
        w.put(p + "files", std::vector<std::uint64_t>{grid_files[g].index(), grid_csv[g] ? grid_csv[g]->size() : 0u});
        w.put_scalar(p + "write_interval", grid_files[g].period());
        w.put(p + "vtk_times", grid_vtk[g] ? grid_vtk[g]->frame_times() : std::vector<double>{});
      }
      for (std::size_t k = 0; k < couplings.size(); ++k) couplings[k]->save(w, "coupling" + std::to_string(k) + "/");
      if (fluid) fluid->save(w, "fluid/");
      if (contact_sample.enabled()) contact_sample.save(w, "contacts/");
      if (!servos.empty()) servos.save(w, "servos/");
      if (contact_vtk) {
        w.put_scalar("contacts/frames", contact_frames.index());
        w.put_scalar("contacts/period", contact_frames.period());
        w.put("contacts/frame_times", contact_vtk->frame_times());
      }
      if (wall_vtk) w.put("walls/frame_times", wall_vtk->frame_times());
    }, ranks);
    spdlog::debug("checkpoint at t = {:.6g} s written in {:.3g} s", ls.time,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  };
  MacroStep step;  // what the hooks see, updated in place
  step.macro = macro;
  step.subdomains = &subdomains;
  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  const bool tty = isatty(fileno(stderr));
  double particle_steps = 0;
  double window_particle_steps = 0;
  auto window_start = start;
  const std::uint64_t stop = options.max_steps ? std::min(options.max_steps, total_macro) : total_macro;
  if (m > stop)
    throw ConfigError({Diagnostic{scenario_file.string(), "/run",
                                  "the checkpoint " + options.restart.string() + " is at t = " +
                                      std::to_string(static_cast<double>(m) * macro) +
                                      " s, after the end of this run (" + std::to_string(stop * macro) +
                                      " s); lengthen run.duration", ""}});
  for (;; ++m) {
    const double t = static_cast<double>(m) * macro;
    // at the start of a macro step, before its hooks and outputs: a restart
    // begins here, and the last one is at the end of the run
    if (m > first_macro && checkpoints_possible &&
        (checkpoints.take(t) || (m == stop && checkpoint_interval > 0)))
      save_checkpoint(m);
    result.interrupted_by = m < stop ? interrupt_requested() : 0;
    if (ranks && m < stop) {
      // every rank stops at the same macro step: the first signal any rank saw
      std::vector<std::uint64_t> sig{static_cast<std::uint64_t>(result.interrupted_by)};
      ranks->sum(sig);
      if (sig[0] != 0 && result.interrupted_by == 0) result.interrupted_by = SIGTERM;
    }
    if (result.interrupted_by != 0) {
      // a signal: the last step is complete; the checkpoint holds it, and
      // probes.csv and the other files end where the checkpoint does
      if (options.checkpoint_on_signal && checkpoints_possible) save_checkpoint(m);
      else if (options.checkpoint_on_signal)
        spdlog::warn("no checkpoint: {}", why_not);
      break;
    }
    if (m < stop && !run_hooks.before.empty()) {
      step.t = t;
      step.index = m;
      MacroHooks::run(run_hooks.before, step);
    }
    if (probe_rows.take(t)) write_probes(t);
    if (vtk_frames.take(t)) write_vtk(t);
    if (contact_frames.take(t)) write_contacts(t);
    if ((!grids.empty() || !couplings.empty()) && m > 0) {
      write_grids(t, false);
      refresh_accessible(t);
    }
    if (m > 0)
      for (auto& c : couplings) c->write_grids(t, false);
    if (fluid && m < stop) fluid->write_fields(t, false, out);
    if (m == stop) break;
    if (options.time_after && m == options.time_after) window_start = std::chrono::steady_clock::now();
    // the contacts of the macro step's last steps, when an output at its end needs them
    const double t_end = static_cast<double>(m + 1) * macro;
    const bool sample = contact_sample.enabled() && ((probing && contact_sample.has_probes() && probe_rows.due(t_end)) ||
                                                     contact_frames.due(t_end));
    if (sample) contact_sample.begin(t_end);
    for (std::size_t k = 0; k < subdomains.size(); ++k) {
      for (int s = 0; s < substeps[k]; ++s) step_subdomain(k, sample && s == substeps[k] - 1);
      const double ps = static_cast<double>(substeps[k]) * static_cast<double>(subdomains[k]->owned());
      particle_steps += ps;
      if (options.time_after && m >= options.time_after) window_particle_steps += ps;
    }
    if (!run_hooks.after.empty()) {
      step.t = static_cast<double>(m + 1) * macro;
      step.index = m;
      MacroHooks::run(run_hooks.after, step);
    }
    const auto now = std::chrono::steady_clock::now();
    const double since = std::chrono::duration<double>(now - last_report).count();
    if (writer && options.progress && since >= (tty ? 1.0 : 10.0)) {
      last_report = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      const double rate = (m + 1) / elapsed;
      const double eta = (stop - m - 1) / rate;
      std::fprintf(stderr, "%s[domel] t = %.4g / %.4g s (%3.0f%%) | %.0f steps/s | %.3g particle-steps/s | ETA %s%s",
                   tty ? "\r" : "", (m + 1) * macro, stop * macro, 100.0 * (m + 1) / stop, rate,
                   particle_steps / elapsed, format_seconds(eta).c_str(), tty ? "   " : "\n");
      std::fflush(stderr);
    }
  }
  for (auto& sd : subdomains) sd->synchronize();  // the last step's pending half kick, inside the timing
  const auto end = std::chrono::steady_clock::now();
  const double wall = std::chrono::duration<double>(end - start).count();
  if (writer && options.progress && tty) std::fprintf(stderr, "\n");
  if (ranks) {
    // every rank's particle-steps (rank 0's progress line counted its own)
    std::vector<std::uint64_t> ps{static_cast<std::uint64_t>(particle_steps),
                                  static_cast<std::uint64_t>(window_particle_steps)};
    ranks->sum(ps);
    particle_steps = static_cast<double>(ps[0]);
    window_particle_steps = static_cast<double>(ps[1]);
  }
  if (probes) probes->flush();
  write_grids(static_cast<double>(m) * macro, true);
  for (auto& c : couplings) c->write_grids(static_cast<double>(m) * macro, true);
  if (fluid) fluid->write_fields(static_cast<double>(m) * macro, true, out);

  result.macro_steps = m;
  result.simulated_time = static_cast<double>(m) * macro;
  result.wall_seconds = wall;
  result.particle_steps_per_second = wall > 0 ? particle_steps / wall : 0;

  nlohmann::json summary;
  summary["domel_version"] = DOMEL_VERSION;
  summary["sdk_abi"] = std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR);
  summary["scenario"] = {{"name", name}, {"file", scenario_file.string()}};
  summary["status"] = result.interrupted_by ? "interrupted" : "completed";
  if (result.interrupted_by) {
    summary["signal"] = result.interrupted_by == SIGINT ? "SIGINT" : result.interrupted_by == SIGTERM ? "SIGTERM"
                                                                                                  : std::to_string(result.interrupted_by);
    if (options.checkpoint_on_signal && checkpoints_possible) summary["checkpoint"] = kCheckpointFile;
  }
  if (ck) summary["restarted_from"] = {{"checkpoint", options.restart.string()}, {"simulated_time_s", ck->loop.time}};
  summary["finished"] = iso_time_now();
  summary["threads"] = threads_requested;
  summary["ranks"] = ranks ? ranks->size() : 1;
  summary["seed"] = seed;
  summary["steps"] = m;
  summary["simulated_time_s"] = result.simulated_time;
  summary["wall_time_s"] = wall;
  summary["particles"] = particles_now();
  summary["particles_at_start"] = particles;
  summary["particle_steps_per_s"] = result.particle_steps_per_second;
  {
    // Peak resident memory of the process (getrusage; Linux reports KiB). The
    // benchmark turns two sizes into bytes per particle (docs/performance.md).
    struct rusage usage {};
    if (getrusage(RUSAGE_SELF, &usage) == 0) summary["peak_rss_bytes"] = static_cast<long long>(usage.ru_maxrss) * 1024;
  }
  nlohmann::json libs = nlohmann::json::array();
  for (const auto& lib : registry.libraries())
    libs.push_back({{"name", lib.name}, {"version", lib.version}, {"path", lib.path.string()},
                    {"abi", std::to_string(lib.abi_major) + "." + std::to_string(lib.abi_minor)}});
  summary["plugin_libraries"] = libs;
  summary["models"] = models_used;
  nlohmann::json files = {{"probes", probing ? "probes.csv" : ""},
                          {"particles", framing ? "particles.pvd" : ""},
                          {"walls", wall_vtk ? "walls.pvd" : ""},
                          {"contacts", contact_vtk ? "contacts.pvd" : ""}};
  nlohmann::json sds = nlohmann::json::array();
  for (std::size_t k = 0; k < subdomains.size(); ++k) {
    const auto& sd = subdomains[k];
    const SubdomainStats st = stats_of(k, result.simulated_time);
    const nlohmann::json traffic = ranks ? ranks->traffic(*sd) : nlohmann::json();
    // the same on every rank of the subdomain's group, none elsewhere
    const auto builds = static_cast<std::uint64_t>(
        ranks ? ranks->max(static_cast<double>(sd->neighbor_builds())) : static_cast<double>(sd->neighbor_builds()));
    MemoryUse mem = sd->memory_use();
    if (ranks) {  // over all ranks
      std::vector<std::uint64_t> b{mem.particles, mem.neighbor_lists, mem.contact_history, mem.threads};
      ranks->sum(b);
      mem.particles = static_cast<std::size_t>(b[0]);
      mem.neighbor_lists = static_cast<std::size_t>(b[1]);
      mem.contact_history = static_cast<std::size_t>(b[2]);
      mem.threads = static_cast<std::size_t>(b[3]);
    }
    sds.push_back({{"name", sd->name()},
                   {"coarse_grain", sd->coarse_grain()},
                   {"particles", st.particles},
                   {"time_step_s", sd->time_step()},
                   {"time_step_reason", time_steps[k].reason},
                   {"rayleigh_time_s", time_steps[k].rayleigh},
                   {"contact_time_s", time_steps[k].contact_time},
                   {"stability_limit_s", time_steps[k].critical},
                   {"steps", sd->steps()},
                   {"neighbor_list_builds", builds},
                   {"memory_bytes", {{"particles", mem.particles},
                                     {"neighbor_lists", mem.neighbor_lists},
                                     {"contact_history", mem.contact_history},
                                     {"thread_force_arrays", mem.threads}}},
                   {"final", {{"ke_translational_J", st.kinetic_translational},
                              {"ke_rotational_J", st.kinetic_rotational},
                              {"mean_angular_speed", st.mean_angular_speed},
                              {"median_angular_speed", st.median_angular_speed},
                              {"trimmed_mean_angular_speed", st.trimmed_mean_angular_speed},
                              {"max_overlap_ratio", st.max_overlap_ratio},
                              {"contacts", st.contacts},
                              {"wall_contacts", st.wall_contacts}}}});
    if (ranks) sds.back()["ranks_exchange"] = traffic;
    if (!groups.empty()) sds.back()["rank_group"] = {{"first", groups[k].first}, {"count", groups[k].count}};
  }
  auto at_end = [&](std::size_t k) -> const ParticleStore& { return particles_of(k, result.simulated_time); };
  if (repose_probe) {
    nlohmann::json angles = nlohmann::json::object();
    for (std::size_t k = 0; k < subdomains.size(); ++k) {
      const auto a = repose_angle(at_end(k), *repose_probe);
      angles[subdomains[k]->name()] = a ? nlohmann::json(*a) : nlohmann::json(nullptr);
    }
    summary["repose_angle_deg"] = angles;
  }
  if (!region_mass.empty()) {
    nlohmann::json rj = nlohmann::json::object();
    for (const auto& rm : region_mass) {
      const auto [kg, n] = mass_in_region(subdomains, at_end, rm);
      rj[rm.name] = {{"mass_kg", kg}, {"particles", n}};
    }
    summary["region_mass"] = rj;
  }
  summary["subdomains"] = sds;
  if (!couplings.empty()) {
    nlohmann::json cj = nlohmann::json::object();
    for (auto& c : couplings) {
      cj[c->spec().name] = c->summary(subdomains, at_end(c->spec().fine), flow);
      if (c->spec().grid_interval > 0)
        files["couplings"][c->spec().name] = {{"balance", c->spec().name + "_balance.csv"},
                                              {"fine_grid", c->spec().name + "_fine.pvd"},
                                              {"coarse_grid", c->spec().name + "_coarse.pvd"}};
      else
        files["couplings"][c->spec().name] = {{"balance", c->spec().name + "_balance.csv"}};
    }
    summary["couplings"] = cj;
  }
  if (fluid) {
    summary["fluid"] = fluid->summary();
    if (summary["fluid"].contains("fields")) files["fluid"] = "fluid.pvd";
  }
  if (!flow.empty()) {
    flow.check_planes(subdomains);
    const nlohmann::json flow_summary = flow.summary(subdomains);
    for (auto& [key, value] : flow_summary.items()) summary[key] = value;
  }
  if (options.time_after && m > options.time_after) {
    const double w = std::chrono::duration<double>(end - window_start).count();
    summary["timed_window"] = {{"from_step", options.time_after},
                               {"steps", m - options.time_after},
                               {"wall_time_s", w},
                               {"particle_steps_per_s", w > 0 ? window_particle_steps / w : 0.0}};
  }
  if (write_state) {
    for (const auto& sd : subdomains) {
      std::string f = sd->name() + "_state.csv";
      for (char& c : f)  // a file name whatever the subdomain is called
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') c = '_';
      std::vector<std::string> names;  // of its materials, by local index
      for (std::size_t g : sd->materials()) names.push_back(materials[g].name);
      const ParticleStore& all = particles_of(static_cast<std::size_t>(&sd - subdomains.data()), result.simulated_time);
      if (writer) io::write_particle_state(out / f, all, sd->name(), result.simulated_time, sd->coarse_grain(), names);
      files["state"][sd->name()] = f;
    }
  }
  for (std::size_t g = 0; g < grids.size(); ++g)
    if (grid_vtk[g]) files["grids"][grid_setups[g].spec.name] = {{"series", grid_setups[g].spec.name + ".pvd"},
                                                                {"profile", grid_setups[g].spec.name + "_profile.csv"}};
  summary["outputs"] = files;
  if (writer) io::write_file_atomically(out / "summary.json", summary.dump(2) + "\n");
  result.summary = summary;
  if (writer)
    spdlog::info("done: {} steps, {:.6g} s simulated in {:.3g} s wall ({:.3g} particle-steps/s)", m,
               result.simulated_time, wall, result.particle_steps_per_second);
  return result;
}

}  // namespace domel::platform
