// SPDX-License-Identifier: MIT
// Slot assembly and batch evaluation of the contact model.
#include "contact/contact_pipeline.hpp"

#include <algorithm>

namespace domel::platform {

ContactPipeline::ContactPipeline(std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots)
    : slots_(std::move(slots)) {
  for (std::size_t s = 0; s < kSlotCount; ++s) {
    offset_[s] = history_stride_;
    if (slots_[s]) history_stride_ += slots_[s]->history_slots();
  }
  const std::size_t n = kBatchSize;
  for (auto* v : {&buf_.overlap, &buf_.nx, &buf_.ny, &buf_.nz, &buf_.r_eff, &buf_.m_eff, &buf_.radius_i,
                  &buf_.radius_j, &buf_.vn, &buf_.vtx, &buf_.vty, &buf_.vtz, &buf_.wx, &buf_.wy, &buf_.wz,
                  &buf_.fn_elastic, &buf_.kn, &buf_.kn_tangent, &buf_.contact_radius, &buf_.fn_damping,
                  &buf_.eta_n, &buf_.fn, &buf_.ftx, &buf_.fty, &buf_.ftz, &buf_.tqx, &buf_.tqy, &buf_.tqz,
                  &buf_.rolling_stiffness, &buf_.rolling_damping})
    v->assign(n, 0.0);
  buf_.history.assign(n * std::max<uint32_t>(history_stride_, 1), 0.0);

  auto& b = batch_;
  b.struct_size = sizeof(domel_contact_batch_v1);
  b.overlap = buf_.overlap.data();
  b.nx = buf_.nx.data(); b.ny = buf_.ny.data(); b.nz = buf_.nz.data();
  b.r_eff = buf_.r_eff.data(); b.m_eff = buf_.m_eff.data();
  b.radius_i = buf_.radius_i.data(); b.radius_j = buf_.radius_j.data();
  b.vn = buf_.vn.data();
  b.vtx = buf_.vtx.data(); b.vty = buf_.vty.data(); b.vtz = buf_.vtz.data();
  b.wx = buf_.wx.data(); b.wy = buf_.wy.data(); b.wz = buf_.wz.data();
  b.fn_elastic = buf_.fn_elastic.data(); b.kn = buf_.kn.data(); b.kn_tangent = buf_.kn_tangent.data();
  b.contact_radius = buf_.contact_radius.data();
  b.fn_damping = buf_.fn_damping.data(); b.eta_n = buf_.eta_n.data(); b.fn = buf_.fn.data();
  b.ftx = buf_.ftx.data(); b.fty = buf_.fty.data(); b.ftz = buf_.ftz.data();
  b.tqx = buf_.tqx.data(); b.tqy = buf_.tqy.data(); b.tqz = buf_.tqz.data();
  b.history_stride = history_stride_;
  b.rolling_stiffness = buf_.rolling_stiffness.data();
  b.rolling_damping = buf_.rolling_damping.data();
}

void ContactPipeline::evaluate(const domel_pair_v1& pair, double dt, uint32_t n) {
  auto& b = batch_;
  b.n = n;
  b.dt = dt;
  b.pair = &pair;
  auto run = [&](Slot s) {
    const auto& inst = slots_[static_cast<int>(s)];
    if (!inst) return;
    b.history = buf_.history.data() + offset_[static_cast<int>(s)];
    inst->contact(b);
  };
  run(Slot::normal);
  run(Slot::damping);
  for (uint32_t c = 0; c < n; ++c) buf_.fn[c] = buf_.fn_elastic[c] + buf_.fn_damping[c];
  run(Slot::tangential);
  std::fill_n(buf_.tqx.begin(), n, 0.0);
  std::fill_n(buf_.tqy.begin(), n, 0.0);
  std::fill_n(buf_.tqz.begin(), n, 0.0);
  if (slots_[static_cast<int>(Slot::rolling)]) {
    std::fill_n(buf_.rolling_stiffness.begin(), n, 0.0);
    std::fill_n(buf_.rolling_damping.begin(), n, 0.0);
  }
  run(Slot::rolling);
  run(Slot::twisting);
}

}  // namespace domel::platform
