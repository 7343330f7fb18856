// SPDX-License-Identifier: MIT
// The built-in fluid-coupler library: "vans" (vans.hpp), the unresolved
// CFD-DEM coupler. Built like a third-party plugin, against sdk/ only (plus
// the header-only Eigen for its pressure solve).
#include "plugins/fluid/vans.hpp"

DOMEL_PLUGIN_LIBRARY("domel_fluid_std", "0.2.0", domel::plugins::fluid::Vans)
