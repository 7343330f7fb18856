// SPDX-License-Identifier: MIT
// Writing, opening and restoring checkpoints (checkpoint.hpp).
#include "scheduler/checkpoint.hpp"

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "loader/plugin_registry.hpp"
#include "flow/particle_flow.hpp"
#include "loop/ranks.hpp"
#include "scheduler/servo.hpp"
#include "subdomain/subdomain.hpp"

#include <ctime>

namespace domel::platform {

namespace {

constexpr const char* kFormat = "domel checkpoint";

std::string sd_prefix(std::size_t k) { return "subdomain" + std::to_string(k) + "/"; }

/// Scenario keys whose change leaves the checkpointed state valid: when the
/// run ends, how often it writes, where, and on how many threads.
const char* const kSafePrefixes[] = {"/run/duration", "/run/steps", "/run/threads", "/run/checkpoint_interval",
                                     "/output/vtk_interval", "/output/probe_interval", "/output/state",
                                     "/output/directory", "/name", "/description", "/$schema"};

bool starts_with_pointer(const std::string& path, const std::string& prefix) {
  return path == prefix || (path.size() > prefix.size() && path.compare(0, prefix.size(), prefix) == 0 &&
                            path[prefix.size()] == '/');
}

/// Keys that decide only the particles a fresh run starts with, which a
/// restart takes from the checkpoint instead.
bool initial_particles_only(const std::string& path) {
  if (path.rfind("/subdomains/", 0) != 0) return false;
  const auto slash = path.find('/', 12);
  if (slash == std::string::npos) return false;
  const std::string rest = path.substr(slash);
  return starts_with_pointer(rest, "/insert") || starts_with_pointer(rest, "/initial_state");
}

std::string short_json(const nlohmann::json& j) {
  std::string s = j.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

int major_of(const std::string& version) {
  try {
    return std::stoi(version);
  } catch (...) {
    return -1;
  }
}

}  // namespace

void write_checkpoint(const std::filesystem::path& file, CheckpointWorld& sim, const LoopState& loop,
                      const PluginRegistry& registry, const std::function<void(ArchiveWriter&)>& extra,
                      RunRanks& ranks) {
  // One process writes each subdomain's sections in place; spread over
  // ranks, every rank's part of each subdomain is a nested archive, on rank 0
  // (the one branch on the rank count here: the file's layout differs).
  const bool in_place = ranks.size() == 1;
  std::vector<std::vector<std::vector<char>>> parts(sim.subdomains.size());
  std::vector<std::uint64_t> owned(sim.subdomains.size());
  for (std::size_t k = 0; k < sim.subdomains.size(); ++k) owned[k] = sim.subdomains[k]->owned();
  ranks.sum(owned);
  if (!in_place) {
    for (std::size_t k = 0; k < sim.subdomains.size(); ++k) {
      ArchiveWriter part;
      sim.subdomains[k]->save(part, "");
      const std::string bytes = part.serialize("{}");
      parts[k] = ranks.gather_to_root(std::vector<char>(bytes.begin(), bytes.end()));
    }
  }
  if (ranks.rank() != 0) return;
  ArchiveWriter w;
  nlohmann::json header;
  header["format"] = kFormat;
  header["domel_version"] = DOMEL_VERSION;
  header["sdk_abi"] = std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR);
  {
    const std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    header["written"] = buf;
  }
  header["scenario"] = {{"name", sim.name}, {"file", sim.scenario_file.string()}};
  header["simulated_time_s"] = loop.time;
  header["macro_step_index"] = loop.macro_index;
  header["threads"] = loop.threads;
  header["ranks"] = ranks.size();
  nlohmann::json sds = nlohmann::json::array();
  for (std::size_t k = 0; k < sim.subdomains.size(); ++k) {
    const Subdomain& sd = *sim.subdomains[k];
    sds.push_back({{"name", sd.name()}, {"coarse_grain", sd.coarse_grain()},
                   {"particles", owned[k]}, {"steps", sd.steps()},
                   {"time_step_s", sd.time_step()}});
  }
  header["subdomains"] = sds;
  header["models"] = sim.models_used;
  header["stateful_models"] = sim.stateful_models;
  nlohmann::json libs = nlohmann::json::array();
  for (const auto& lib : registry.libraries())
    libs.push_back({{"name", lib.name}, {"version", lib.version},
                    {"abi", std::to_string(lib.abi_major) + "." + std::to_string(lib.abi_minor)}});
  header["plugin_libraries"] = libs;
  header["document"] = sim.document;

  w.put(std::string("loop/counters"), std::vector<std::uint64_t>{loop.macro_index, loop.checkpoints,
                                                                  static_cast<std::uint64_t>(loop.threads)});
  w.put(std::string("loop/reals"), std::vector<double>{loop.time});
  if (!sim.servos.empty()) sim.servos.save(w, "servos/");
  for (std::size_t k = 0; k < sim.subdomains.size(); ++k) {
    if (in_place) {
      sim.subdomains[k]->save(w, sd_prefix(k));
      continue;
    }
    w.put_scalar<std::uint64_t>(sd_prefix(k) + "ranks", parts[k].size());
    for (std::size_t r = 0; r < parts[k].size(); ++r)
      w.put_text(sd_prefix(k) + "rank" + std::to_string(r), std::string(parts[k][r].begin(), parts[k][r].end()));
  }
  sim.flow.save(w, "flow/");
  if (extra) extra(w);
  io::write_file_atomically(file, w.serialize(header.dump()));
}

OpenedCheckpoint open_checkpoint(const std::filesystem::path& file, const CheckpointWorld& sim) {
  OpenedCheckpoint ck;
  ck.archive = std::make_unique<ArchiveReader>(file);
  const ArchiveReader& r = *ck.archive;
  try {
    ck.header = nlohmann::json::parse(r.header());
  } catch (const nlohmann::json::exception&) {
    r.fail("", "has a header that is not JSON");
  }
  if (!ck.header.is_object() || ck.header.value("format", std::string()) != kFormat || !ck.header.contains("document"))
    r.fail("", "has no domel checkpoint header");

  // The scenario: every change must be one that leaves the state valid.
  std::vector<Diagnostic> refused;
  const nlohmann::json patch = nlohmann::json::diff(ck.header["document"], sim.document);
  for (const auto& op : patch) {
    const std::string path = op["path"].get<std::string>();
    const nlohmann::json::json_pointer ptr(path);
    const std::string was = ck.header["document"].contains(ptr) ? short_json(ck.header["document"][ptr]) : "(absent)";
    const std::string now = sim.document.contains(ptr) ? short_json(sim.document[ptr]) : "(absent)";
    bool safe = false;
    for (const char* p : kSafePrefixes) safe = safe || starts_with_pointer(path, p);
    if (safe) {
      ck.allowed_changes.push_back(path + ": " + was + " -> " + now);
    } else if (initial_particles_only(path)) {
      ck.allowed_changes.push_back(path + ": " + was + " -> " + now + " (ignored: the particles come from the checkpoint)");
    } else {
      refused.push_back(Diagnostic{sim.scenario_file.string(), path,
                                   "differs from the checkpointed run's scenario (" + file.string() + "): it was " +
                                       was + ", now " + now + "; a restart may change only the end time, output "
                                       "intervals, output folder, threads and checkpoint interval",
                                   ""});
    }
  }
  // The plugins: the same model, of the same major version, in every slot.
  const nlohmann::json& was_models = ck.header["models"];
  for (const auto& [sd, slots] : sim.models_used.items()) {
    if (!slots.is_object()) continue;
    for (const auto& [slot, m] : slots.items()) {
      if (!was_models.contains(sd) || !was_models[sd].contains(slot)) continue;  // a scenario change, reported above
      const auto& old = was_models[sd][slot];
      const std::string old_v = old.value("version", std::string()), new_v = m.value("version", std::string());
      if (major_of(old_v) != major_of(new_v))
        refused.push_back(Diagnostic{sim.scenario_file.string(), "",
                                     "subdomain '" + sd + "', " + slot + " model '" + m.value("model", std::string()) +
                                         "': the checkpoint was written with version " + old_v + ", this run loads " +
                                         new_v + " (another major version may keep other state)",
                                     ""});
      else if (old_v != new_v)
        ck.allowed_changes.push_back("subdomain '" + sd + "', " + slot + " model version " + old_v + " -> " + new_v);
    }
  }
  // The controllers and the fluid coupler: their saved state is their own
  // format, so another major version is refused too.
  const nlohmann::json was_stateful = ck.header.value("stateful_models", nlohmann::json::object());
  const nlohmann::json& now_stateful = sim.stateful_models;
  for (const auto& [where, m] : now_stateful.items()) {
    if (!was_stateful.contains(where)) continue;  // a scenario change, reported above
    const std::string old_v = was_stateful[where].value("version", std::string()), new_v = m.value("version", std::string());
    if (major_of(old_v) != major_of(new_v))
      refused.push_back(Diagnostic{sim.scenario_file.string(), "",
                                   where + " model '" + m.value("model", std::string()) +
                                       "': the checkpoint was written with version " + old_v + ", this run loads " +
                                       new_v + " (another major version may save its state differently)",
                                   ""});
    else if (old_v != new_v)
      ck.allowed_changes.push_back(where + " model version " + old_v + " -> " + new_v);
  }
  if (!refused.empty()) throw ConfigError(refused);

  const auto c = r.get<std::uint64_t>("loop/counters");
  const auto reals = r.get<double>("loop/reals");
  if (c.size() != 3 || reals.size() != 1) r.fail("loop/counters", "does not hold the run loop's state");
  ck.loop.macro_index = c[0];
  ck.loop.checkpoints = c[1];
  ck.loop.threads = static_cast<int>(c[2]);
  ck.loop.time = reals[0];
  // "ranks" since checkpoints under MPI; earlier files were written by one process
  const nlohmann::json ranks = ck.header.contains("ranks") ? ck.header["ranks"] : nlohmann::json(std::uint64_t{1});
  if (!ranks.is_number_integer() || ranks.get<std::int64_t>() < 1 || ranks.get<std::int64_t>() > (1 << 24))
    r.fail("", "has a header whose \"ranks\" is not a positive count");
  ck.loop.ranks = ranks.get<int>();
  return ck;
}

bool restore_checkpoint(const OpenedCheckpoint& ck, CheckpointWorld& sim, RunRanks& ranks) {
  bool same_split = true;
  const ArchiveReader& r = *ck.archive;
  // the servos' travel first: the subdomains place their walls with it
  if (!sim.servos.empty()) sim.servos.load(r, "servos/");
  for (std::size_t k = 0; k < sim.subdomains.size(); ++k) {
    const std::string p = sd_prefix(k);
    const std::uint64_t written_on = r.has(p + "ranks") ? r.scalar<std::uint64_t>(p + "ranks") : 1;
    const auto now = static_cast<std::uint64_t>(ranks.size());
    if (written_on != now) {
      // another rank count: every part read, the particles shared out anew
      std::vector<std::unique_ptr<ArchiveReader>> nested;
      std::vector<std::pair<const ArchiveReader*, std::string>> parts;
      if (written_on == 1) parts.emplace_back(&r, p);
      for (std::uint64_t q = 0; written_on > 1 && q < written_on; ++q) {
        const std::string key = p + "rank" + std::to_string(q);
        nested.push_back(std::make_unique<ArchiveReader>(r.text(key), r.path().string() + " (section '" + key + "')"));
        parts.emplace_back(nested.back().get(), "");
      }
      sim.subdomains[k]->restore_shared_out(parts);
      same_split = false;
      continue;
    }
    if (written_on == 1) {  // one process wrote the sections in place
      same_split = sim.subdomains[k]->restore(r, p) && same_split;
      continue;
    }
    const std::string key = p + "rank" + std::to_string(ranks.rank());
    const ArchiveReader part(r.text(key), r.path().string() + " (section '" + key + "')");
    same_split = sim.subdomains[k]->restore(part, "") && same_split;
  }
  sim.flow.restore(*ck.archive, "flow/", sim.subdomains);
  return same_split;
}

}  // namespace domel::platform
