// SPDX-License-Identifier: MIT
// The built-in insertion library. Registration table: to add a model, write
// its header (class + schema + insert) and add it to the list below.
#include "lattice.hpp"
#include "random_fill.hpp"

DOMEL_PLUGIN_LIBRARY("domel_insertion_std", "1.3.0", domel::plugins::insertion::Lattice,
                     domel::plugins::insertion::RandomFill)
