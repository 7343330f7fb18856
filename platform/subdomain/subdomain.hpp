// SPDX-License-Identifier: MIT
// One resolution level: its particle store, coarse-grain ratio, material,
// contact model (slot pipeline), neighbour lists, walls and time step, and
// the orchestration of its step through the named phases of
// step_phases.hpp. The work itself lives in the pieces it calls:
//   integrator.hpp       half kicks, drift, the body-force list
//   contact_sweep.hpp    pair and wall contacts (one gather/scatter)
//   force_partition.hpp  the threads' share of a force evaluation and its sum
//   time_step.hpp        the time-step estimate from the contact model
//   diagnostics.hpp      statistics, memory, contact counts
// Subdomains of one scenario do not touch each other's particles; coupling
// operators exchange cell averages between them through hooks.
#pragma once

#include "core/gravity.hpp"
#include "averaging/cell_grid.hpp"
#include "contact/contact_pipeline.hpp"
#include "contact/contact_sweep.hpp"
#include "contact/time_step.hpp"
#include "core/material.hpp"
#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "core/thread_pool.hpp"
#include "geometry/wall.hpp"
#include "geometry/wall_neighbors.hpp"
#include "subdomain/diagnostics.hpp"
#include "subdomain/force_partition.hpp"
#include "subdomain/integrator.hpp"
#include "subdomain/rank_exchange.hpp"
#include "subdomain/step_phases.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace domel::platform {

class ArchiveWriter;
class ArchiveReader;
struct SubdomainSavedState;  ///< subdomain_checkpoint.cpp

class Subdomain {
 public:
  Subdomain(std::string name, double coarse_grain, std::size_t material, std::unique_ptr<ContactPipeline> pipeline);

  const std::string& name() const { return name_; }
  double coarse_grain() const { return coarse_grain_; }
  /// Its own material (index into the scenario's materials): the first of materials().
  std::size_t material() const { return material_; }
  /// The materials its particles may have, as indices into the scenario's
  /// materials; ParticleStore::material holds a position in this list.
  const std::vector<std::size_t>& materials() const { return materials_; }
  /// The position of scenario material `global` in materials(); adds it
  /// when absent (before set_environment() only).
  std::uint8_t local_material(std::size_t global);
  ContactPipeline& pipeline() { return *pipeline_; }
  /// The particles at the end of the last step: a step left pending by
  /// step_deferred() is finished first (synchronize()). The const overload
  /// does so too (the pending kick is an internal deferral, not observable
  /// state); not for concurrent use from several threads.
  /// Its per-particle `contacts` are counted here, from the lists' contact
  /// flags, once per force evaluation (no work in the step loop).
  ParticleStore& store();
  const ParticleStore& store() const { return const_cast<Subdomain*>(this)->store(); }  // see synchronize_logically_const
  /// Particle count (needs no synchronisation); ghosts included when distributed.
  std::size_t size() const { return store_.size(); }
  /// Distributed: the owned particles' contact counts made complete (the
  /// contacts this rank's ghosts saw added to their owners'), as one process
  /// counts them; then store() returns them until the next force
  /// evaluation. Collective; nothing to do on one process.
  void collect_contact_counts();
  /// Finish the last step now (see store()); throws RuntimeError when a
  /// particle became non-finite. Cheap when nothing is pending.
  void synchronize();

  /// The coefficients of a pair of scenario materials (the interaction table).
  using CoefficientsOf = PairCoefficients (*)(const void* table, std::size_t a, std::size_t b);
  /// Wire materials and walls: every pair of materials() and every (wall,
  /// material) pair is derived once from the scenario's materials and the
  /// interaction table `coefficients(table, a, b)`. Call before setup(), after
  /// every local_material().
  void set_environment(const std::vector<Material>& materials, const void* table, CoefficientsOf coefficients,
                       const std::vector<WallPrimitive>* walls, const double gravity[3]);
  /// Where the initial particles came from (a state file), for the message
  /// when their initial forces are not finite (setup()).
  void set_initial_source(std::string source) { initial_source_ = std::move(source); }
  void set_skin(double skin) { skin_ = skin; }
  /// Periodic boundaries (core/neighbor_list.hpp); call before setup().
  void set_periodic(const PeriodicBox& box) {
    box_ = box;
    nlist_.set_periodic(ranks_->pair_box(box));
  }
  const PeriodicBox& periodic() const { return box_; }
  /// Spread this subdomain over several ranks (rank_exchange.hpp): call
  /// before setup(), with the store holding this rank's share of the
  /// particles and no ghosts. Pairs through periodic faces are then pairs
  /// with ghost images, and each step completes in phase order.
  void set_rank_exchange(std::unique_ptr<RankExchange> ranks);
  bool distributed() const { return ranks_->over_ranks(); }
  /// The particles this rank owns: store()[0, owned()); the rest are ghosts.
  std::size_t owned() const { return store_.size() - ghosts_; }
  /// The store to add particles to or remove them from between steps (a
  /// pour, a deletion region, an inflow): store(), without the ghosts when
  /// distributed (what is added or removed is this rank's own; the next step
  /// rebuilds the lists on every rank and moves each particle to its owner).
  ParticleStore& particles_to_edit();
  /// This subdomain lives on other ranks (levels on rank groups,
  /// docs/distributed.md): this rank holds none of its particles, steps it
  /// empty (its clock still runs) and keeps none of those created alike.
  /// Before setup(), with an empty store.
  void set_elsewhere() { elsewhere_ = true; }
  bool elsewhere() const { return elsewhere_; }
  /// Whether this rank keeps a particle every rank created alike (a pour's,
  /// an inflow's, a checkpoint's shared out anew): always on one process;
  /// spread over ranks, the rank starts_on_rank() names.
  bool keeps(std::uint64_t id) const {
    return !elsewhere_ && starts_on_rank(id, ranks_->rank(), ranks_->size());
  }
  /// Re-order the store by spatial cells every `builds` neighbour-list
  /// builds (and after 10 % growth) when it holds 5000+ particles; 0: never.
  void set_reorder_every(std::size_t builds) { reorder_every_ = builds; }
  double skin() const { return skin_; }
  void set_time_step(double dt) { dt_ = dt; }
  /// Worker threads for the force and integration loops (>= 1). Results are
  /// bit-identical run to run for a fixed count; different counts agree to
  /// round-off (the pair forces are summed in a different order).
  void set_threads(int threads);
  int threads() const { return pool_->size(); }
  double time_step() const { return dt_; }

  /// The pair constants (E*, G*, restitution, friction, rolling friction)
  /// the contact kernels see: of particles of local materials a and b, and
  /// of a particle of local material a with wall primitive w.
  const domel_pair_v2& pair(std::size_t a, std::size_t b) const { return pairs_[a * materials_.size() + b]; }
  const domel_pair_v2& wall_pair(std::size_t w, std::size_t a) const { return wall_pairs_[w * materials_.size() + a]; }
  /// Classes of material pairs that act alike (the same constants and
  /// rolling model): the contact sweep evaluates each as one run.
  std::size_t pair_classes() const { return class_pairs_.size(); }
  /// The rolling model acting on those pairs (null: none).
  const ModelInstance* pair_rolling(std::size_t a, std::size_t b) const {
    return pair_rolling_[a * materials_.size() + b];
  }
  const ModelInstance* wall_pair_rolling(std::size_t w, std::size_t a) const {
    return wall_pair_rolling_[w * materials_.size() + a];
  }

  /// Gravity that changes with time (core/gravity.hpp): read once per step
  /// for the forces at the step's end. Without one, gravity stays the
  /// vector given to set_environment().
  void set_gravity(std::shared_ptr<const GravitySchedule> g);
  /// The walls' primitives in their reference state (time 0; empty before set_environment()).
  const std::vector<WallPrimitive>& reference_walls() const {
    static const std::vector<WallPrimitive> kNone;
    return walls_ ? *walls_ : kNone;
  }
  /// The force [N] the particles put on scenario wall `wall` at the last
  /// force evaluation: the sum over its primitives with track_load set.
  void wall_load(std::size_t wall, double f[3]) const;

  /// The body-force list (gravity; the store's external forces once enabled).
  const BodyForces& body_forces() const { return body_forces_; }
  /// Reset the forces of particles [first, last) to their body forces: for
  /// particles added between steps (pours, inflow), so that their first
  /// half kick sees the same forces as every other particle's.
  void apply_body_forces(std::size_t first, std::size_t last);

  /// Particle k (an index into store()) was placed smaller than its own
  /// size, as a conversion between levels places its particles
  /// (coupling/conversion.hpp, docs/adaptive.md): from the next step on its
  /// radius grows by rate [m/s] times the time step at the start of every
  /// step until it reaches `to`; its mass and inertia should be those of
  /// `to` already. The neighbour lists count the growth as they count
  /// displacements (NeighborList::add_growth), so no contact is missed.
  /// The targets and rates are two per-particle fields ("grow_to",
  /// "grow_rate"), added at the first call, carried and checkpointed.
  void grow(std::size_t k, double to, double rate);
  /// Add the two growth fields now (idempotent; grow() does at its first
  /// call): a run whose particles may grow calls it at set-up, so that a
  /// checkpoint written with them is read into a store that has them.
  void enable_growth();
  /// Whether some particle is still growing.
  bool growing() const { return growing_; }
  /// A growing particle whose overlap with a pair partner or a wall (of
  /// every kind but meshes) exceeds this fraction of its full diameter waits
  /// that step for its neighbours to make room; 0: it never waits. Default
  /// 0.01: grown at a fixed rate alone, a refined packing jams and bursts
  /// (docs/adaptive.md has the figures).
  void set_growth_overlap(double fraction) { grow_overlap_ = fraction; }

  /// Register a hook on a phase of every following step (step_phases.hpp).
  /// From then on each step completes in phase order.
  void add_hook(Phase phase, StepHook hook);
  const StepHooks& hooks() const { return hooks_; }

  /// Estimate contact time and stability limit from the contact model itself
  /// (contact/time_step.hpp).
  TimeStepReport estimate_time_step(double impact_velocity);

  /// Build neighbour lists and evaluate forces at the current state. Throws
  /// RuntimeError when those forces are not finite (coinciding particles).
  void setup();
  /// One velocity-Verlet step of dt, complete on return.
  void step() {
    step_deferred();
    synchronize();
  }
  /// One velocity-Verlet step of dt. Without hooks it leaves its second
  /// half kick (and, with threads, the last force sums and the wall
  /// contacts) pending: the next step does them in its first sweep over the
  /// store, which saves one sweep and one fork/join per step
  /// (docs/performance.md). store(), stats(), contact_records() and
  /// synchronize() finish it, so every observer that goes through them sees
  /// the complete step; a reference to the store kept from before does not.
  /// With hooks the step completes in phase order (bit-identical results).
  void step_deferred();

  /// Checkpoints: everything the next step depends on, after finishing the
  /// last one (synchronize(): the fused path's deferred work is done the way
  /// the next step would do it, so the run goes on bit-identically).
  void save(ArchiveWriter& w, const std::string& prefix);
  /// Instead of setup(), once the environment, skin and threads are set: the
  /// state save() wrote, lists and forces included, so the next step is the
  /// one the saved run would have taken. Returns false when the threads'
  /// split could not be restored (another thread count: the forces are then
  /// summed in another order, and the run differs from the saved one by
  /// round-off). Throws ConfigError when the checkpoint does not fit this
  /// subdomain.
  bool restore(const ArchiveReader& r, const std::string& prefix);
  /// Restore from a checkpoint written on another number of ranks (or one
  /// process): `parts` are its parts of this subdomain (reader, prefix), one
  /// per rank it was written on. This rank takes the particles it would own
  /// at a start (id modulo the rank count) with their contact histories;
  /// the exchange and a list build then place them, so the run is a valid
  /// continuation (the sums' order differs: round-off). Collective.
  void restore_shared_out(const std::vector<std::pair<const ArchiveReader*, std::string>>& parts);

  double time() const { return time_; }
  std::uint64_t steps() const { return steps_; }

  /// Record every contact force of the following force evaluations (for the
  /// cell averages' contact stress; CellGrid::sample). Off by default: a
  /// sampling step costs one append per contact, other steps nothing.
  void set_record_contacts(bool on) { record_ = on; }
  /// The records of the last force evaluation, one list per thread.
  std::vector<const std::vector<ContactRecord>*> contact_records() const;
  std::size_t neighbor_builds() const { return nlist_.builds(); }
  /// Of this rank's own particles when distributed (contacts: those it computes).
  SubdomainStats stats() const;
  MemoryUse memory_use() const;

 private:
  /// The checkpoint part under prefix into this subdomain (store, lists,
  /// clocks); returns the part's own particle count (a rank's part: its
  /// owned ones; one process: all).
  /// `saved`: where its state section is read to, or null.
  std::size_t load_state(const ArchiveReader& r, const std::string& prefix, SubdomainSavedState* saved = nullptr);
  /// synchronize() for the const observers (store(), stats(),
  /// contact_records()): the pending kick is an internal deferral, not
  /// observable state.
  void synchronize_logically_const() const { const_cast<Subdomain*>(this)->synchronize(); }
  /// The fused, deferred step (no hooks).
  void step_fused();
  /// The step in phase order, with its hooks.
  void step_in_order();
  void run_hooks(Phase phase);
  /// Rethrow a kernel's failure with the subdomain, step and time.
  [[noreturn]] void rethrow_with_context(const std::exception& e, const char* during) const;

  /// The exchange phase's own work: wrap positions into a periodic box; when
  /// distributed, migration (with the contact histories) instead.
  void exchange();
  /// Each owned particle's share of the force evaluation's cost, for the
  /// ranks' decomposition (the thread balance's estimate: list entries and
  /// contacts it leads, wall entries and contacts).
  std::vector<std::uint64_t> rank_costs() const;
  /// The body-force list on the owned particles, zero on the ghosts (their
  /// forces are contact forces only, sent home by reverse_exchange).
  void reset_forces();
  void rebuild_lists();
  /// Move the moving walls to time t; rebuild the list of a wall that became
  /// active or moved more than skin/2 since its build, clear a removed one's.
  void update_walls(double t);
  /// Whether this step rebuilds the lists, from pass 1's counts; latches the
  /// far tier's screening otherwise.
  bool rebuild_due(bool stale);
  /// Add particle-pair and wall contact forces; with defer_reduce the other
  /// threads' partial sums and the wall contacts are left to the next pass.
  /// packed_filled: packed_ holds the store's positions already (pass 1 of
  /// step_fused filled it), else the pair sweep fills it first.
  void contact_forces(bool defer_reduce, bool packed_filled = false);
  void pair_forces(bool defer_reduce, bool packed_filled);
  void wall_forces();
  PairSweep pair_sweep() const;
  WallSweep wall_sweep();
  /// The part of the last force evaluation left to the next pass, for thread
  /// t: with `reduce`, the other threads' sums and the wall contacts of its
  /// particle range. Returns that range.
  std::pair<std::size_t, std::size_t> finish_forces(int t, bool reduce, std::size_t n);
  /// Take the pending force sum, if any, and split the particles for it.
  bool take_pending_reduce(std::size_t n);
  void finish_wall_stats();
  [[noreturn]] void throw_nonfinite(const char* when, double t, std::uint64_t step) const;
  void prune_removed_walls();
  /// The growth of this step (grow()), before its drift; clears growing_ when none is left.
  void grow_step();
  /// After a checkpoint's particles were loaded: the growth fields, if any, and whether any particle grows.
  void find_growth();

  std::string name_;
  double coarse_grain_;
  std::size_t material_;
  std::string initial_source_;
  std::unique_ptr<ContactPipeline> pipeline_;
  ParticleStore store_;
  NeighborList nlist_;
  std::vector<WallNeighbors> wall_lists_;
  const std::vector<WallPrimitive>* walls_ = nullptr;  ///< reference state (time 0) of the walls
  std::vector<WallPrimitive> walls_now_;  ///< this subdomain's walls placed at wall_time_
  double wall_time_ = 0;                  ///< time of the walls' placement and surface velocities
  std::vector<std::size_t> materials_;     ///< scenario indices; [0] = material_
  std::vector<Material> local_materials_;  ///< their constants, same order
  std::vector<domel_pair_v2> pairs_;       ///< [a * n + b], n = materials_.size()
  std::vector<domel_pair_v2> wall_pairs_;  ///< [w * n + a]
  std::vector<const ModelInstance*> pair_rolling_, wall_pair_rolling_;  ///< their rolling models, same order
  /// Pairs of materials that act alike (the same constants and rolling
  /// model) form one class, which the contact sweep evaluates as one run:
  /// a mixture of materials with the same constants costs what one material
  /// does. pair_class_[a * n + b] indexes class_pairs_ and class_rolling_.
  std::vector<uint16_t> pair_class_;
  std::vector<domel_pair_v2> class_pairs_;
  std::vector<const ModelInstance*> class_rolling_;
  std::vector<uint8_t> wall_uniform_;  ///< per wall primitive: every material meets it alike
  BodyForces body_forces_;
  std::shared_ptr<const GravitySchedule> gravity_;  ///< null: constant gravity
  StepHooks hooks_;
  double skin_ = 0;
  double dt_ = 0;
  double time_ = 0;
  std::uint64_t steps_ = 0;
  std::size_t last_contacts_ = 0, last_wall_contacts_ = 0;
  double last_max_overlap_ratio_ = 0;
  std::vector<ContactScratch> scratch_;  ///< per thread
  ForcePartition partition_;
  PackedPositions packed_;  ///< the pair screen's copy of the positions, filled before each force evaluation
  std::vector<DriftCounts> drift_counts_;  ///< per thread, of pass 1
  std::vector<double> nonfinite_counts_;   ///< per thread, of a second half kick
  bool reduce_pending_ = false;
  bool contacts_counted_ = true;  ///< store_.contacts is up to date (count_contacts)
  bool contacts_collected_ = false;  ///< distributed: and the ghosts' counts were sent home
  bool kick_pending_ = false;  ///< the last step's second half kick is still to do (store())
  double pending_half_ = 0;    ///< its half time step
  double forces_time_ = 0;     ///< time_ at the last force evaluation (wall activity)
  static constexpr std::size_t kReorderMinParticles = 5000;
  std::size_t reorder_every_ = 20;  ///< list builds between spatial re-orderings (0: never)
  std::size_t builds_since_reorder_ = SIZE_MAX / 2;  ///< re-order at the first build
  std::size_t reordered_size_ = 0;
  bool walls_force_rebuild_ = false;  ///< a moving wall travelled skin/2 since its list was built
  bool record_ = false;    ///< fill ContactScratch::records (set_record_contacts)
  bool far_active_ = true;  ///< the far tier of the pair list is screened (see NeighborList::near_size)
  std::unique_ptr<ThreadPool> pool_;
  PeriodicBox box_;                     ///< set_periodic()
  std::unique_ptr<RankExchange> ranks_ = std::make_unique<OneProcessExchange>();  ///< set_rank_exchange()
  std::size_t ghosts_ = 0;      ///< the ghosts at the end of the store (only a rank holds any)
  std::size_t ghosts_end_ = 0;  ///< the store's size after the ghosts were built
  bool edited_ = false;         ///< particles_to_edit() dropped ghosts that the lists name
  bool elsewhere_ = false;      ///< set_elsewhere()
  bool growing_ = false;        ///< some particle's radius is below its grow_to (grow())
  std::size_t grow_to_ = SIZE_MAX, grow_rate_ = SIZE_MAX;  ///< their aux fields, once added
  double grow_overlap_ = 0.01;  ///< set_growth_overlap()
  std::vector<double> overlap_;  ///< grow_step()'s scratch
};

}  // namespace domel::platform
