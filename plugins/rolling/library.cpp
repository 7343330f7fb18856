// SPDX-License-Identifier: MIT
// The built-in rolling-resistance library. Registration table: to add a
// model, write its header (class + schema + kernel) and add one row.
#include "dct.hpp"
#include "sd_critical_angle.hpp"

DOMEL_PLUGIN_LIBRARY("domel_rolling_std", "1.0.0",
                     domel::plugins::rolling::SdCriticalAngle,  // rolling
                     domel::plugins::rolling::Dct)              // rolling
