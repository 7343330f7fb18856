// SPDX-License-Identifier: MIT
// ParaView output of the walls (output.wall_surfaces): one VTK XML PolyData
// file (.vtp) per particle frame holding every wall primitive active at that
// time as polygons, placed where its motion has taken it, with the scenario
// wall's index as cell data and the surface velocity as point data;
// <basename>.pvd lists the frames. Unbounded primitives are drawn as far as
// WallPrimitive's drawing hints say (a box's face as its rectangle, a
// container's bottom as a disk), other planes clipped to the scene's box.
#pragma once

#include "geometry/wall.hpp"
#include "io/vtk_frames.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace domel::platform::io {

/// Polygons in flat arrays: points (x, y, z each), and per polygon its
/// first entry in `connectivity` (offsets has one more entry than polygons).
struct SurfacePolygons {
  std::vector<double> points;
  std::vector<std::int64_t> offsets{0};
  std::vector<std::int64_t> connectivity;
  std::vector<std::int32_t> wall;  ///< per polygon: the scenario wall
  std::size_t polygons() const { return offsets.size() - 1; }
};

/// Segments of a full circle when curved walls are drawn.
inline constexpr int kWallSegments = 64;

/// Append the surface of `w` (already placed at its time) to `out`. An
/// unbounded plane without drawing hints is clipped to the box [lo, hi]; an
/// annulus without an outer radius is drawn out to the box's farthest corner.
void append_wall_surface(const WallPrimitive& w, const double lo[3], const double hi[3], SurfacePolygons& out);

class WallSurfaceSeries {
 public:
  WallSurfaceSeries(std::filesystem::path directory, std::string basename);

  /// Writes the primitives of `base` (their time-0 state) that are active
  /// at `time`, placed at that time, as the next frame (cell data "wall",
  /// Int32; point data "velocity", the surface velocity [m/s]); [lo, hi] is
  /// the scene's box. Throws RuntimeError when a file cannot be written.
  std::filesystem::path write(double time, const std::vector<WallPrimitive>& base, const double lo[3],
                              const double hi[3]);

  std::vector<double> frame_times() const { return frames_.times(); }
  void resume(const std::vector<double>& times) { frames_.resume(times); }

 private:
  VtkFrames frames_;
};

}  // namespace domel::platform::io
