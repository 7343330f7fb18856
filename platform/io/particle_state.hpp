// SPDX-License-Identifier: MIT
// Particle state files: every particle of one subdomain as CSV, written at
// full precision at the end of a run (`output.state`) and read back as the
// starting particles of a later run (`subdomains[k].initial_state`). The
// use: settle a bed once, then start many runs (a benchmark, a parameter
// study) from the settled bed, as LIGGGHTS' write_data/read_data are used.
// Contact history is not stored: tangential springs and rolling springs of
// the restarted run start from zero, as after a LIGGGHTS read_data.
//
// Format (v1): comment lines start with '#'; the first non-comment line is
// the header "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed"; then one row per
// particle. Units SI (m, m/s, rad/s); radius is the parcel radius (the
// subdomain's coarse-grain ratio already applied); fixed is 0 or 1. Numbers
// are written with 17 significant digits, so a write/read round trip is
// exact. A subdomain of several materials (a mixture) writes v2: a 13th
// column "material", the particle's material by name
// ("id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed,material"); a v1 file's
// particles are of the reading subdomain's own material.
#pragma once

#include "core/particle_store.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace domel::platform::io {

struct ParticleStateRow {
  std::uint64_t id = 0;
  double x = 0, y = 0, z = 0, radius = 0;
  double vx = 0, vy = 0, vz = 0, wx = 0, wy = 0, wz = 0;
  bool fixed = false;
  std::string material;  ///< v2: the material's name; v1: empty (the subdomain's own)
};

/// The file's text for the particles of `store` (header comments name the
/// subdomain, the simulated time and the coarse-grain ratio). With more
/// than one name in `materials` (the names of ParticleStore::material's
/// indices) the file is v2, with each particle's material.
std::string format_particle_state(const ParticleStore& store, const std::string& subdomain, double time,
                                  double coarse_grain, const std::vector<std::string>& materials = {});

/// Write format_particle_state() to `path`, whole or not at all.
void write_particle_state(const std::filesystem::path& path, const ParticleStore& store,
                          const std::string& subdomain, double time, double coarse_grain,
                          const std::vector<std::string>& materials = {});

/// Read a state file. Throws std::runtime_error "<file>:<line>: <what was
/// expected>, found '<text>'" on the first bad line: a missing or different
/// header, a wrong column count, a number that does not parse or is not
/// finite, a radius <= 0, a fixed flag other than 0/1.
std::vector<ParticleStateRow> read_particle_state(const std::filesystem::path& path);

/// The number of lines of a file (an upper bound of its particle rows).
std::size_t count_lines(const std::filesystem::path& path);

/// The same checks, streaming: visit(row) for each particle in file order,
/// with no copy of the whole file in memory. Returns the number of rows.
std::size_t for_each_particle_state_row(const std::filesystem::path& path,
                                        const std::function<void(const ParticleStateRow&)>& visit);

}  // namespace domel::platform::io
