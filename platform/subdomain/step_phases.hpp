// SPDX-License-Identifier: MIT
// The named phases of a subdomain's time step and their hook lists.
//
// A step runs these phases in this order (as LAMMPS' Verlet::run names the
// points of its step, for the same reasons):
//
//   initial_integrate  first half kick + drift, then the neighbour-list check
//   exchange           only on steps that rebuild the lists: migration
//                      between processes (empty on one rank) ...
//   neighbor           ... and the rebuild of the pair and wall lists
//   ghost_update       forward exchange of ghost particles (empty for now)
//   body_force         the body-force list: gravity, the external force array
//   contact_force      particle pairs and walls
//   reverse_exchange   ghost forces home (empty for now)
//   post_force         the forces are complete: controllers, fluid drag
//   final_integrate    second half kick
//   end_of_step        the step is complete
//
// A hook registered on a phase runs after the phase's own work. With every
// list empty the subdomain takes its fused, deferred fast path (which is the
// body-force list holding gravity and the external forces, and nothing
// else); once any hook is registered, each step completes in this order
// before the next starts. The scheduler's per-macro-step hooks live in
// scheduler/ (before and after each macro step of all subdomains).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace domel::platform {

class Subdomain;
struct ParticleStore;

enum class Phase : int {
  initial_integrate = 0,
  exchange,
  neighbor,
  ghost_update,
  body_force,
  contact_force,
  reverse_exchange,
  post_force,
  final_integrate,
  end_of_step,
};
constexpr std::size_t kPhaseCount = 10;
constexpr const char* kPhaseNames[kPhaseCount] = {
    "initial_integrate", "exchange",         "neighbor",   "ghost_update",    "body_force",
    "contact_force",     "reverse_exchange", "post_force", "final_integrate", "end_of_step"};

/// What a hook sees: the subdomain and its particles as they are at the
/// phase (`store` is the subdomain's store without the synchronisation and
/// contact counting of Subdomain::store(), which a hook does not need), the
/// step's index (0 for the first step) and the time the step ends at, which
/// is the time of its force evaluation.
struct StepContext {
  Subdomain& subdomain;
  ParticleStore& store;
  std::uint64_t step;
  double time;
  double dt;
  Phase phase;
};

/// A named hook: the name appears in error messages and logs.
struct StepHook {
  std::string name;
  std::function<void(StepContext&)> run;
};

/// The hook lists of one subdomain, one per phase.
class StepHooks {
 public:
  void add(Phase p, StepHook hook) {
    lists_[static_cast<std::size_t>(p)].push_back(std::move(hook));
    ++count_;
  }
  bool empty() const { return count_ == 0; }
  const std::vector<StepHook>& at(Phase p) const { return lists_[static_cast<std::size_t>(p)]; }

 private:
  std::array<std::vector<StepHook>, kPhaseCount> lists_;
  std::size_t count_ = 0;
};

}  // namespace domel::platform
