// SPDX-License-Identifier: MIT
// A coupling between two resolution levels (the Domain-Element Model,
// docs/multilevel.md; the algorithms of docs/physics.md §5 as LIGGGHTS-PFM
// codes them): a fine subdomain lives inside a box (the region) of its
// coarse parent's domain, split into hexahedral cells on which both levels
// are averaged. At every control interval, at a time that is a step of both
// levels, the coupling
//   1. removes the fine particles whose centre has left the region and books
//      them as outflow of the face they crossed;
//   2. counts the coarse parcels that entered the region through an inflow
//      face since the last interval, each parcel once per face (mass,
//      momentum, size): a face is one counting surface, as each of
//      LIGGGHTS-PFM's massflow/mesh/face fixes counts once on its own;
//   3. when a transfer is due (the counted material would fill a face's
//      insertion shell beyond fill_target, or transfer_max_steps passed),
//      turns what each face counted into fine particles
//      (alpha_c/alpha_f)^3 per parcel, placed in the shell behind the face by
//      sequential simple inhibition with the face's mass-weighted velocity;
//      what cannot be placed waits (the backlog);
//   3a. with match_outflow, removes the coarse parcels lowest in the region
//      while the fine level has discharged more mass from the region than
//      the coarse level (through faces that are not inflow faces, or by
//      deletion): the coarse outflow then follows the fine discharge;
//   4. hands both levels' cell averages (sampled at the step that ended at
//      this time) and particles to its two controller plugins, the fine
//      boundary PI stress controller and the coarse P velocity controller,
//      whose forces the levels then carry as external forces until the next
//      interval.
// Nothing here reads a level's state from the future: every exchange runs
// between macro steps, when all levels stand at the same time.
//
// Spread over MPI ranks (set_ranks), every rank gathers both levels'
// particles in id order and runs the same exchange on them: the same books,
// the same random draws, the same controller calls. Each rank then removes
// its own particles among those removed, keeps the inserted particles whose
// id falls to it (starts_on_rank, as a pour's) and adds the controllers'
// forces to its own particles (docs/distributed.md).
#pragma once

#include "averaging/cell_grid.hpp"
#include "coupling/conversion.hpp"
#include "geometry/wall.hpp"
#include "loader/plugin_registry.hpp"
#include "flow/particle_flow.hpp"
#include "loop/macro_step.hpp"
#include "loop/ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace domel::platform {

class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;
class RunRanks;

namespace io {
class CsvSeries;
class CellGridVtkSeries;
}  // namespace io

/// Faces of the region box: -x, +x, -y, +y, -z, +z.
inline constexpr int kFaces = 6;
const char* face_name(int face);
/// "-x" ... "+z" -> 0 ... 5; -1 for anything else.
int face_from_name(const std::string& name);

struct ControllerSetup {
  bool enabled = false;
  std::shared_ptr<ModelInstance> model;
  nlohmann::json params;  ///< what the model was created with (defaults filled), for summary.json
};

/// A coupling as the scenario describes it, resolved by the builder.
struct CouplingSpec {
  std::string name;
  std::string where;  ///< JSON pointer of the block, for messages
  std::size_t coarse = 0, fine = 0;  ///< subdomain indices
  CellGridSpec grid;                 ///< the region and its cells; `every` is set by the coupling
  std::array<bool, kFaces> inflow{};
  double fine_density = 0;           ///< [kg/m^3] of the fine level's material
  double alpha_ratio = 0.5;          ///< alpha_fine / alpha_coarse
  double shell_depth = 0;            ///< [m]
  double fill_target = 0.1;
  int attempts = 1000;
  double grid_interval = 0;          ///< [s] between grid files; 0: none
  bool match_outflow = false;        ///< remove coarse parcels so the coarse outflow follows the fine one
  int growth_steps = 2000;           ///< fine steps over which particles refined at the start grow to their size
  std::uint64_t seed = 1;
  // timing, resolved from the levels' sub-steps per macro step
  std::uint64_t control_macro = 1;   ///< macro steps per control interval
  int fine_steps = 1;                ///< fine steps per control interval (N)
  int coarse_steps = 1;              ///< coarse steps per control interval
  std::uint64_t transfer_controls = 1;  ///< control intervals per transfer, at most
  ControllerSetup stress;            ///< acts on the fine level
  ControllerSetup velocity;          ///< acts on the coarse level
};

/// The books of one face, in the integer mass units of the flow balance
/// (particle_flow.hpp): counted = inserted + pending exactly; removed is
/// the fine outflow through the face.
struct FaceBalance {
  MassUnits counted = 0, inserted = 0, removed = 0;
  std::uint64_t parcels = 0;           ///< coarse parcels counted
  std::uint64_t n_inserted = 0, n_removed = 0;
  std::deque<double> queue;            ///< radii of the fine particles still to insert (the backlog first)
  double fraction = 0;                 ///< fine particles owed beyond the whole ones in the queue
  // this transfer interval
  double mass_open = 0;                ///< [kg] counted since the last transfer
  double momentum[3] = {0, 0, 0};      ///< [kg m/s] of what was counted since the last transfer
  double velocity[3] = {0, 0, 0};      ///< [m/s] given to inserted particles (the last interval's mean)
  std::uint64_t backlog = 0;           ///< particles that could not be placed at the last transfer
  int growing = 0;                     ///< consecutive transfers with a growing backlog
  bool warned = false;
  bool warned_fill = false;
  double volume_open = 0;              ///< [m^3] solid volume counted since the last transfer
  MassUnits pending() const { return counted - inserted; }
};

class Coupling {
 public:
  explicit Coupling(CouplingSpec spec);
  ~Coupling();
  Coupling(const Coupling&) = delete;
  Coupling& operator=(const Coupling&) = delete;

  const CouplingSpec& spec() const { return spec_; }
  /// Spread over these ranks (null: one process); before start().
  void set_ranks(RunRanks& ranks) { ranks_ = &ranks; }
  /// The two levels' averages on the region's cells; the run loop samples
  /// them on the steps they are due (every control interval of each level).
  CellGrid& fine_grid() { return *fine_grid_; }
  CellGrid& coarse_grid() { return *coarse_grid_; }
  const std::array<FaceBalance, kFaces>& faces() const { return faces_; }
  /// The outflow books of the region in exact mass units, for
  /// match_outflow: the fine discharge (removed at faces that are not
  /// inflow faces and by deletion regions), the coarse discharge by itself
  /// (parcels that left the box through such a face or were deleted), what
  /// match_outflow removed, and the deficit still owed [kg].
  struct Outflow {
    MassUnits fine = 0, coarse = 0, sink = 0;
    std::uint64_t n_sink = 0;
    /// [kg] the fine discharge minus the coarse one and the sink's, since the
    /// start; negative while the coarse level leads
    double deficit() const { return mass_kg(fine) - mass_kg(coarse) - mass_kg(sink); }
  };
  const Outflow& outflow() const { return outflow_; }

  /// Before the first step: accessible volumes, the coarse parcels' sides,
  /// the balance file. `out` empty: no files. Collective on ranks.
  void start(std::vector<std::unique_ptr<Subdomain>>& subdomains, const std::vector<WallPrimitive>& walls,
             const std::filesystem::path& out);
  /// What the refinement at the start made (refine_at_start): the coarse
  /// parcels inside the region and their mass, the fine particles made and
  /// theirs, the mass carried (short of a whole fine particle, per parcel
  /// size), and the operation's books (conversion.hpp).
  struct StartRefinement {
    std::uint64_t parcels = 0, particles = 0;
    MassUnits parcel_units = 0, particle_units = 0, carried_units = 0;
    double momentum_residual = 0;  ///< [kg m/s] largest component, parcels (and carried) in minus particles out
    double angular_in = 0, angular_out = 0;  ///< [kg m^2/s] magnitude of the sums about each parcel's centre
    double kinetic_in = 0, kinetic_out = 0;  ///< [J]
    double fluctuation = 0;        ///< [J] kinetic energy of the particles' velocities about their parcel's
    double smallest_start = 1;     ///< smallest start radius over full radius
    double growth_time = 0;        ///< [s] growth_steps fine steps
  };
  const StartRefinement& start_refinement() const { return refined_; }
  /// On a fresh start, after start(): when the fine level holds no particle,
  /// every coarse parcel whose centre lies in the region becomes fine
  /// particles (refine_parcel) that grow to their size over growth_steps of
  /// the fine level's steps, counted as inserted into the fine level's
  /// books; the parcels stay, as the image of that material (docs/adaptive.md).
  /// Collective on ranks.
  void refine_at_start(std::vector<std::unique_ptr<Subdomain>>& subdomains, ParticleFlow& flow);
  /// One control interval at time t (all levels stand at t): steps 1-4 of
  /// the file comment. External forces of both levels must have been zeroed
  /// by the caller (several couplings add into the same level). Collective
  /// on ranks.
  void exchange(double t, std::vector<std::unique_ptr<Subdomain>>& subdomains,
                const std::vector<WallPrimitive>& walls, ParticleFlow& flow);
  /// Grid files due at macro step `tick`, time t (or the last ones when final).
  void write_grids(std::uint64_t tick, double t, bool final);
  /// Checkpoints (docs/checkpoint.md), written at a macro-step start before
  /// the exchange: both grids' averages, every face's books and queue, the
  /// parcels followed and those already counted, the insertion RNG, the
  /// counters and outflow books, the controllers' states (ABI 2.3
  /// save_state) and how far the balance and grid files got.
  void save(ArchiveWriter& w, const std::string& prefix);
  /// After start() on a restart: every value replaced by the checkpoint's,
  /// the files continued. Throws ConfigError naming the section when the
  /// checkpoint holds another coupling.
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load, field by field (core/archive.hpp).
  void fields(CheckpointFields& f);

  /// Close the balance file and describe the coupling for summary.json;
  /// `fine` holds all the fine level's particles (on ranks: gathered).
  nlohmann::json summary(const std::vector<std::unique_ptr<Subdomain>>& subdomains, const ParticleStore& fine,
                         const ParticleFlow& flow);

  /// Wall time spent in the coupling so far [s], by part: removal and face
  /// counting, transfers (insertion), the controllers (views and calls),
  /// and the run loop's sampling of the two grids (added by the run loop).
  struct Timing {
    double count = 0, transfer = 0, control = 0, averaging = 0;
  };
  Timing& timing() { return timing_; }

  /// Statistics of the run so far.
  std::uint64_t transfers() const { return transfers_; }
  std::uint64_t control_calls() const { return controls_; }
  double last_exchange_time() const { return last_t_; }

 private:
  // The steps work on a level's whole set of particles: its store on one
  // process, its particles gathered from the ranks on several (see above);
  // the removals return the ids removed, in store order.
  std::vector<std::uint64_t> remove_escaped(ParticleStore& fine, ParticleFlow& flow);
  void count_inflow(const ParticleStore& coarse);
  void fit_in_region(const ConvertedBody& parcel, std::vector<ConvertedBody>& made) const;
  std::vector<std::uint64_t> match_outflow(ParticleStore& coarse, const Subdomain& level, ParticleFlow& flow);
  void transfer(double t, Subdomain& level, ParticleStore& fine, const std::vector<WallPrimitive>& walls,
                ParticleFlow& flow);
  std::size_t insert_face(int face, double t, ParticleStore& fine, const std::vector<WallPrimitive>& walls,
                          std::uint64_t& next_id);
  void control(double t, double interval, Subdomain& fine_level, ParticleStore& fine, Subdomain& coarse_level,
               ParticleStore& coarse);
  void write_row(double t, const ParticleStore& fine, const ParticleFlow& flow);
  double shell_volume(int face) const;

  CouplingSpec spec_;
  RunRanks* ranks_ = &one_process();
  std::unique_ptr<CellGrid> fine_grid_, coarse_grid_;
  std::array<FaceBalance, kFaces> faces_;
  /// parcel id -> position and mass at the last count, for the parcels near the region
  std::unordered_map<std::uint64_t, std::array<double, 4>> coarse_last_;
  /// per face, the parcels it has counted (each face counts a parcel once)
  std::array<std::unordered_set<std::uint64_t>, kFaces> counted_ids_;
  std::mt19937_64 rng_;
  std::uint64_t controls_ = 0, transfers_ = 0;
  std::uint64_t since_transfer_ = 0;  ///< control intervals since the last transfer
  double last_t_ = 0;
  double last_row_t_ = -1;
  Timing timing_;
  Outflow outflow_;
  StartRefinement refined_;
  double fine_dmax_ = 0;              ///< largest fine diameter seen (forcing layer, insertion hash)
  std::unique_ptr<io::CsvSeries> balance_;
  std::unique_ptr<io::CellGridVtkSeries> vtk_fine_, vtk_coarse_;
  Cadence grid_files_;  ///< the grid files, every grid_interval (never due when 0)
  // scratch of the controller views
  std::vector<std::uint32_t> cell_f_, cell_c_, count_f_, count_c_;
  std::vector<double> stress_f_, stress_c_;
};

}  // namespace domel::platform
