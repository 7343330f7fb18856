// SPDX-License-Identifier: MIT
// Output of the Eulerian cell averages (averaging/cell_grid.hpp): a ParaView
// time series of VTK ImageData files (.vti, one per output time, the fields
// as cell data) with a .pvd collection, and a CSV of the layer profile along
// one axis (one row per layer per output time) for "pressure over height"
// plots. Every file is replaced atomically, like the particle series
// (io/vtk_writer.hpp), so both can be opened while the run goes on.
#pragma once

#include "io/vtk_frames.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "averaging/cell_grid.hpp"
#include "io/csv_series.hpp"

namespace domel::platform::io {

/// ParaView grid series: <dir>/<basename>_<000000>.vti plus <dir>/<basename>.pvd.
/// The directory is created (with parents) on the first write.
class CellGridVtkSeries {
 public:
  /// Throws std::invalid_argument if `basename` is empty or contains a '/'.
  CellGridVtkSeries(std::filesystem::path directory, std::string basename);

  /// Writes one .vti: an image with the grid's origin (lo), spacing (cell
  /// size) and cells, cell-data arrays "count", "count_fixed", "mass",
  /// "volume_fraction", "velocity" (3 components), "pressure", "stress" and
  /// "stress_kinetic" (9 components, row-major, > 0 in compression),
  /// "accessible"; field data "TimeValue" and "samples". Binary appended,
  /// zlib-compressed, written under a temporary name then renamed; then the
  /// .pvd listing every file so far is rewritten atomically. Throws
  /// std::invalid_argument when `f` does not fit the grid, RuntimeError when
  /// a file cannot be written. Returns the path of the .vti.
  std::filesystem::path write(double time, const CellGrid& grid, const CellFields& f);

  std::size_t files_written() const { return frames_.size(); }
  /// Checkpoints: the frames' times, and continuing the series (VtkFrames::resume).
  std::vector<double> frame_times() const { return frames_.times(); }
  void resume(const std::vector<double>& times) { frames_.resume(times); }

 private:
  std::filesystem::path directory_;
  std::string basename_;
  VtkFrames frames_;
};

/// A uniform grid's cell fields for FieldImageSeries: cell (ix, iy, iz) has
/// index ix + nx (iy + ny iz); a field of c components holds c values per
/// cell, interleaved.
struct FieldImage {
  std::array<std::uint32_t, 3> cells{0, 0, 0};
  double origin[3] = {0, 0, 0};   ///< [m]
  double spacing[3] = {0, 0, 0};  ///< [m]
  struct Field {
    std::string name;
    int components = 1;
    const double* data = nullptr;
  };
  std::vector<Field> fields;
};

/// ParaView series of any uniform grid's cell fields (a fluid coupler's):
/// <dir>/<basename>_<000000>.vti plus <dir>/<basename>.pvd, written as
/// CellGridVtkSeries writes its frames.
class FieldImageSeries {
 public:
  FieldImageSeries(std::filesystem::path directory, std::string basename);
  /// Throws std::invalid_argument when the grid has no cells, RuntimeError
  /// when a file cannot be written. Returns the path of the .vti.
  std::filesystem::path write(double time, const FieldImage& image);
  std::size_t files_written() const { return frames_.size(); }
  /// The frames so far, and a restart's continuation of them (VtkFrames).
  std::vector<double> frame_times() const { return frames_.times(); }
  void resume(const std::vector<double>& times) { frames_.resume(times); }

 private:
  std::filesystem::path directory_;
  VtkFrames frames_;
};

/// The layer profile as a CSV time series, <dir>/<name>_profile.csv, columns
/// time, layer, centre, accessible_volume, count, volume_fraction, pressure,
/// vx, vy, vz (SI units; see LayerProfile). The directory is created on the
/// first write; the file is rewritten atomically after every write().
class CellGridProfileCsv {
 public:
  /// Throws std::invalid_argument for an axis other than 0, 1, 2.
  CellGridProfileCsv(std::filesystem::path directory, const std::string& name, int axis = 2);

  /// Appends one row per layer of grid.profile(f, axis) and flushes.
  void write(double time, const CellGrid& grid, const CellFields& f);

  const std::filesystem::path& path() const { return path_; }
  /// Checkpoints: the file's length, and continuing it (CsvSeries::resume).
  std::size_t size() const { return csv_.size(); }
  void resume(std::size_t bytes) { csv_.resume(bytes); }

 private:
  std::filesystem::path directory_;
  std::filesystem::path path_;
  int axis_;
  CsvSeries csv_;
};

}  // namespace domel::platform::io
