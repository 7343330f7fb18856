// SPDX-License-Identifier: MIT
// The built-in contact-law library. Registration table: to add a model, write
// its header (class + schema + kernel) and add one row below.
#include "hertz.hpp"
#include "linear_normal.hpp"
#include "linear_tangential.hpp"
#include "mindlin.hpp"
#include "restitution_damping.hpp"

DOMEL_PLUGIN_LIBRARY("domel_contact_std", "1.0.0",
                     domel::plugins::contact::Hertz,              // normal
                     domel::plugins::contact::LinearNormal,       // normal
                     domel::plugins::contact::RestitutionDamping, // damping
                     domel::plugins::contact::Mindlin,            // tangential
                     domel::plugins::contact::LinearTangential)   // tangential
