// SPDX-License-Identifier: MIT
// Cell grids of a run spread over ranks (issue 19): every rank samples the
// same grid from every rank's particles and contact records, so that the
// grid's fields are the same on every rank (outputs, and the controllers
// and couplers that read them). The records name particles by index into
// the rank's own store; here they are re-indexed into the gathered one.
#pragma once

#include "averaging/cell_grid.hpp"
#include "core/particle_store.hpp"
#include "loop/ranks.hpp"

#include <vector>

namespace domel::platform {

class Subdomain;

/// The contact records of the last force evaluation on every rank (each pair
/// once: on the rank that computed it), indexed into `all`, which holds
/// every rank's particles of sd in id order (RunRanks::gather(sd, true)); in
/// rank order. Collective.
std::vector<ContactRecord> gather_contact_records(RunRanks& ranks, const Subdomain& sd, const ParticleStore& all);

}  // namespace domel::platform
