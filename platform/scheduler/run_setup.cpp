// SPDX-License-Identifier: MIT
// The run loop's helpers (simulation.hpp): the levels' rank groups, time
// steps and threads before the first step, the world a checkpoint restores,
// and the part of summary.json that is the run's own (the components add
// theirs at finish()).
#include "scheduler/simulation.hpp"

#include "core/error.hpp"
#include "scheduler/checkpoint.hpp"

#include <spdlog/spdlog.h>

#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <ctime>

namespace domel::platform {

namespace {

std::string iso_time_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

}  // namespace

std::vector<RankGroup> Simulation::rank_groups_checked(RunRanks& ranks) const {
  if (ranks.size() == 1) {  // rank groups share out ranks: there are none to share
    if (!rank_shares.empty()) spdlog::info("one process: the subdomains' rank_share apply to runs under mpirun only");
    return {};
  }
  if (rank_shares.empty()) return {};
  // levels on rank groups (subdomains[].rank_share), checked before anything is written
  if (static_cast<std::size_t>(ranks.size()) < subdomains.size())
    throw ConfigError({Diagnostic{scenario_file.string(), "/subdomains/0/rank_share",
                                  "the subdomains run on rank groups of their own (rank_share), which needs a rank "
                                  "for each of the " + std::to_string(subdomains.size()) + " subdomains; mpirun "
                                  "started " + std::to_string(ranks.size()),
                                  "run on at least " + std::to_string(subdomains.size()) + " ranks (mpirun -np " +
                                      std::to_string(subdomains.size()) + "), or remove every rank_share"}});
  return rank_groups(rank_shares, ranks.size());
}

std::vector<int> Simulation::prepare_levels(RunRanks& ranks, const std::vector<RankGroup>& groups, int threads_n,
                                            bool writer) {
  // Multi-rate: the macro step is the largest subdomain step; finer subdomains
  // sub-cycle with dt_k = macro / n_k (n_k rounded up, so no step grows).
  const double macro = macro_step();
  std::vector<int> substeps;
  for (std::size_t k = 0; k < subdomains.size(); ++k) {
    Subdomain& sd = *subdomains[k];
    const int n = substeps_of(macro, sd.time_step());
    if (std::fabs(macro / n - sd.time_step()) > 1e-12 * macro) {
      spdlog::info("subdomain '{}': time step adjusted from {:.6g} s to {:.6g} s = macro step / {}", sd.name(),
                   sd.time_step(), macro / n, n);
      sd.set_time_step(macro / n);
    }
    substeps.push_back(n);
    sd.set_threads(threads_n);
    if (groups.empty()) {
      ranks.distribute(sd);
      continue;
    }
    ranks.distribute(sd, groups[k].first, groups[k].count);
    if (writer)
      spdlog::info("subdomain '{}' on rank{} {}{}", sd.name(), groups[k].count > 1 ? "s" : "", groups[k].first,
                   groups[k].count > 1 ? "-" + std::to_string(groups[k].first + groups[k].count - 1) : "");
  }
  return substeps;
}

void Simulation::restore_world(const OpenedCheckpoint& ck, RunRanks& ranks, int threads_n, bool writer) {
  const int ranks_now = ranks.size();
  CheckpointWorld w = world();
  if (ck.loop.ranks != ranks_now) {
    if (writer)
      spdlog::warn("restart on {} rank(s), the checkpoint was written on {}: the particles are shared out anew and "
                   "the forces summed in another order, so the run differs from an uninterrupted one by round-off",
                   ranks_now, ck.loop.ranks);
    restore_checkpoint(ck, w, ranks);
  } else if (!restore_checkpoint(ck, w, ranks) && writer) {
    spdlog::warn("restart on {} thread(s), the checkpoint was written on {}: the forces are summed in another "
                 "order, so the run differs from an uninterrupted one by round-off", threads_n, ck.loop.threads);
  }
  spdlog::info("restart from {}: t = {:.6g} s, macro step {}", ck.archive->path().string(), ck.loop.time,
               ck.loop.macro_index);
}

nlohmann::json Simulation::summary(RunContext& ctx, const RunResult& result, const RunOptions&,
                                   const PluginRegistry& registry, const std::vector<RankGroup>& groups,
                                   int threads_n, std::size_t particles_at_start) const {
  RunRanks& ranks = ctx.ranks;
  nlohmann::json summary;
  summary["domel_version"] = DOMEL_VERSION;
  summary["sdk_abi"] = std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR);
  summary["scenario"] = {{"name", name}, {"file", scenario_file.string()}};
  summary["status"] = result.interrupted_by ? "interrupted" : "completed";
  if (result.interrupted_by)
    summary["signal"] = result.interrupted_by == SIGINT    ? "SIGINT"
                        : result.interrupted_by == SIGTERM ? "SIGTERM"
                                                           : std::to_string(result.interrupted_by);
  summary["finished"] = iso_time_now();
  summary["threads"] = threads_n;
  summary["ranks"] = ranks.size();
  summary["seed"] = seed;
  summary["steps"] = result.macro_steps;
  summary["simulated_time_s"] = result.simulated_time;
  summary["wall_time_s"] = result.wall_seconds;
  std::size_t particles = 0;
  for (const auto& sd : subdomains) particles += sd->owned();
  summary["particles"] = ranks.sum_count(particles);
  summary["particles_at_start"] = particles_at_start;
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
  nlohmann::json sds = nlohmann::json::array();
  for (std::size_t k = 0; k < subdomains.size(); ++k) {
    const auto& sd = subdomains[k];
    const SubdomainStats st = ctx.stats(k, result.simulated_time);
    const nlohmann::json traffic = ranks.traffic(*sd);  // null on one process
    // the same on every rank of the subdomain's group, none elsewhere
    const auto builds = static_cast<std::uint64_t>(
        ranks.max(static_cast<double>(sd->neighbor_builds())));
    MemoryUse mem = sd->memory_use();
    {  // over all ranks
      std::vector<std::uint64_t> b{mem.particles, mem.neighbor_lists, mem.contact_history, mem.threads};
      ranks.sum(b);
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
    if (!traffic.is_null()) sds.back()["ranks_exchange"] = traffic;
    if (!groups.empty()) sds.back()["rank_group"] = {{"first", groups[k].first}, {"count", groups[k].count}};
  }
  summary["subdomains"] = sds;
  summary["outputs"] = nlohmann::json::object();
  return summary;
}

}  // namespace domel::platform
