// SPDX-License-Identifier: MIT
// Checkpoints of a run (docs/checkpoint.md): what the run loop itself keeps
// (the macro step reached, the output schedules, how far its files got), the
// header that says which run wrote the file, and the comparison of a
// restarted run's scenario with the checkpointed one: changes that cannot
// alter the state are listed, the others refused with their JSON pointer.
#pragma once

#include "core/archive.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

class PluginRegistry;
class RunRanks;
class Subdomain;
class WallServos;
class ParticleFlow;

/// The checkpoint file's name in the output folder.
inline constexpr const char* kCheckpointFile = "checkpoint.ckpt";

/// The run loop's own state at the start of macro step `macro_index`,
/// before its components act; each component keeps its own (its section).
struct LoopState {
  std::uint64_t macro_index = 0;
  double time = 0;               ///< [s] macro_index x macro step
  std::uint64_t checkpoints = 0;  ///< the checkpoints' cadence index (core/cadence.hpp)
  int threads = 1;
  int ranks = 1;  ///< the processes the run was spread over (header "ranks")
};

/// What a checkpoint holds of a run besides its components' sections (the
/// world: servo walls, subdomains, the particle flow's books), and what a
/// restart's scenario is compared with (Simulation::world()).
struct CheckpointWorld {
  const std::string& name;
  const std::filesystem::path& scenario_file;
  const nlohmann::json& document;     ///< the validated scenario, defaults filled
  const nlohmann::json& models_used;  ///< per subdomain: slot -> {model, version, library}
  /// "where" -> {model, version, library} of the models that save their own
  /// state (each coupling's controllers, the fluid coupler)
  nlohmann::json stateful_models;
  std::vector<std::unique_ptr<Subdomain>>& subdomains;
  WallServos& servos;
  ParticleFlow& flow;
};

/// Write `file` atomically: the header, the loop state and the world (the
/// servo walls' travel, every subdomain, the particle flow's books).
/// Finishes every subdomain's pending step first. `extra` adds the
/// components' sections (Simulation::run).
///
/// One process writes each subdomain's sections in place. Spread over
/// ranks (`ranks`), every rank calls it: each subdomain is
/// written as one part per rank (that rank's own particles, ghosts, lists
/// and exchange), gathered to rank 0, which writes the file; what every rank
/// holds alike (the loop, the servos, the flow, `extra`) is rank 0's.
void write_checkpoint(const std::filesystem::path& file, CheckpointWorld& sim, const LoopState& loop,
                      const PluginRegistry& registry, const std::function<void(ArchiveWriter&)>& extra,
                      RunRanks& ranks);

/// A checkpoint opened for a restart and checked against the scenario.
struct OpenedCheckpoint {
  std::unique_ptr<ArchiveReader> archive;
  LoopState loop;
  nlohmann::json header;
  std::vector<std::string> allowed_changes;  ///< "pointer: old -> new", safe ones
};

/// Open `file` and compare it with `sim` (built from the scenario to run):
/// throws ConfigError naming the file and every difference that would make
/// the checkpoint's state wrong for this scenario (another material, contact
/// model or plugin major version, coarse-grain ratio, time step, walls,
/// pours ...). Changes of the end time, output intervals, threads, output
/// folder and checkpoint interval are allowed and listed.
OpenedCheckpoint open_checkpoint(const std::filesystem::path& file, const CheckpointWorld& sim);

/// Restore every subdomain and the particle flow from an opened checkpoint
/// (instead of Subdomain::setup() and ParticleFlow::start()). Returns false
/// when some subdomain's thread split could not be restored (another thread
/// count): the run then differs from the uninterrupted one by round-off.
/// Spread over ranks, every rank restores its own part of each subdomain
/// (a checkpoint of the same rank count: the run goes on bit for bit).
bool restore_checkpoint(const OpenedCheckpoint& ck, CheckpointWorld& sim, RunRanks& ranks);

}  // namespace domel::platform
