// SPDX-License-Identifier: MIT
// One resolution level: its particle store, coarse-grain ratio, material,
// contact model (slot pipeline), neighbour lists and time step. The per-step
// hot path lives here and reads top to bottom:
//   step(): half kick -> drift -> (rebuild lists) -> forces -> half kick
//   compute_forces(): gravity, particle pairs in batches, walls in batches.
// Subdomains of one scenario do not touch each other's particles; coupling
// operators (a later stage) exchange cell averages between them.
#pragma once

#include "averaging/cell_grid.hpp"
#include "contact/contact_pipeline.hpp"
#include "core/material.hpp"
#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "core/thread_pool.hpp"
#include "geometry/wall.hpp"
#include "geometry/wall_neighbors.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace domel::platform {

/// Observables of the last force evaluation and the current state.
struct SubdomainStats {
  std::size_t particles = 0;         ///< all particles, fixed ones included
  std::size_t fixed = 0;             ///< fixed particles (not in the kinetic statistics)
  std::size_t contacts = 0;          ///< particle-particle contacts
  std::size_t wall_contacts = 0;
  double kinetic_translational = 0;  ///< [J]
  double kinetic_rotational = 0;     ///< [J]
  double mean_angular_speed = 0;     ///< mean |omega| [rad/s]
  /// median |omega| [rad/s]: robust against the few particles that spin
  /// freely about their contact normal, which rolling models do not resist
  /// and which pin the plain mean (peers/RESULTS.md §2)
  double median_angular_speed = 0;
  /// mean |omega| over particles with |omega| < 1 rad/s [rad/s] (the peers' trimmed statistic)
  double trimmed_mean_angular_speed = 0;
  double max_overlap_ratio = 0;      ///< max delta / (mean diameter of the pair), walls: delta / d
};

/// Bytes held by a subdomain's per-particle and per-contact arrays (their
/// capacity), for the run summary and the memory benchmark.
struct MemoryUse {
  std::size_t particles = 0;        ///< the particle store
  std::size_t neighbor_lists = 0;   ///< pair and wall lists without their history
  std::size_t contact_history = 0;  ///< per-entry history rows of the pair and wall lists
  std::size_t threads = 0;          ///< the other threads' force arrays
};

struct TimeStepReport {
  double rayleigh = 0;       ///< Rayleigh time of the smallest particle [s]
  double contact_time = 0;   ///< shortest simulated collision at the impact velocity [s]
  double critical = 0;       ///< explicit stability limit 2/omega (damped) of the stiffest contact [s]
  std::string critical_of;   ///< which contact sets it ("particle-particle", "wall 'x'")
  double chosen = 0;         ///< [s]
  std::string reason;
};

class Subdomain {
 public:
  Subdomain(std::string name, double coarse_grain, std::size_t material, std::unique_ptr<ContactPipeline> pipeline);

  const std::string& name() const { return name_; }
  double coarse_grain() const { return coarse_grain_; }
  std::size_t material() const { return material_; }
  ContactPipeline& pipeline() { return *pipeline_; }
  /// The particles at the end of the last step: a step left pending by
  /// step_deferred() is finished first (synchronize()). The const overload
  /// does so too (the pending kick is an internal deferral, not observable
  /// state); not for concurrent use from several threads.
  /// Its per-particle `contacts` are counted here, from the lists' contact
  /// flags, once per force evaluation (no work in the step loop).
  ParticleStore& store() {
    synchronize();
    if (!contacts_counted_) count_contacts();
    return store_;
  }
  const ParticleStore& store() const { return const_cast<Subdomain*>(this)->store(); }  // see synchronize_logically_const
  /// Particle count (needs no synchronisation).
  std::size_t size() const { return store_.size(); }
  /// Finish the last step now (see store()); throws RuntimeError when a
  /// particle became non-finite. Cheap when nothing is pending.
  void synchronize();

  /// Wire materials and walls (pairs are derived once). Call before setup().
  void set_environment(const std::vector<Material>& materials, const std::vector<PairCoefficients>& wall_pairs,
                       const PairCoefficients& self_pair, const std::vector<WallPrimitive>* walls,
                       const double gravity[3]);
  void set_skin(double skin) { skin_ = skin; }
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

  /// Estimate contact time and stability limit from the contact model itself:
  /// a head-on collision at `impact_velocity` is integrated with the normal
  /// and damping stages (particle-particle and each wall).
  TimeStepReport estimate_time_step(double impact_velocity);

  /// Build neighbour lists and evaluate forces at the current state.
  void setup();
  /// One velocity-Verlet step of dt, complete on return.
  void step() {
    step_deferred();
    synchronize();
  }
  /// One velocity-Verlet step of dt that leaves its second half kick (and,
  /// with threads, the last force sums and the wall contacts) pending: the
  /// next step does them in its first sweep over the store, which saves one
  /// sweep and one fork/join per step (docs/performance.md). store(),
  /// stats(), contact_records() and synchronize() finish it, so every
  /// observer that goes through them sees the complete step; a reference to
  /// the store kept from before does not. The run loop uses this; code that
  /// holds on to the store across steps uses step().
  void step_deferred();

  double time() const { return time_; }
  std::uint64_t steps() const { return steps_; }

  /// Record every contact force of the following force evaluations (for the
  /// cell averages' contact stress; CellGrid::sample). Off by default: a
  /// sampling step costs one append per contact, other steps nothing.
  void set_record_contacts(bool on) { record_ = on; }
  /// The records of the last force evaluation, one list per thread.
  std::vector<const std::vector<ContactRecord>*> contact_records() const;
  std::size_t neighbor_builds() const { return nlist_.builds(); }
  SubdomainStats stats() const;
  MemoryUse memory_use() const;

 private:
  /// synchronize() for the const observers (store(), stats(),
  /// contact_records()): the pending kick is an internal deferral, not
  /// observable state.
  void synchronize_logically_const() const { const_cast<Subdomain*>(this)->synchronize(); }
  /// One thread's batch workspace, batch bookkeeping and force accumulators.
  struct ThreadScratch {
    std::unique_ptr<ContactPipeline::Workspace> ws;
    std::vector<uint32_t> entry;     ///< list entry of each batch slot
    std::vector<double> ci, cj;      ///< lever arms of each batch slot
    std::vector<double> fx, fy, fz, tx, ty, tz;  ///< accumulators (threads > 0)
    std::vector<ContactRecord> records;  ///< contact forces on recording steps
    std::size_t n_contacts = 0;
    std::size_t wall_contacts = 0;
    double wall_max_ratio = 0;
    std::size_t lo = 0, hi = 0;      ///< particle-index span of this thread's pairs this step
    /// The part of [lo, hi) that no other thread's pairs touch this step:
    /// forces on these particles go straight into the store (threads > 0;
    /// own_lo == own_hi == hi when there is none). Only [lo, own_lo) and
    /// [own_hi, hi) of the private arrays are cleared and summed.
    std::size_t own_lo = 0, own_hi = 0;
    /// The parts of the span that go through the private arrays.
    std::array<std::pair<std::size_t, std::size_t>, 2> shared_ranges() const { return {{{lo, own_lo}, {own_hi, hi}}}; }
    std::size_t span[2][2] = {{0, 0}, {0, 0}};  ///< the span per list tier (near, far)
    double max_ratio = 0;
    MeshScratch mesh;                ///< mesh walls: per-particle feature bookkeeping
    std::vector<MeshContact> mesh_out;
    std::vector<uint8_t> counted;
  };
  /// Where a thread adds forces: the store itself (thread 0) or its own arrays.
  struct Accumulator {
    double *fx, *fy, *fz, *tx, *ty, *tz;
  };

  void rebuild_lists();
  /// Move the moving walls to time t; rebuild the list of a wall that became
  /// active or moved more than skin/2 since its build, clear a removed one's.
  void update_walls(double t);
  void compute_forces();   ///< reset to gravity, then contact_forces()
  /// Add particle-pair and wall contact forces; with defer_reduce the other
  /// threads' partial sums are left for the caller (reduce_partials).
  void contact_forces(bool defer_reduce = false);
  void pair_forces(bool defer_reduce);
  void reduce_partials(std::size_t first, std::size_t last);
  void reduce_split(std::size_t n);
  /// Wall-contact work per particle for reduce_split (with balance_pairs).
  void refresh_wall_work();
  void balance_pairs(int nt);
  /// Forces on particles in [ts.own_lo, ts.own_hi) go to `own`, on the others
  /// to `shared`; without kZoned all go to `own`. kTorque: the pipeline has
  /// a rolling or twisting model, whose couples are added.
  template <bool kZoned, bool kTorque>
  void pair_range(std::size_t first, std::size_t last, ThreadScratch& ts, const Accumulator& own,
                  const Accumulator& shared);
  using PairRange = void (Subdomain::*)(std::size_t, std::size_t, ThreadScratch&, const Accumulator&,
                                        const Accumulator&);
  /// The pair_range instance for this pipeline, with or without zones.
  PairRange pair_kernel(bool zoned) const;
  /// Set lo/hi and own_lo/own_hi of every thread for this step (threads > 1).
  void thread_zones(bool far);
  /// The part of the last force evaluation left to the integration pass,
  /// for thread t: with `reduce`, the other threads' sums and the wall
  /// contacts of its particle range (pass2_split_). Returns that range.
  std::pair<std::size_t, std::size_t> finish_forces(int t, bool reduce, std::size_t n);
  /// Take the pending force sum, if any, and split the particles for it.
  bool take_pending_reduce(std::size_t n);
  void finish_wall_stats();
  [[noreturn]] void throw_nonfinite() const;
  void wall_forces();
  void prune_removed_walls();
  /// Fill store_.contacts from the last force evaluation (store()).
  void count_contacts();
  void wall_range(ThreadScratch& ts, std::size_t first, std::size_t last);

  std::string name_;
  double coarse_grain_;
  std::size_t material_;
  std::unique_ptr<ContactPipeline> pipeline_;
  ParticleStore store_;
  NeighborList nlist_;
  std::vector<WallNeighbors> wall_lists_;
  const std::vector<WallPrimitive>* walls_ = nullptr;  ///< reference state (time 0) of the walls
  std::vector<WallPrimitive> walls_now_;  ///< this subdomain's walls placed at wall_time_
  bool any_moving_ = false;
  double wall_time_ = 0;                  ///< time of the walls' placement and surface velocities
  std::vector<domel_pair_v2> wall_pairs_;
  domel_pair_v2 self_pair_{};
  Material own_material_;
  double gravity_[3] = {0, 0, 0};
  double skin_ = 0;
  double dt_ = 0;
  double time_ = 0;
  std::uint64_t steps_ = 0;
  std::size_t last_contacts_ = 0, last_wall_contacts_ = 0;
  double last_max_overlap_ratio_ = 0;
  std::vector<ThreadScratch> scratch_;
  std::vector<double> partial_, tier_partial_;  ///< per-thread counts of the integration passes
  std::vector<std::size_t> split_[2];  ///< per list tier (near, far): ranges of the threads (balance_pairs)
  std::size_t split_builds_ = 0;
  bool reduce_pending_ = false;
  bool contacts_counted_ = true;  ///< store_.contacts is up to date (count_contacts)
  bool kick_pending_ = false;  ///< the last step's second half kick is still to do (store())
  double pending_half_ = 0;    ///< its half time step
  double forces_time_ = 0;     ///< time_ at the last force evaluation (wall activity)
  std::vector<double> bad_partial_;  ///< per-thread counts of non-finite particles
  /// refresh_wall_work: (particle, wall cost of the entries up to this one), ascending in particle
  std::vector<std::pair<uint32_t, double>> wall_work_;
  std::vector<std::size_t> split_cuts_;       ///< reduce_split's segment bounds and weights
  std::vector<double> split_weights_;
  std::vector<std::size_t> pass2_split_;  ///< particle ranges of the second half kick when it also reduces
  static constexpr std::size_t kReorderMinParticles = 5000;
  std::size_t reorder_every_ = 20;  ///< list builds between spatial re-orderings (0: never)
  std::size_t builds_since_reorder_ = SIZE_MAX / 2;  ///< re-order at the first build
  std::size_t reordered_size_ = 0;
    bool walls_force_rebuild_ = false;  ///< a moving wall travelled skin/2 since its list was built
  bool record_ = false;    ///< fill ThreadScratch::records (set_record_contacts)
  bool far_active_ = true;  ///< the far tier of the pair list is screened (see NeighborList::near_size)
  std::unique_ptr<ThreadPool> pool_;
};

}  // namespace domel::platform
