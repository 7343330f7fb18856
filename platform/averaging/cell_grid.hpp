// SPDX-License-Identifier: MIT
// Eulerian cell averages on an axis-aligned hexahedral grid: particle count,
// mass, volume fraction, mass-averaged (Favre) velocity and the granular
// stress tensor (kinetic + contact virial) per cell, as LIGGGHTS-PFM's
// `fix ave/euler/region` computes them (docs/physics.md §5.2, §8; the
// formulas and the choices made are in docs/averaging.md). The grid also
// knows the accessible-volume weight of each cell (the fraction on the
// particle side of every wall) and can reduce a field set to a layer profile
// along one axis. It depends only on the particle store, the wall primitives
// and a list of contact records, never on Subdomain or Simulation: the run
// loop records the contact forces on sampling steps and calls sample().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/neighbor_list.hpp"
#include "core/cadence.hpp"
#include "core/particle_store.hpp"
#include "geometry/wall.hpp"

namespace domel::platform {

/// The most cells a grid may have (about 3 GB of averages): more is refused
/// by the grid and by the scenario's checks, before anything is allocated.
inline constexpr std::size_t kMaxGridCells = 10000000;


class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

/// One contact force, recorded during a force evaluation on sampling steps.
/// A pair appears once (either orientation); i and j index the same
/// ParticleStore that is passed to CellGrid::sample().
struct ContactRecord {
  std::uint32_t i;        ///< particle index
  std::uint32_t j;        ///< partner particle index, or kWall
  double fx, fy, fz;      ///< force on i [N] (j receives the opposite)
  double px, py, pz;      ///< wall contacts: the contact point; pairs: j's position, or through a periodic face its image nearest to i [m]
  std::uint32_t wall = 0; ///< wall contacts: the subdomain's wall primitive; unused for pairs
  static constexpr std::uint32_t kWall = 0xffffffffu;
};

/// What a scenario says about one grid. The scenario parser validates it
/// (with JSON pointers); CellGrid's constructor checks it again and throws
/// std::invalid_argument naming the grid and the offending member.
struct CellGridSpec {
  std::string name;              ///< file-name stem of the output (no '/')
  double lo[3] = {0, 0, 0};      ///< box corner [m]
  double hi[3] = {0, 0, 0};      ///< opposite corner [m], hi > lo on every axis
  int cells[3] = {1, 1, 1};      ///< cell counts per axis, >= 1
  int every = 15;                ///< sample every N steps of its subdomain (physics.md §5.2, nevery 15)
  double write_interval = 0;     ///< simulated s between grid files (0: none)
  int accessible_samples = 8;    ///< sub-sampling points per axis per cell for w_c (8: 512 per cell)
};

/// Per-cell fields. Every vector has one entry per cell (9 for the tensors,
/// row-major: [3*a + b] is sigma_ab), flattened with c = ix + nx*(iy + ny*iz).
/// For a mean (CellGrid::mean_since_last_take) each field is the mean over
/// the samples, except the velocity, which is the Favre mean over the samples
/// (sum of momentum / sum of mobile mass), see docs/averaging.md.
struct CellFields {
  double time = 0;               ///< time of the (last) sample [s]
  std::size_t samples = 0;       ///< samples behind these fields (1 for latest())
  std::vector<double> count;            ///< particles with centre in the cell, fixed ones included
  std::vector<double> count_fixed;      ///< of which fixed (ParticleStore::kFixed)
  std::vector<double> mass;             ///< [kg], fixed particles included
  std::vector<double> mobile_mass;      ///< [kg], fixed particles excluded (weight of the velocity)
  std::vector<double> volume_fraction;  ///< sum V_i / (V_c w_c), fixed particles included
  std::vector<double> vx, vy, vz;       ///< Favre velocity of the mobile particles [m/s] (0 if none)
  /// Smallest and largest velocity component of the mobile particles in the
  /// cell [m/s] (0 if none; the controllers' velocity limit, physics.md
  /// §5.3). Only latest() has them; a mean over samples leaves them 0.
  std::vector<double> vmin_x, vmin_y, vmin_z, vmax_x, vmax_y, vmax_z;
  std::vector<double> pressure;         ///< tr(stress)/3 [Pa], > 0 in compression
  std::vector<double> accessible;       ///< w_c in [0, 1]
  std::vector<double> stress;           ///< 9 per cell [Pa], kinetic + contact, > 0 in compression (physics.md §8)
  std::vector<double> stress_kinetic;   ///< 9 per cell [Pa], the kinetic part

  /// Resize every vector for `n` cells and set all values to 0.
  void reset(std::size_t n);
  /// Every per-cell vector with its name (checkpoints).
  template <class F>
  void for_each_field(F&& f) {
    const std::pair<const char*, std::vector<double>*> all[] = {
        {"count", &count}, {"count_fixed", &count_fixed}, {"mass", &mass}, {"mobile_mass", &mobile_mass},
        {"volume_fraction", &volume_fraction}, {"vx", &vx}, {"vy", &vy}, {"vz", &vz}, {"vmin_x", &vmin_x},
        {"vmin_y", &vmin_y}, {"vmin_z", &vmin_z}, {"vmax_x", &vmax_x}, {"vmax_y", &vmax_y}, {"vmax_z", &vmax_z},
        {"pressure", &pressure}, {"accessible", &accessible}, {"stress", &stress},
        {"stress_kinetic", &stress_kinetic}};
    for (const auto& [name, v] : all) f(name, *v);
  }
};

/// A field set reduced to layers along one axis ("pressure over height").
/// Scalar means over the cells of a layer are weighted by accessible volume
/// V_c w_c, which makes them the layer's own volume fraction and stress;
/// the velocity is weighted by mobile mass (the layer's Favre velocity).
/// Layers without accessible volume have all means 0.
struct LayerProfile {
  int axis = 2;
  std::vector<double> centre;             ///< layer mid-coordinate along `axis` [m]
  std::vector<double> accessible_volume;  ///< sum V_c w_c [m^3]
  std::vector<double> count;              ///< particles in the layer (sum)
  std::vector<double> volume_fraction;
  std::vector<double> pressure;           ///< [Pa]
  std::vector<double> vx, vy, vz;         ///< [m/s]
};

/// Eulerian averaging grid over one subdomain's particles.
///
/// Usage in the run loop: construct from the spec, call set_accessible(walls)
/// once, then on every step with `due(step)` record the contact forces of that
/// force evaluation and call sample(); controllers read latest(), output calls
/// mean_since_last_take() every write_interval. Not thread-safe: one thread
/// calls sample() at a time (the records may come from several threads, one
/// vector each).
class CellGrid {
 public:
  /// Throws std::invalid_argument for an empty or '/'-containing name,
  /// hi <= lo, a cell count < 1, every < 1, write_interval < 0 or
  /// accessible_samples < 1.
  explicit CellGrid(CellGridSpec spec);

  const CellGridSpec& spec() const { return spec_; }
  std::size_t cell_count() const { return n_cells_; }
  /// Edge lengths of one cell [m].
  const std::array<double, 3>& cell_size() const { return h_; }
  /// Volume V_c of one cell [m^3] (all cells are equal).
  double cell_volume() const { return cell_volume_; }
  /// Flattened index ix + nx*(iy + ny*iz).
  std::size_t index(int ix, int iy, int iz) const {
    return static_cast<std::size_t>(ix) +
           static_cast<std::size_t>(spec_.cells[0]) *
               (static_cast<std::size_t>(iy) + static_cast<std::size_t>(spec_.cells[1]) * static_cast<std::size_t>(iz));
  }
  /// Cell holding the point, binned half-open [lo, hi) per axis; -1 outside the box.
  std::ptrdiff_t cell_of(double x, double y, double z) const;
  /// The sampled subdomain's periodic boundaries: positions are binned at
  /// their image inside the periodic box.
  void set_periodic(const PeriodicBox& box) { periodic_ = box; }
  /// True on the steps the grid samples (step % every == 0).
  bool due(std::uint64_t step) const { return samples_.on(step); }

  /// Accessible-volume weight w_c of each cell: the fraction of the cell on
  /// the particle side of every wall, by regular sub-sampling
  /// (accessible_samples^3 points at the sub-cell centres; a point is
  /// accessible when every primitive whose gap() is defined there gives
  /// d >= 0). Only walls active at `time` count (WallPrimitive::active). Sampling error
  /// with n points per axis: at most 1/(2n) of the cell for a plane parallel
  /// to a cell face; for curved or oblique walls of that order or less
  /// (0.019 measured for a cylinder at n = 8, docs/averaging.md).
  /// Without a call, w_c = 1 everywhere. Called once before the run.
  void set_accessible(const std::vector<WallPrimitive>& walls, double time = 0.0);
  const std::vector<double>& accessible() const { return accessible_; }

  /// Instantaneous fields from the particle centres (binning by centre;
  /// particles outside the box are ignored), the kinetic stress about the
  /// cell's Favre velocity and the contact virial: a pair record adds
  /// 1/2 (x_i - p) (x) F_i to i's cell (p: j, or its image nearest to i) and 1/2 to j's cell (a half whose
  /// particle is outside the box is dropped); a wall record adds
  /// (x_i - p) (x) F_i to i's cell. sigma = (kinetic + contact)/(V_c w_c),
  /// p = tr(sigma)/3, phi = sum V_i/(V_c w_c); cells with w_c = 0 get
  /// phi = sigma = 0. Fixed particles count in count, mass, phi and the
  /// virial, not in the velocity or the kinetic stress. Null entries of
  /// `records` are skipped. Throws RuntimeError for a record whose index is
  /// out of range of the store. Replaces latest() and adds to the running mean.
  void sample(const ParticleStore& s, const std::vector<const std::vector<ContactRecord>*>& records,
              double time);
  /// Over MPI ranks: adds one rank's partial per-cell values up over all
  /// ranks, element-wise `sums` and `maxima`, the same bits on every rank.
  /// Collective.
  using RankReduction = std::function<void(std::vector<double>& sums, std::vector<double>& maxima)>;
  /// The same sample of a subdomain spread over ranks, from each rank's own
  /// part: the particles s[0, owned) (the rest are ghosts, whose positions
  /// only place the contact records) and the contacts this rank computed
  /// (each pair and wall contact is computed on one rank). The per-cell sums
  /// are reduced in two passes (counts, masses and momenta; then the kinetic
  /// stress about the reduced Favre velocities and the contact virial), so
  /// every rank holds the whole sample without gathering any particle.
  /// Collective: every rank calls it, a rank without particles too.
  void sample(const ParticleStore& s, std::size_t owned,
              const std::vector<const std::vector<ContactRecord>*>& records, double time,
              const RankReduction& over_ranks);

  /// The last sample (for controllers and couplers); all zero before the first.
  const CellFields& latest() const { return latest_; }
  /// Mean over the samples since the last call, then reset (for output).
  /// With no pending sample: zero fields (accessible filled), samples = 0.
  CellFields mean_since_last_take();
  std::size_t samples_pending() const { return pending_; }

  /// Layer profile of `f` along `axis` (0, 1, 2); see LayerProfile. Throws
  /// std::invalid_argument for another axis or a field set of the wrong size.
  LayerProfile profile(const CellFields& f, int axis = 2) const;

  /// Checkpoints: the accessible volume, the last sample and the running
  /// sums since the last take. load() throws ConfigError when the
  /// checkpoint's grid has another cell count.
  void save(ArchiveWriter& w, const std::string& prefix) const;
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load, field by field (core/archive.hpp).
  void fields(CheckpointFields& f);

 private:
  CellGridSpec spec_;
  std::size_t n_cells_ = 0;
  std::array<double, 3> h_{};
  std::array<double, 3> inv_h_{};
  double cell_volume_ = 0;
  std::vector<double> accessible_;
  CellFields latest_;
  CellFields sum_;                 ///< running sums since the last take (velocity slots hold momentum)
  Cadence samples_;       ///< every spec_.every steps of the subdomain, from step 0
  PeriodicBox periodic_;  ///< set_periodic()
  std::size_t pending_ = 0;
  std::vector<std::ptrdiff_t> cell_scratch_;  ///< cell of each particle in the current sample
};

}  // namespace domel::platform
