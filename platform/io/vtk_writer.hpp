// SPDX-License-Identifier: MIT
// ParaView output of the particles: one VTK XML PolyData file (.vtp) per
// output time, holding every particle of every subdomain as a vertex with its
// velocity, angular velocity, force, torque, radius, mass, id, subdomain,
// material and contact count, plus a
// .pvd collection file that lists the frames with their times so ParaView
// opens the whole series as one time-dependent data set. Both files are
// replaced atomically, so the series can be opened while the run goes on.
#pragma once

#include "io/vtk_frames.hpp"

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/particle_store.hpp"

namespace domel::platform::io {

/// One subdomain's particles.
struct ParticleSet {
  const ParticleStore* store;
  int subdomain;
  /// the subdomain's materials as indices into the scenario's
  /// (ParticleStore::material is a position in this list); null: all 0
  const std::vector<std::size_t>* materials = nullptr;
};

/// ParaView particle time series: <dir>/<basename>_<000000>.vtp files plus
/// <dir>/<basename>.pvd index. The directory is created (with parents) on the
/// first write if it does not exist.
class VtkSeriesWriter {
 public:
  /// Throws std::invalid_argument if `basename` is empty or contains a '/'.
  VtkSeriesWriter(std::filesystem::path directory, std::string basename);

  VtkSeriesWriter(const VtkSeriesWriter&) = delete;
  VtkSeriesWriter& operator=(const VtkSeriesWriter&) = delete;
  VtkSeriesWriter(VtkSeriesWriter&&) = default;
  VtkSeriesWriter& operator=(VtkSeriesWriter&&) = default;

  /// Writes one .vtp with all particles of all sets (in order) as vertices,
  /// point-data arrays "velocity" (3 comp, double), "angular_velocity" (3),
  /// "force" (3, the total of the last force evaluation: body forces,
  /// contacts, controllers, fluid), "torque" (3), "radius", "mass" (double),
  /// "id" (UInt64), "subdomain", "material", "contacts" (Int32).
  /// Binary appended, zlib-compressed. The .vtp is written under a temporary
  /// name in the same directory then renamed; then the .pvd is rewritten
  /// atomically, listing every file written so far (relative names).
  /// Throws std::invalid_argument for a null store, RuntimeError when a store's
  /// arrays have inconsistent lengths or a file cannot be written. A frame
  /// counts as written once its .vtp is in place, even if the .pvd update
  /// then fails (the next successful write lists it).
  /// Returns the path of the .vtp written.
  std::filesystem::path write(double time, const std::vector<ParticleSet>& sets);

  /// The scenario's material names by index: written as field data
  /// "material_names" (a string array) with every frame, so that the
  /// `material` point array can be read without the scenario.
  void set_material_names(std::vector<std::string> names) { material_names_ = std::move(names); }

  /// Number of .vtp files written so far by this writer.
  std::size_t files_written() const { return frames_.size(); }
  /// Checkpoints: the frames' times, and continuing the series (VtkFrames::resume).
  std::vector<double> frame_times() const { return frames_.times(); }
  void resume(const std::vector<double>& times) { frames_.resume(times); }

 private:
  std::filesystem::path directory_;
  std::string basename_;
  VtkFrames frames_;
  std::vector<std::string> material_names_;
};

}  // namespace domel::platform::io
