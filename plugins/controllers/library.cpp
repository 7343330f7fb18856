// SPDX-License-Identifier: MIT
// The built-in controller library. Registration table: to add a model, write
// its header (class + schema + control) and add one row. Both models take
// levels[0] as the FINE level and levels[1] as the COARSE level, on grids of
// the same geometry (docs/controllers.md).
#include "stress_pi.hpp"
#include "velocity_p.hpp"

DOMEL_PLUGIN_LIBRARY("domel_controller_std", "1.1.0",
                     domel::plugins::controller::StressPi,   // controller: fine <- coarse, stress PI
                     domel::plugins::controller::VelocityP)  // controller: coarse <- fine, velocity P(I)
