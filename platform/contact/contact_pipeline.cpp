// SPDX-License-Identifier: MIT
// Slot assembly and batch evaluation of the contact model.
#include "contact/contact_pipeline.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>

namespace domel::platform {

ContactPipeline::ContactPipeline(std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots,
                                 std::vector<std::unique_ptr<ModelInstance>> pair_rolling)
    : slots_(std::move(slots)), pair_rolling_(std::move(pair_rolling)) {
  for (std::size_t s = 0; s < kSlotCount; ++s) {
    offset_[s] = history_stride_;
    uint32_t slice = slots_[s] ? slots_[s]->history_slots() : 0;
    if (slots_[s] && slots_[s]->reads_masses()) reads_masses_ = true;
    if (s == static_cast<std::size_t>(Slot::rolling))
      for (const auto& m : pair_rolling_)
        if (m) {
          slice = std::max(slice, m->history_slots());
          reads_masses_ = reads_masses_ || m->reads_masses();
          has_rolling_ = true;
        }
    history_stride_ += slice;
  }
  has_rolling_ = has_rolling_ || slots_[static_cast<int>(Slot::rolling)];
  main_ = make_workspace();
}

void ContactPipeline::Workspace::AlignedFree::operator()(void* p) const { std::free(p); }

ContactPipeline::Workspace::Workspace(uint32_t history_stride) {
  const std::size_t n = kBatchSize;
  const std::initializer_list<BatchArray*> arrays = {
      &buf.overlap, &buf.nx, &buf.ny, &buf.nz, &buf.r_eff, &buf.m_eff, &buf.radius_i, &buf.radius_j,
      &buf.mass_i, &buf.mass_j, &buf.vn, &buf.vtx, &buf.vty, &buf.vtz, &buf.wx, &buf.wy, &buf.wz, &buf.fn_elastic,
      &buf.kn, &buf.kn_tangent, &buf.contact_radius, &buf.fn_damping, &buf.eta_n, &buf.fn, &buf.ftx, &buf.fty,
      &buf.ftz, &buf.tqx, &buf.tqy, &buf.tqz, &buf.rolling_stiffness, &buf.rolling_damping};
  static_assert(kArrayStride % 64 == 0, "arrays start on cache lines");
  const std::size_t bytes = arrays.size() * kArrayStride;
  block_.reset(static_cast<double*>(std::aligned_alloc(64, bytes)));
  if (!block_) throw std::bad_alloc();
  std::memset(block_.get(), 0, bytes);
  std::size_t k = 0;
  for (BatchArray* a : arrays)
    a->p = reinterpret_cast<double*>(reinterpret_cast<char*>(block_.get()) + kArrayStride * k++);
  buf.history.assign(n * std::max<uint32_t>(history_stride, 1), 0.0);
  buf.pair_of.assign(n, nullptr);

  auto& b = batch;
  b.struct_size = sizeof(domel_contact_batch_v2);
  b.overlap = buf.overlap.data();
  b.nx = buf.nx.data(); b.ny = buf.ny.data(); b.nz = buf.nz.data();
  b.r_eff = buf.r_eff.data(); b.m_eff = buf.m_eff.data();
  b.radius_i = buf.radius_i.data(); b.radius_j = buf.radius_j.data();
  b.mass_i = buf.mass_i.data(); b.mass_j = buf.mass_j.data();
  b.vn = buf.vn.data();
  b.vtx = buf.vtx.data(); b.vty = buf.vty.data(); b.vtz = buf.vtz.data();
  b.wx = buf.wx.data(); b.wy = buf.wy.data(); b.wz = buf.wz.data();
  b.fn_elastic = buf.fn_elastic.data(); b.kn = buf.kn.data(); b.kn_tangent = buf.kn_tangent.data();
  b.contact_radius = buf.contact_radius.data();
  b.fn_damping = buf.fn_damping.data(); b.eta_n = buf.eta_n.data(); b.fn = buf.fn.data();
  b.ftx = buf.ftx.data(); b.fty = buf.fty.data(); b.ftz = buf.ftz.data();
  b.tqx = buf.tqx.data(); b.tqy = buf.tqy.data(); b.tqz = buf.tqz.data();
  b.history_stride = history_stride;
  b.rolling_stiffness = buf.rolling_stiffness.data();
  b.rolling_damping = buf.rolling_damping.data();
}

void ContactPipeline::evaluate(Workspace& ws, const domel_pair_v2& pair, const ModelInstance* rolling, double dt,
                               uint32_t n) const {
  ws.batch.pair = &pair;  // one pair for the batch: read once per batch by the kernels (abi.h)
  ws.batch.pair_of = nullptr;
  run_stages(ws.batch, ws.buf.history.data(), rolling, dt, n);
}

void ContactPipeline::evaluate(Workspace& ws, double dt, uint32_t n) const {
  ws.batch.pair = nullptr;
  ws.batch.pair_of = ws.buf.pair_of.data();
  run_stages(ws.batch, ws.buf.history.data(), slot(Slot::rolling), dt, n);
}

void ContactPipeline::evaluate_range(Workspace& ws, const domel_pair_v2& pair, const ModelInstance* rolling,
                                     double dt, uint32_t first, uint32_t n) const {
  if (first == 0) return evaluate(ws, pair, rolling, dt, n);
  domel_contact_batch_v2 b = ws.batch;  // the same arrays, from contact `first` on
  b.pair = &pair;
  b.pair_of = nullptr;
  for (const double** p : {&b.overlap, &b.nx, &b.ny, &b.nz, &b.r_eff, &b.m_eff, &b.radius_i, &b.radius_j, &b.mass_i,
                           &b.mass_j, &b.vn, &b.vtx, &b.vty, &b.vtz, &b.wx, &b.wy, &b.wz})
    *p += first;
  for (double** p : {&b.fn_elastic, &b.kn, &b.kn_tangent, &b.contact_radius, &b.fn_damping, &b.eta_n, &b.fn, &b.ftx,
                     &b.fty, &b.ftz, &b.tqx, &b.tqy, &b.tqz, &b.rolling_stiffness, &b.rolling_damping})
    *p += first;
  run_stages(b, ws.buf.history.data() + static_cast<std::size_t>(first) * history_stride_, rolling, dt, n);
}

void ContactPipeline::run_stages(domel_contact_batch_v2& b, double* history, const ModelInstance* rolling, double dt,
                                 uint32_t n) const {
  b.n = n;
  b.dt = dt;
  auto run = [&](Slot s) {
    const ModelInstance* inst = s == Slot::rolling ? rolling : slots_[static_cast<int>(s)].get();
    if (!inst) return;
    b.history = history + offset_[static_cast<int>(s)];
    inst->contact(b);
  };
  run(Slot::normal);
  run(Slot::damping);
  for (uint32_t c = 0; c < n; ++c) b.fn[c] = b.fn_elastic[c] + b.fn_damping[c];
  run(Slot::tangential);
  if (has_torque()) {  // else they stay zero from the workspace's construction: only these slots write them
    std::fill_n(b.tqx, n, 0.0);
    std::fill_n(b.tqy, n, 0.0);
    std::fill_n(b.tqz, n, 0.0);
  }
  if (has_rolling_) {  // a pair without a rolling model reports none
    std::fill_n(b.rolling_stiffness, n, 0.0);
    std::fill_n(b.rolling_damping, n, 0.0);
  }
  run(Slot::rolling);
  run(Slot::twisting);
}

}  // namespace domel::platform
