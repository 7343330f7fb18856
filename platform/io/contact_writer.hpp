// SPDX-License-Identifier: MIT
// ParaView output of the contacts (output.contacts): one VTK XML PolyData
// file (.vtp) per output time holding every contact of every subdomain as a
// line cell, from the centre of particle i to the centre of its partner j (a
// pair) or to the contact point on the wall, with the contact's forces,
// overlap and state as cell data, for force chains (Tube or Glyph filters in
// ParaView); <basename>.pvd lists the frames. Written like the particles'
// series (io/vtk_frames.hpp).
#pragma once

#include "io/vtk_frames.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace domel::platform::io {

/// One contact as it is written. The normal n points from j (or the wall)
/// to i; the force is the one on i (j receives the opposite).
struct ContactRow {
  double a[3];              ///< centre of i [m]
  double b[3];              ///< centre of j, or the contact point on the wall [m]
  double force[3];          ///< total contact force on i [N]
  double normal_force;      ///< F . n [N], > 0 pushes i away from j
  double tangential[3];     ///< F - (F . n) n [N]
  double overlap;           ///< R_i + R_j - |x_i - x_j|, or R_i - |x_i - contact point| [m]
  std::uint64_t id_i;       ///< particle id of i
  std::uint64_t id_j;       ///< particle id of j, kWallId for a wall
  std::int32_t subdomain;   ///< index of the subdomain
  std::int32_t wall;        ///< index of the scenario wall, -1 for a particle pair
  std::int32_t sliding;     ///< 1 when |F_t| has reached mu |F_n| (the Coulomb cap), else 0
  std::int32_t padding = 0;
  static constexpr std::uint64_t kWallId = ~std::uint64_t{0};
};

class ContactSeriesWriter {
 public:
  ContactSeriesWriter(std::filesystem::path directory, std::string basename);

  /// Writes the rows as the next frame at simulated `time` (cell data:
  /// "force", "tangential_force" (3 comp.), "normal_force", "overlap"
  /// (double), "id_i", "id_j" (UInt64), "subdomain", "wall", "sliding"
  /// (Int32); two points per line) and rewrites the .pvd. Throws
  /// RuntimeError when a file cannot be written.
  std::filesystem::path write(double time, const std::vector<ContactRow>& rows);

  std::vector<double> frame_times() const { return frames_.times(); }
  void resume(const std::vector<double>& times) { frames_.resume(times); }

 private:
  VtkFrames frames_;
};

}  // namespace domel::platform::io
