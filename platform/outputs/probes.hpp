// SPDX-License-Identifier: MIT
// probes.csv (output.probe_interval): one row every probe interval, the
// time, every subdomain's statistics (particles, kinetic energies, angular
// speeds, overlap, contacts) and then the columns of the probe sources the
// builder gave it, in that order: the repose angle, region masses, the
// particle flow's deletion and plane rates, wall loads and servo walls.
#pragma once

#include "core/archive.hpp"
#include "io/csv_series.hpp"
#include "loop/component.hpp"

#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

/// The unit of a probes.csv column ("s", "J", "rad/s", "kg", "1" for counts
/// and ratios ...), "" for a column it does not know.
std::string probe_column_unit(const std::string& column);

class ProbesOutput final : public Component {
 public:
  /// `interval` [s] between rows (0: no probes.csv); `sources` add their
  /// columns after the subdomains' statistics, in this order.
  ProbesOutput(double interval, std::vector<ProbeSource*> sources)
      : interval_(interval), sources_(std::move(sources)) {}

  unsigned points() const override { return kOutput; }
  std::string section() const override { return "probes/"; }
  void setup(RunContext& ctx) override;
  void output(RunContext& ctx, const MacroStep& step) override;
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  /// The row index and period, and how far probes.csv got (its last flush).
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) override;

  /// The rows' cadence (the contact sample records for the rows that read it).
  const Cadence& cadence() const { return rows_; }
  bool enabled() const { return interval_ > 0; }
  /// Put the rows written so far into the file (a frame was just written).
  void flush() {
    if (file_) file_->flush();
  }

 private:
  /// Both directions of the checkpoint (core/archive.hpp); `first`: a restart's macro step.
  void fields(CheckpointFields& f, std::uint64_t first);
  double interval_;
  std::vector<ProbeSource*> sources_;
  Cadence rows_;
  std::unique_ptr<io::CsvSeries> file_;
};

}  // namespace domel::platform
