// SPDX-License-Identifier: MIT
// The run's clock: the macro step (the largest subdomain step; finer
// subdomains sub-cycle within it) and where the loop stands in it.
#pragma once

#include "core/cadence.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace domel::platform {

class Subdomain;

/// The macro step of a set of subdomains: the largest time step.
double macro_step_of(const std::vector<std::unique_ptr<Subdomain>>& subdomains);

/// Sub-steps of a subdomain of time step dt within a macro step: rounded up,
/// so that no step grows (the subdomain then steps with macro / n).
int substeps_of(double macro, double dt);

/// Where the loop stands: the simulated time at the point (the macro step's
/// start for before_macro, output and before_steps, its end for
/// after_macro), the macro step's index m and length. One object lives for
/// the whole run and is updated in place.
struct MacroStep {
  double t = 0;               ///< [s]
  double macro = 0;           ///< [s] the macro step
  std::uint64_t index = 0;    ///< m: the macro step that starts, or has ended (after_macro)
  bool last = false;          ///< the final time: outputs only, no step follows
  std::vector<std::unique_ptr<Subdomain>>* subdomains = nullptr;
};

}  // namespace domel::platform
