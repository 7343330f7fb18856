// SPDX-License-Identifier: MIT
// What the contacts of one output time give the outputs: the load on walls
// (output.wall_loads: force and torque about an axis, in probes.csv) and the
// contact rows of output.contacts (io/contact_writer.hpp). The run loop asks
// every subdomain to record its contact forces in the last step before an
// output time (Subdomain::set_record_contacts) and hands them to take(); the
// outputs written at that time read the sample. A sample belongs to one
// time; asked for another, the wall loads are NaN and no contact frame is
// written. As a run component it decides before every macro step's steps
// whether an output at its end reads the sample (the cadences it was given
// by wanted_at()), has each subdomain record its last step's contacts then,
// and takes them; its wall-load columns go to probes.csv.
#pragma once

#include "averaging/cell_grid.hpp"
#include "core/archive.hpp"
#include "core/particle_store.hpp"
#include "geometry/wall.hpp"
#include "io/contact_writer.hpp"
#include "flow/particle_flow.hpp"
#include "loop/component.hpp"

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace domel::platform {

class Subdomain;

/// output.wall_loads[k]: the load the particles put on one scenario wall.
struct WallLoadProbe {
  std::string name;                        ///< column prefix (the wall's name)
  std::size_t wall = 0;                    ///< index of the scenario wall
  std::size_t subdomain = kAllSubdomains;  ///< the only subdomain counted, or all
  bool has_axis = false;                   ///< the torque column is written
  double point[3] = {0, 0, 0};             ///< a point on the torque axis [m]
  double axis[3] = {0, 0, 1};              ///< its unit direction
};

class ContactSample final : public Component, public ProbeSource {
 public:
  void configure(std::vector<WallLoadProbe> probes, bool rows);
  bool enabled() const { return !probes_.empty() || rows_wanted_; }
  bool has_probes() const { return !probes_.empty(); }
  bool wants_rows() const { return rows_wanted_; }
  const std::vector<WallLoadProbe>& probes() const { return probes_; }

  /// The probes' columns of probes.csv: <name>.force_x, .force_y, .force_z
  /// [N], and <name>.torque [N m] when the probe has an axis.
  std::vector<std::string> columns() const;

  /// Start the sample of time t (forgetting the last one).
  void begin(double t);
  /// Add subdomain k's contacts of its last force evaluation (recorded:
  /// Subdomain::set_record_contacts) at the sample's time. `walls` are the
  /// scenario's wall primitives, as the subdomain indexes them.
  void take(std::size_t k, const Subdomain& sd, const std::vector<WallPrimitive>& walls);
  /// The same from particles `s` and their contact records (a subdomain
  /// spread over ranks: every rank's particles and records, gathered;
  /// RunRanks::contact_records); sd gives the material pairs.
  void take(std::size_t k, const Subdomain& sd, const ParticleStore& s,
            const std::vector<const std::vector<ContactRecord>*>& records, const std::vector<WallPrimitive>& walls);

  /// Append the probes' values at time t to a probes.csv row: the sample's
  /// when it was taken at t (within `tolerance` s), NaN otherwise.
  void append_values(double t, double tolerance, std::vector<double>& row) const;
  /// The contact rows of the sample at t, or null when it was not taken at t.
  const std::vector<io::ContactRow>* rows_at(double t, double tolerance) const;

  /// Checkpoints: the sample held for the next outputs (taken at the end of
  /// the macro step before the checkpoint, written after it).
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load (core/archive.hpp).
  void fields(CheckpointFields& f);

  // Component
  /// An output whose due ticks (macro steps) read the sample: the probes'
  /// rows (when there are wall-load probes) and the contact frames.
  void wanted_at(const Cadence* outputs) { wanted_at_.push_back(outputs); }
  unsigned points() const override { return enabled() ? kBeforeSteps | kStep : 0u; }
  std::string section() const override { return enabled() ? "contacts/" : ""; }
  /// A fresh run: every subdomain records its first force evaluation's contacts...
  void init(RunContext& ctx) override;
  /// ...which are the sample of t = 0.
  void setup(RunContext& ctx) override;
  void before_steps(RunContext& ctx, const MacroStep& step) override;
  bool records_contacts(std::size_t, bool last) const override { return sampling_ && last; }
  void after_step(RunContext& ctx, std::size_t k, bool last) override;
  void load(RunContext&, const ArchiveReader& r, const std::string& prefix) override { load(r, prefix); }
  void probe_columns(std::vector<std::string>& names) const override;
  void probe_values(RunContext& ctx, double t, std::vector<double>& row) override;

 private:
  /// Subdomain k's contacts of its last step, on ranks from every rank's
  /// particles and records (gathered on every rank: a servo moves its wall
  /// alike on all).
  void take(RunContext& ctx, std::size_t k);
  std::vector<const Cadence*> wanted_at_;
  bool sampling_ = false;  ///< this macro step's last steps record for the sample
  std::vector<WallLoadProbe> probes_;
  bool rows_wanted_ = false;
  double time_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sums_;  ///< per probe: force x, y, z on the wall, torque about its axis
  std::vector<io::ContactRow> rows_;
};

}  // namespace domel::platform
