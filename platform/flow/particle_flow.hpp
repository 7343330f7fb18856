// SPDX-License-Identifier: MIT
// Particles entering and leaving a run, and the mass balance that checks it:
//   - pours: insertion during the run from a region at a mass rate (a silo
//     fill), through the same insertion plugins as the start-up insertion;
//   - deletion regions: particles whose centre enters the region are removed
//     and their mass is counted (a silo outlet);
//   - mass-flow planes: the net mass whose centres crossed a plane;
//   - the mass balance per subdomain, inserted - present - removed, kept in
//     integer units of 1e-18 kg so that it is exact (no round-off): every
//     particle's mass is quantised once, from the same double, on the way in,
//     on the way out and while present.
// Everything here runs between steps, never inside one: a pour or a removal
// changes the store's layout, and the subdomain rebuilds its neighbour list
// at its next step (ParticleStore::layout_version). Checks are therefore
// batched at an interval (deletion regions: run.deletion_interval) so that a
// steady outflow costs one list build per interval, not one per particle.
#pragma once

#include "loader/plugin_registry.hpp"
#include "loop/macro_step.hpp"
#include "loop/component.hpp"
#include "loop/ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace domel::platform {

class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

/// Candidate particles an insertion model placed (parcel radii, alpha
/// applied); for a mixture, each one's component (else empty).
struct InsertionCandidates {
  std::vector<double> x, y, z, r;
  std::vector<std::uint32_t> component;
  std::size_t size() const { return x.size(); }
};

/// The materials of an insertion's particles: one, or one per component of
/// a mixture ("distribution": {"type": "mixture"}), local to the subdomain,
/// with their densities.
struct InsertedMaterials {
  std::vector<std::uint8_t> material;
  std::vector<double> density;  ///< [kg/m^3]
  bool mixture() const { return material.size() > 1; }
  /// Candidate q's material and density.
  std::uint8_t material_of(const InsertionCandidates& c, std::size_t q) const {
    return c.component.empty() ? material[0] : material[c.component[q]];
  }
  double density_of(const InsertionCandidates& c, std::size_t q) const {
    return c.component.empty() ? density[0] : density[c.component[q]];
  }
};

/// The one way the platform asks an insertion model for particles, for the
/// start-up insertion and for pours alike: fill `region` with the model's
/// particles, radii scaled by alpha, avoiding the particles of `present`
/// (none when null), with `seed`, at most `max_count` of them (the
/// scenario's run.max_particles; 0: no limit). Throws PluginError when the
/// model fails or would place more. Along the periodic axes of `box` the
/// new particles keep clear of the present ones' images too. With
/// `components`, the model says each particle's mixture component.
InsertionCandidates request_insertion(const ModelInstance& model, const domel_region_v1& region, std::uint64_t seed,
                                      double alpha, const ParticleStore* present, std::size_t max_count,
                                      const PeriodicBox& box = {}, bool components = false);

/// Drop the candidates that would overlap a wall of `walls` (the reference
/// state of the scenario's walls) as they stand at time t: no particle is
/// placed in contact with a wall, whatever its kind (issue 41). Keeps the
/// order of the rest; returns how many it dropped.
std::size_t drop_wall_overlaps(InsertionCandidates& c, const std::vector<WallPrimitive>& walls, double t);

/// Exact mass in units of 1e-18 kg (sums in 128 bits).
using MassUnits = __int128;
MassUnits mass_units(double kg);
double mass_kg(MassUnits u);
/// Exact books in a checkpoint (core/archive.hpp, CheckpointFields): each
/// value as two 64-bit halves.
void mass_units_field(CheckpointFields& f, const std::string& key, std::vector<MassUnits>& v);

struct MassAccount {
  MassUnits inserted = 0;
  MassUnits removed = 0;
  std::uint64_t n_inserted = 0;
  std::uint64_t n_removed = 0;
};

/// A cumulative series sampled at the probe rows, with its rate.
struct FlowSeries {
  std::vector<double> t, value;
  /// least-squares slope of value(t) over [t0, t1] (NaN with fewer than 3 rows)
  double slope(double t0, double t1) const;
};

struct Pour {
  std::string where;        ///< JSON pointer of the block, for messages
  std::size_t subdomain = 0;
  std::shared_ptr<ModelInstance> model;
  domel_region_v1 region{};
  double velocity[3] = {0, 0, 0};
  bool fixed = false;
  InsertedMaterials materials;  ///< the particles' material(s), local to the subdomain
  double alpha = 1;
  double mass_rate = 0;     ///< [kg/s]
  double total_mass = std::numeric_limits<double>::infinity();  ///< [kg]
  double start = 0, end = std::numeric_limits<double>::infinity();  ///< [s]
  double interval = 0;      ///< [s] between insertion events
  std::uint64_t seed = 0;
  // state
  Cadence schedule;          ///< events due at start + k interval (set by ParticleFlow::start)
  std::uint64_t events = 0;
  std::uint64_t inserted = 0;
  double inserted_mass = 0;  ///< [kg]
  double shortfall = 0;      ///< [kg] largest deficit against the rate seen after an event
  bool warned = false;
};

/// Counts every subdomain's particles.
inline constexpr std::size_t kAllSubdomains = static_cast<std::size_t>(-1);

struct DeletionRegion {
  std::string name;
  std::size_t subdomain = kAllSubdomains;  ///< the only subdomain it removes from, or all
  domel_region_v1 region{};
  double rate_window[2] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  std::uint64_t removed = 0;
  double removed_mass = 0;  ///< [kg], all subdomains
  FlowSeries series;
};

struct MassFlowPlane {
  std::string name;
  std::size_t subdomain = kAllSubdomains;  ///< the only subdomain it counts, or all
  double p[3] = {0, 0, 0};
  double n[3] = {0, 0, 1};
  double rate_window[2] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  std::vector<std::unordered_map<std::uint64_t, signed char>> side;  ///< per subdomain: id -> side at the last check
  double mass = 0;          ///< [kg] net mass crossed along n
  std::int64_t count = 0;   ///< net particles crossed along n
  FlowSeries series;
};

/// A run component (loop/component.hpp): pours and checks before every
/// macro step, plane rates and books in probes.csv and summary.json. Its
/// books are part of the world a checkpoint holds with the subdomains
/// (save/restore, called by scheduler/checkpoint.cpp), not a component section.
class ParticleFlow final : public Component, public ProbeSource {
 public:
  std::vector<Pour> pours;
  std::vector<DeletionRegion> deletions;
  std::vector<MassFlowPlane> planes;
  double deletion_interval = 0;  ///< [s] between deletion (and plane) checks: run.deletion_interval
  std::uint64_t next_id = 1;     ///< id of the next inserted particle
  std::size_t max_particles = 0; ///< the most one insertion may place (run.max_particles; 0: no limit)

  bool empty() const { return pours.empty() && deletions.empty() && planes.empty() && !external_; }

  /// The run's ranks (loop/ranks.hpp; spread over several): every rank keeps the same
  /// books. A pour's insertion is computed alike on every rank from all
  /// particles (the same new particles and ids for any rank count), each new
  /// particle kept by one rank; deletion regions remove each rank's own
  /// particles and the counts are summed (exactly: integers, 1e-18 kg
  /// units); the planes watch all particles. Call before start().
  void set_ranks(RunRanks& ranks) { ranks_ = &ranks; }

  /// Particles that something else (a coupling between levels) adds to or
  /// removes from subdomain k between steps: they enter the balance like a
  /// pour's or a deletion region's, and a removed one leaves the planes' books.
  void count_inserted(std::size_t k, double mass);
  void count_removed(std::size_t k, std::uint64_t id, double mass);
  /// Something else adds and removes particles: the balance is kept (and
  /// reported) even without pours, deletions or planes.
  void expect_external() { external_ = true; }

  /// Before the first step: every particle present counts as inserted; the
  /// pours' and checks' cadences start (their tolerance from the subdomains'
  /// macro step, loop/cadence.hpp).
  void start(std::vector<std::unique_ptr<Subdomain>>& subdomains);
  /// At the start of macro step `step.index` (time step.t): pours and checks that are due.
  void update(const MacroStep& step, std::vector<std::unique_ptr<Subdomain>>& subdomains);
  /// Plane crossings up to now (also called at every probe row and at the end).
  void check_planes(std::vector<std::unique_ptr<Subdomain>>& subdomains);

  // Component: the ranks before the levels' set-up (a restart's restore()
  // counts over them), the start of a fresh run at setup, update() before
  // every macro step
  unsigned points() const override { return empty() ? 0u : kBeforeMacro; }
  void init(RunContext& ctx) override { set_ranks(ctx.ranks); }
  void setup(RunContext& ctx) override;
  void before_macro(RunContext& ctx, const MacroStep& step) override { update(step, ctx.subdomains); }
  /// The plane crossings to the end, and summary.json's books (when not empty()).
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  // ProbeSource: columns() and append_row(), the planes checked first
  void probe_columns(std::vector<std::string>& names) const override;
  void probe_values(RunContext& ctx, double t, std::vector<double>& row) override;

  std::vector<std::string> columns() const;
  /// Append this row's values (cumulative masses and rates since the last row).
  void append_row(double t, std::vector<double>& row);
  nlohmann::json summary(const std::vector<std::unique_ptr<Subdomain>>& subdomains) const;
  /// inserted - present - removed [kg] of subdomain k: exactly 0 unless a particle was lost or duplicated
  MassUnits residual(std::size_t k, const ParticleStore& s) const;
  const std::vector<MassAccount>& accounts() const { return accounts_; }

  /// Checkpoints: the next id, the books, each pour's progress (its events
  /// seed its insertions), the deletions' and planes' counts, series and
  /// sides, the checks' schedule. restore() replaces start() in a restarted
  /// run and throws ConfigError when the scenario's pours, deletion regions
  /// or planes are not the checkpoint's.
  void save(ArchiveWriter& w, const std::string& prefix) override;
  void restore(const ArchiveReader& r, const std::string& prefix, std::vector<std::unique_ptr<Subdomain>>& subdomains);
  /// Both directions of save and restore, field by field (core/archive.hpp),
  /// for a run of `subdomains` levels.
  void fields(CheckpointFields& f, std::size_t subdomains);

 private:
  void pour(Pour& p, double t, Subdomain& sd);
  void delete_particles(std::vector<std::unique_ptr<Subdomain>>& subdomains);

  /// The mass [1e-18 kg] and number of subdomain k's particles, over all ranks.
  std::pair<MassUnits, std::uint64_t> present(const Subdomain& sd) const;
  /// Each rank's bytes on every rank (one process: its own).
  std::vector<std::vector<char>> from_every_rank(const std::vector<char>& mine) const;

  RunRanks* ranks_ = &one_process();
  std::vector<MassAccount> accounts_;
  bool external_ = false;
  Cadence checks_;  ///< deletion (and plane) checks, every deletion_interval from deletion_interval on
  double last_row_t_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> last_row_;
};

}  // namespace domel::platform
