// SPDX-License-Identifier: MIT
// The ParaView frames of a run (output.vtk_interval): every particle of
// every subdomain in particles_<n>.vtp / particles.pvd, and with
// output.wall_surfaces the walls placed at each frame's time in walls.pvd
// (io/vtk_writer.hpp, io/wall_surfaces.hpp). Spread over ranks, every rank
// takes part in the gather of a frame and rank 0 writes it.
#pragma once

#include "core/archive.hpp"
#include "io/vtk_writer.hpp"
#include "io/wall_surfaces.hpp"
#include "loop/component.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

class ProbesOutput;

class ParticleFrames final : public Component {
 public:
  /// `interval` [s] between frames (0: none); `materials` the scenario's
  /// material names; `walls` with wall surfaces, drawn within [lo, hi] where
  /// unbounded; `probes` is flushed after every frame, so probes.csv
  /// reaches it (may be null).
  ParticleFrames(double interval, std::vector<std::string> materials, bool walls, std::array<double, 3> lo,
                 std::array<double, 3> hi, ProbesOutput* probes)
      : interval_(interval), materials_(std::move(materials)), wall_surfaces_(walls), lo_(lo), hi_(hi),
        probes_(probes) {}

  unsigned points() const override { return kOutput; }
  std::string section() const override { return "frames/"; }
  void setup(RunContext& ctx) override;
  void output(RunContext& ctx, const MacroStep& step) override;
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  /// The frame index and period, and both series' frame times.
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) override;

 private:
  /// Both directions of the checkpoint (core/archive.hpp); `first`: a restart's macro step.
  void fields(CheckpointFields& f, std::uint64_t first);
  double interval_;
  std::vector<std::string> materials_;
  bool wall_surfaces_;
  std::array<double, 3> lo_, hi_;
  ProbesOutput* probes_;
  Cadence frames_;
  std::unique_ptr<io::VtkSeriesWriter> vtk_;
  std::unique_ptr<io::WallSurfaceSeries> walls_;
};

}  // namespace domel::platform
