// Guards the per-contact material-pair sets of the contact pipeline (abi.h,
// domel_contact_batch_v2::pair_of): a batch that mixes two pair sets,
// grouped or interleaved, gives every contact exactly (bit for bit) the
// forces, torques and history it gets in a uniform batch of its own pair,
// through the built-in normal, damping, tangential and rolling plugins; and
// mass_i/mass_j reach the kernels (the uniform path stays the one used by runs).
#include "contact/contact_pipeline.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <vector>

namespace {

using domel::platform::ContactPipeline;
using domel::platform::kSlotCount;
using domel::platform::ModelInstance;

std::unique_ptr<ContactPipeline> make_pipeline() {
  auto& reg = domel::test::builtin_registry();
  std::array<std::unique_ptr<ModelInstance>, kSlotCount> slots;
  const auto add = [&](std::size_t s, uint32_t kind, const char* name, const nlohmann::json& params) {
    const auto* m = reg.find(kind, name);
    if (m == nullptr) throw std::runtime_error(std::string("built-in model not loaded: ") + name);
    slots[s] = std::make_unique<ModelInstance>(*m, params, "test");
  };
  add(0, DOMEL_KIND_NORMAL, "hertz", nlohmann::json::object());
  add(1, DOMEL_KIND_DAMPING, "restitution", nlohmann::json::object());
  add(2, DOMEL_KIND_TANGENTIAL, "mindlin", nlohmann::json::object());
  add(3, DOMEL_KIND_ROLLING, "sd_critical_angle", {{"critical_angle", 20.0}});
  return std::make_unique<ContactPipeline>(std::move(slots));
}

domel_pair_v2 pair(double e_star, double restitution, double friction, double mu_r) {
  domel_pair_v2 p{};
  p.struct_size = sizeof p;
  p.youngs_eff = e_star;
  p.shear_eff = 0.4 * e_star;
  p.restitution = restitution;
  p.friction = friction;
  p.coarse_grain = 1.0;
  p.has_rolling_friction = mu_r > 0 ? 1u : 0u;
  p.rolling_friction = mu_r;
  return p;
}

/// Contact c's inputs (varied kinematics; a history that makes the tangential spring slip for some).
void fill(ContactPipeline::Buffers& b, uint32_t q, uint32_t c) {
  const double s = 1.0 + 0.1 * c;
  b.overlap[q] = 2e-6 * s;
  b.nx[q] = 0.0; b.ny[q] = 0.6; b.nz[q] = 0.8;
  b.r_eff[q] = 7e-4; b.m_eff[q] = 1.5e-5;
  b.radius_i[q] = 1.4e-3; b.radius_j[q] = 1.4e-3;
  b.mass_i[q] = 3e-5; b.mass_j[q] = 3e-5;
  b.vn[q] = 0.05 * s;
  b.vtx[q] = 0.02 * s; b.vty[q] = -0.01 * c; b.vtz[q] = 0.0075 * c;
  b.wx[q] = 3.0 * s; b.wy[q] = -2.0; b.wz[q] = 1.0 * c;
}

}  // namespace

TEST(ContactPipeline, MixedPairBatchEqualsUniformBatchesBitForBit) {
  auto pipe = make_pipeline();
  const uint32_t stride = pipe->history_stride();
  ASSERT_EQ(stride, 6u);  // mindlin 3 + sd_critical_angle 3
  EXPECT_FALSE(pipe->reads_masses());  // every built-in stage declares DOMEL_CONTACT_IGNORES_MASSES
  const domel_pair_v2 a = pair(5e8, 0.5, 0.3, 0.0), b = pair(2e9, 0.8, 0.7, 0.25);
  for (const auto& order : {std::vector<int>{0, 0, 0, 1, 1, 1}, std::vector<int>{0, 1, 0, 1, 1, 0}}) {
    const uint32_t n = static_cast<uint32_t>(order.size());
    auto mixed = pipe->make_workspace();
    for (uint32_t c = 0; c < n; ++c) {
      fill(mixed->buf, c, c);
      mixed->buf.pair_of[c] = order[c] ? &b : &a;
      for (uint32_t h = 0; h < stride; ++h) mixed->buf.history[c * stride + h] = 1e-7 * (h + 1) * (c + 1);
    }
    pipe->evaluate(*mixed, 1e-6, n);
    for (uint32_t c = 0; c < n; ++c) {
      auto one = pipe->make_workspace();
      fill(one->buf, 0, c);
      for (uint32_t h = 0; h < stride; ++h) one->buf.history[h] = 1e-7 * (h + 1) * (c + 1);
      pipe->evaluate(*one, order[c] ? b : a, 1e-6, 1);
      EXPECT_EQ(one->buf.fn[0], mixed->buf.fn[c]) << c;
      EXPECT_EQ(one->buf.ftx[0], mixed->buf.ftx[c]) << c;
      EXPECT_EQ(one->buf.fty[0], mixed->buf.fty[c]) << c;
      EXPECT_EQ(one->buf.tqx[0], mixed->buf.tqx[c]) << c;
      EXPECT_EQ(one->buf.tqz[0], mixed->buf.tqz[c]) << c;
      EXPECT_EQ(one->buf.rolling_stiffness[0], mixed->buf.rolling_stiffness[c]) << c;
      for (uint32_t h = 0; h < stride; ++h) EXPECT_EQ(one->buf.history[h], mixed->buf.history[c * stride + h]) << c;
    }
    // not vacuous: contact 0 under the other pair's set gives another force
    auto other = pipe->make_workspace();
    fill(other->buf, 0, 0);
    pipe->evaluate(*other, order[0] ? a : b, 1e-6, 1);
    EXPECT_NE(other->buf.fn[0], mixed->buf.fn[0]);
  }
  // a uniform call sets pair and leaves pair_of null, as kernels of ABI 1 read it
  auto ws = pipe->make_workspace();
  fill(ws->buf, 0, 0);
  pipe->evaluate(*ws, a, 1e-6, 1);
  EXPECT_EQ(ws->batch.pair, &a);
  EXPECT_EQ(ws->batch.pair_of, nullptr);
  EXPECT_EQ(ws->batch.mass_i, ws->buf.mass_i.data());
  EXPECT_EQ(ws->batch.mass_j, ws->buf.mass_j.data());
}
