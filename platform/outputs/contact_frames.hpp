// SPDX-License-Identifier: MIT
// output.contacts: the contacts of the sample (contact_sample.hpp) as
// force-chain frames, contacts_<n>.vtp / contacts.pvd, every contact
// interval (io/contact_writer.hpp).
#pragma once

#include "core/archive.hpp"
#include "io/contact_writer.hpp"
#include "loop/component.hpp"

#include <memory>

namespace domel::platform {

class ContactSample;

class ContactFrames final : public Component {
 public:
  /// `interval` [s] between frames (0: none), of `sample`'s rows.
  ContactFrames(double interval, ContactSample& sample) : interval_(interval), sample_(sample) {}

  unsigned points() const override { return kOutput; }
  std::string section() const override { return "contact_frames/"; }
  void setup(RunContext& ctx) override;
  void output(RunContext& ctx, const MacroStep& step) override;
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(RunContext& ctx, const ArchiveReader& r, const std::string& prefix) override;

  /// The frames' cadence (the contact sample records for them).
  const Cadence& cadence() const { return frames_; }

 private:
  /// Both directions of the checkpoint (core/archive.hpp); `first`: a restart's macro step.
  void fields(CheckpointFields& f, std::uint64_t first);
  double interval_;
  ContactSample& sample_;
  Cadence frames_;  ///< on every rank: it decides a gather
  std::unique_ptr<io::ContactSeriesWriter> vtk_;
};

}  // namespace domel::platform
