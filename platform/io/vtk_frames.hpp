// SPDX-License-Identifier: MIT
// One ParaView time series on disk: frames <basename>_<NNNNNN>.<ext> written
// through any VTK XML writer (binary appended, zlib, under a temporary name
// then renamed, so a reader never sees half a file) and the .pvd collection
// that lists them, rewritten atomically after every frame. Shared by the
// particle series (vtk_writer) and the cell-grid series (cell_grid_output).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

class vtkXMLWriter;

namespace domel::platform::io {

class VtkFrames {
 public:
  VtkFrames(std::filesystem::path directory, std::string basename, std::string extension);

  /// Write the writer's input as the next frame at simulated `time` and
  /// rewrite <basename>.pvd. The writer's input must be set; its file name
  /// and encoding are set here; the directory is created (with parents) if
  /// it does not exist. Throws RuntimeError when a file cannot be
  /// written. Returns the frame's path.
  std::filesystem::path write(vtkXMLWriter& writer, double time);

  std::size_t size() const { return frames_.size(); }
  /// The frames' times, in order (checkpoints).
  std::vector<double> times() const;
  /// Continue a series of which the first times.size() frames are on disk
  /// (a restart): the .pvd is rewritten to list them alone, and frames of a
  /// later number left by the interrupted run are removed.
  void resume(const std::vector<double>& times);
  const std::filesystem::path& directory() const { return directory_; }

 private:
  struct Frame {
    double time;
    std::string file;  ///< relative to directory_
  };
  void write_collection() const;
  std::string frame_name(std::size_t k) const;

  std::filesystem::path directory_;
  std::string basename_;
  std::string extension_;
  std::vector<Frame> frames_;
};

}  // namespace domel::platform::io
