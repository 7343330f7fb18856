// SPDX-License-Identifier: MIT
// The contact model of a subdomain: slots filled at run time by plugin
// instances and evaluated in a fixed order on batches of contacts
// (normal -> damping -> F_n sum -> tangential -> rolling -> twisting),
// as LAMMPS' granular sub-models are (style.md). Each slot owns a slice of
// the per-contact history; the pipeline lays the slices out in one stride.
//
// Callers fill the input arrays of a Workspace for up to kBatchSize contacts
// (and their history rows; the masses when reads_masses(): mass_j = 0 for a
// wall), call
// evaluate(workspace, pair, rolling, dt, n) when every contact shares one
// material pair (the batch then carries the pair once, abi.h; `rolling` is
// the pair's rolling model), or
// evaluate(workspace, dt, n) after filling buf.pair_of per contact, grouped
// by pair, for a batch of several pairs; then read fn and the tangential
// force and torque outputs. The slot instances are
// shared; each thread uses its own Workspace (kernels may run concurrently
// on one instance, see abi.h).
#pragma once

#include "loader/plugin_registry.hpp"

#include <array>
#include <memory>
#include <vector>

namespace domel::platform {

enum class Slot { normal = 0, damping, tangential, rolling, twisting };
constexpr std::size_t kSlotCount = 5;
constexpr const char* kSlotNames[kSlotCount] = {"normal", "damping", "tangential", "rolling", "twisting"};

class ContactPipeline {
 public:
  static constexpr uint32_t kBatchSize = 256;

  /// normal, damping and tangential are required; rolling and twisting may
  /// be null. `pair_rolling`: the rolling models that material pairs name in
  /// place of the rolling slot's (interactions[].rolling), indexed as
  /// rolling_model() takes them; they share the rolling slot's slice of the
  /// history, as long as the longest of them.
  explicit ContactPipeline(std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots,
                           std::vector<std::unique_ptr<ModelInstance>> pair_rolling = {});

  /// PairCoefficients::rolling_model of a pair: the rolling slot's model
  /// (kSubdomainRolling), none (kNoRolling, null) or pair model k.
  static constexpr int kSubdomainRolling = -1;
  static constexpr int kNoRolling = -2;
  const ModelInstance* rolling_model(int k) const {
    if (k == kSubdomainRolling) return slot(Slot::rolling);
    return k >= 0 ? pair_rolling_.at(static_cast<std::size_t>(k)).get() : nullptr;
  }

  uint32_t history_stride() const { return history_stride_; }
  const ModelInstance* slot(Slot s) const { return slots_[static_cast<int>(s)].get(); }
  /// A rolling or twisting model (of the slot or of a pair) fills the torque
  /// couples (tqx, tqy, tqz); without one they stay zero.
  bool has_torque() const { return has_rolling_ || slots_[static_cast<int>(Slot::twisting)]; }
  /// Whether some stage reads the batch's mass_i/mass_j; when none does,
  /// the gathers leave them unfilled (abi.h, DOMEL_CONTACT_IGNORES_MASSES).
  bool reads_masses() const { return reads_masses_; }

  /// One per-contact array of a batch: kBatchSize doubles inside the
  /// workspace's block.
  struct BatchArray {
    double* p = nullptr;
    double* data() const { return p; }
    double& operator[](std::size_t c) const { return p[c]; }
    double* begin() const { return p; }
    double* end() const { return p + kBatchSize; }
  };
  /// Buffers of one batch (structure of arrays, capacity kBatchSize).
  struct Buffers {
    BatchArray overlap, nx, ny, nz, r_eff, m_eff, radius_i, radius_j, mass_i, mass_j, vn, vtx, vty, vtz, wx, wy, wz;
    BatchArray fn_elastic, kn, kn_tangent, contact_radius, fn_damping, eta_n, fn;
    BatchArray ftx, fty, ftz, tqx, tqy, tqz;
    BatchArray rolling_stiffness, rolling_damping;
    std::vector<double> history;  ///< kBatchSize * history_stride
    std::vector<const domel_pair_v2*> pair_of;  ///< per contact, for a batch of several pairs
  };
  /// One thread's batch buffers and the ABI view of them. The per-contact
  /// arrays lie in one cache-line-aligned block, kArrayStride bytes apart:
  /// 2 KiB of data plus 3 cache lines, so that no two arrays start at the
  /// same address modulo 4 KiB (35 and 64 are coprime). Element c of any two
  /// arrays then never shares the low 12 address bits, which the CPU's
  /// store-to-load check compares first (4K aliasing: a load from one array
  /// stalls behind a store to another at the same offset, as separately
  /// allocated 2 KiB vectors can land).
  class Workspace {
   public:
    static constexpr std::size_t kArrayStride = kBatchSize * sizeof(double) + 3 * 64;
    explicit Workspace(uint32_t history_stride);
    Workspace(const Workspace&) = delete;
    Workspace& operator=(const Workspace&) = delete;
    Buffers buf;
    domel_contact_batch_v2 batch{};

   private:
    struct AlignedFree {
      void operator()(void* p) const;
    };
    std::unique_ptr<double, AlignedFree> block_;
  };
  std::unique_ptr<Workspace> make_workspace() const { return std::make_unique<Workspace>(history_stride_); }

  /// Evaluate all stages on the first n contacts of a workspace, all of one
  /// material pair, whose rolling model is `rolling` (rolling_model() of
  /// the pair; null: none).
  void evaluate(Workspace& ws, const domel_pair_v2& pair, const ModelInstance* rolling, double dt, uint32_t n) const;
  /// The same with the rolling slot's model.
  void evaluate(Workspace& ws, const domel_pair_v2& pair, double dt, uint32_t n) const {
    evaluate(ws, pair, slot(Slot::rolling), dt, n);
  }
  /// The same for a batch of several pairs: contact c uses *ws.buf.pair_of[c]
  /// (and the rolling slot's model).
  void evaluate(Workspace& ws, double dt, uint32_t n) const;
  /// Evaluate contacts [first, first + n) of a workspace, all of one pair:
  /// a run of a batch grouped by material pair (the kernels see a batch
  /// that starts at `first`).
  void evaluate_range(Workspace& ws, const domel_pair_v2& pair, const ModelInstance* rolling, double dt,
                      uint32_t first, uint32_t n) const;

  /// The pipeline's own workspace, for single-threaded callers.
  Buffers& buffers() { return main_->buf; }
  void evaluate(const domel_pair_v2& pair, double dt, uint32_t n) { evaluate(*main_, pair, dt, n); }
  void evaluate(const domel_pair_v2& pair, const ModelInstance* rolling, double dt, uint32_t n) {
    evaluate(*main_, pair, rolling, dt, n);
  }

 private:
  std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots_;
  std::vector<std::unique_ptr<ModelInstance>> pair_rolling_;
  std::array<uint32_t, kSlotCount> offset_{};
  uint32_t history_stride_ = 0;
  bool reads_masses_ = false;
  bool has_rolling_ = false;  ///< the slot or some pair has a rolling model
  std::unique_ptr<Workspace> main_;
  /// The stages on batch b (its arrays may start inside the workspace's),
  /// with `rolling` in the rolling slot.
  void run_stages(domel_contact_batch_v2& b, double* history, const ModelInstance* rolling, double dt,
                  uint32_t n) const;
};

}  // namespace domel::platform
