// SPDX-License-Identifier: MIT
// The contact sweep: the contacts of a pair list and of the wall lists are
// gathered into batches, evaluated by the slot pipeline, and scattered as
// forces and torques. Pairs and walls share one gather (the contact points'
// relative velocity into a batch slot) and one scatter (a slot's force and
// lever-arm torque); they differ only in how a contact is found (a list
// entry's overlap, a wall's gap) and in who receives the reaction.
//
// Contact geometry (docs/physics.md notation): n points from j to i,
// overlap delta = R_i + R_j - |x_i - x_j|. The lever arm from a particle
// centre to the contact point is c_i = R_i - delta/2 for a particle pair
// (the middle of the overlap, as LIGGGHTS' c_ri) and c_i = R_i - delta for a
// wall (the contact point lies on the wall surface).
// Relative velocity of the contact points: v_c = (v_i + w_i x (-c_i n)) - (v_j + w_j x (c_j n)).
// Forces: F_i = F_n n + F_t, F_j = -F_i. Torques: T_i = -c_i n x F_t + M,
// T_j = -c_j n x F_t - M (M: rolling/twisting couple on i).
//
// Fields: reads the store's x, y, z, v, w, radius, mass (the pair screen
// its packed copy of x, y, z and radius, PackedPositions); adds into the
// accumulators' f and t; reads and writes the lists' touching flags and
// history rows.
#pragma once

#include "averaging/cell_grid.hpp"
#include "contact/contact_pipeline.hpp"
#include "core/neighbor_list.hpp"
#include "core/particle_store.hpp"
#include "geometry/triangle_mesh.hpp"
#include "geometry/wall.hpp"
#include "geometry/wall_neighbors.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace domel::platform {

/// Where a sweep adds forces and torques: the store itself or a thread's own arrays.
struct ForceAccumulator {
  double *fx, *fy, *fz, *tx, *ty, *tz;
  static ForceAccumulator of(ParticleStore& s) {
    return {s.fx.data(), s.fy.data(), s.fz.data(), s.tx.data(), s.ty.data(), s.tz.data()};
  }
};

/// One thread's batch workspace and what its sweeps counted.
struct ContactScratch {
  explicit ContactScratch(const ContactPipeline& pipeline);
  std::unique_ptr<ContactPipeline::Workspace> ws;
  std::vector<uint32_t> entry;         ///< list entry of each batch slot
  std::vector<double> ci, cj;          ///< lever arms of each batch slot
  std::vector<ContactRecord> records;  ///< contact forces on recording steps
  std::vector<double> wall_load;       ///< per wall primitive with track_load: the force on its particles (x, y, z)
  /// Several materials: the batch's grouping by material pair (counts,
  /// the sorted entries, the runs as (first slot, pair)) and the wall
  /// contacts staged before it.
  std::vector<uint32_t> key_count, sorted;
  std::vector<std::pair<uint32_t, uint32_t>> runs;
  struct WallCandidate {
    uint32_t entry, particle;
    double d, nx, ny, nz;
  };
  std::vector<WallCandidate> staged;
  std::size_t pair_contacts = 0;
  double pair_max_ratio = 0;
  std::size_t wall_contacts = 0;
  double wall_max_ratio = 0;
  MeshScratch mesh;                    ///< mesh walls: per-particle feature bookkeeping
  std::vector<MeshContact> mesh_out;
  std::vector<uint8_t> counted;
};

/// The particles' positions and radii packed for the pair sweep's overlap
/// screen: per particle x, y, z and radius in one 32-byte row, so that a
/// list entry loads its two particles with four 16-byte loads instead of
/// eight scalar ones from four arrays (the screen visits every entry of the
/// list each step and was bound by its loads; docs/performance.md,
/// 2026-12-05, fourth session). A copy of the store's x, y, z and radius,
/// valid from its fill until the next change of either: the subdomain fills
/// it right before each force evaluation (the fused step's first sweep
/// writes it as it drifts). Values are copied, never recomputed, so the
/// screen's arithmetic and results are those of the arrays.
struct PackedPositions {
  std::vector<double> xyzr;  ///< [4 k, 4 k + 4): x, y, z and radius of particle k (16-byte aligned)
  /// Size the array for n particles (no fill).
  void resize(std::size_t n) { xyzr.resize(4 * n); }
  /// Copy particles [first, last) of the store (the array sized by resize());
  /// kick_drift (integrator.cpp) writes the same rows as it drifts.
  void fill(const ParticleStore& s, std::size_t first, std::size_t last);
  std::size_t bytes() const { return xyzr.capacity() * sizeof(double); }
};
static_assert(__STDCPP_DEFAULT_NEW_ALIGNMENT__ >= 16, "the pair screen reads PackedPositions rows as aligned 16-byte pairs");

/// The inputs of the pair sweep of one force evaluation.
struct PairSweep {
  const ParticleStore* store;
  NeighborList* list;
  const ContactPipeline* pipeline;
  /// The classes of material pairs that act alike (Subdomain): their
  /// constants and rolling models (null: none), and the class of the pair of
  /// local materials a and b at [a * n_materials + b]. One class: every
  /// contact takes class 0's.
  const domel_pair_v2* pairs;
  const ModelInstance* const* rolling;
  const uint16_t* pair_class;
  uint32_t n_classes;
  uint32_t n_materials;
  double dt;
  bool record;  ///< append each contact's force to ContactScratch::records
  const double* packed;  ///< the store's positions and radii, packed and filled (PackedPositions::xyzr)
};

/// The pair contacts of list entries [first, last). Forces on particles in
/// [own_lo, own_hi) go to `own`, on the others to `shared`; without kZoned
/// all go to `own`. kTorque: the pipeline has a rolling or twisting model,
/// whose couples are added.
using PairRangeFn = void (*)(const PairSweep&, std::size_t first, std::size_t last, ContactScratch& ts,
                             std::size_t own_lo, std::size_t own_hi, const ForceAccumulator& own,
                             const ForceAccumulator& shared);
/// The pair_range instance for a pipeline (with or without a couple, with or
/// without the masses its stages read), with or without zones, for one
/// class of material pairs or several (`mixed`: each batch is grouped by
/// class and evaluated run by run; one class keeps the single-pair path).
PairRangeFn pair_kernel(const ContactPipeline& pipeline, bool zoned, bool mixed, bool periodic);

/// The inputs of the wall sweep of one force evaluation.
struct WallSweep {
  ParticleStore* store;
  std::vector<WallNeighbors>* lists;
  const std::vector<WallPrimitive>* walls;   ///< placed at wall_time
  const domel_pair_v2* pairs;                ///< [w * n_materials + a], per wall and particle material
  const ModelInstance* const* rolling;       ///< the rolling model of each pair, same order (null: none)
  const uint8_t* uniform;                    ///< per wall: every material meets it alike (one run, no grouping)
  uint32_t n_materials;
  const ContactPipeline* pipeline;
  double dt;
  double forces_time;  ///< the force evaluation's time (which walls are active)
  double wall_time;    ///< the walls' placement time (surface velocities)
  bool record;
};

/// The wall contacts of the particles with index in [first, last), added
/// straight into the store. Each touches one particle, so threads with
/// disjoint particle ranges may run this at once. Wall lists are in index order.
void wall_range(const WallSweep& sweep, ContactScratch& ts, std::size_t first, std::size_t last);

}  // namespace domel::platform
