// SPDX-License-Identifier: MIT
#include "geometry/wall_motion.hpp"

#include "core/rotation.hpp"

#include <algorithm>

namespace domel::platform {

namespace {

double norm(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/// A translating item's displacement and velocity at t.
void translation_of(const MotionItem& it, double t, double d[3], double u[3]) {
  const double e = it.elapsed(t);
  const bool on = it.active(t);
  switch (it.kind) {
    case MotionItem::Kind::translation:
      for (int a = 0; a < 3; ++a) {
        d[a] = it.vec[a] * e;
        u[a] = on ? it.vec[a] : 0.0;
      }
      return;
    case MotionItem::Kind::vibration: {
      const double s = std::sin(it.omega_f * e + it.phase) - std::sin(it.phase);
      const double c = on ? it.omega_f * std::cos(it.omega_f * e + it.phase) : 0.0;
      for (int a = 0; a < 3; ++a) {
        d[a] = it.vec[a] * s;
        u[a] = it.vec[a] * c;
      }
      return;
    }
    case MotionItem::Kind::servo: {
      // the travel stops changing outside the item's window
      const double s = it.servo ? it.servo->travel(std::min(std::max(t, it.start), it.end)) : 0.0;
      const double v = it.servo && on ? it.servo->velocity : 0.0;
      for (int a = 0; a < 3; ++a) {
        d[a] = it.vec[a] * s;
        u[a] = it.vec[a] * v;
      }
      return;
    }
    case MotionItem::Kind::rotation: break;
  }
  d[0] = d[1] = d[2] = u[0] = u[1] = u[2] = 0.0;
}

}  // namespace

WallMotion WallMotion::constant(const double velocity[3], const double omega[3], const double origin[3], double start,
                                double end) {
  WallMotion m;
  MotionItem rot;
  rot.kind = MotionItem::Kind::rotation;
  MotionItem tr;
  tr.kind = MotionItem::Kind::translation;
  for (auto* it : {&rot, &tr}) {
    it->start = start;
    it->end = end;
  }
  for (int a = 0; a < 3; ++a) {
    rot.vec[a] = omega[a];
    rot.origin[a] = origin[a];
    tr.vec[a] = velocity[a];
  }
  if (norm(omega) > 0) m.items.push_back(rot);
  if (norm(velocity) > 0) m.items.push_back(tr);
  return m;
}

WallPose WallMotion::pose_at(double t) const {
  WallPose p;
  for (const MotionItem& it : items) {
    if (it.kind != MotionItem::Kind::rotation) {
      double d[3], u[3];
      translation_of(it, t, d, u);
      for (int a = 0; a < 3; ++a) {
        p.d[a] += d[a];
        p.d_dot[a] += u[a];
      }
      continue;
    }
    // x -> Ri (x - o) + o applied to x = R x0 + d:
    //   R' = Ri R, d' = Ri (d - o) + o,
    //   omega' = w + Ri omega, d_dot' = w x (Ri (d - o)) + Ri d_dot
    // (w: the item's angular velocity while it is active, else 0)
    const double w = norm(it.vec);
    if (w <= 0.0) continue;
    const double k[3] = {it.vec[0] / w, it.vec[1] / w, it.vec[2] / w};
    double Ri[9];
    rotation_matrix(k, w * it.elapsed(t), Ri);
    double R[9];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        R[3 * r + c] = Ri[3 * r] * p.R[c] + Ri[3 * r + 1] * p.R[3 + c] + Ri[3 * r + 2] * p.R[6 + c];
    std::copy(R, R + 9, p.R);
    const double rel[3] = {p.d[0] - it.origin[0], p.d[1] - it.origin[1], p.d[2] - it.origin[2]};
    double rr[3], om[3], dd[3];
    mat_vec(Ri, rel, rr);
    mat_vec(Ri, p.omega, om);
    mat_vec(Ri, p.d_dot, dd);
    const bool on = it.active(t);
    const double wv[3] = {on ? it.vec[0] : 0.0, on ? it.vec[1] : 0.0, on ? it.vec[2] : 0.0};
    for (int a = 0; a < 3; ++a) {
      p.d[a] = rr[a] + it.origin[a];
      p.omega[a] = wv[a] + om[a];
    }
    p.d_dot[0] = wv[1] * rr[2] - wv[2] * rr[1] + dd[0];
    p.d_dot[1] = wv[2] * rr[0] - wv[0] * rr[2] + dd[1];
    p.d_dot[2] = wv[0] * rr[1] - wv[1] * rr[0] + dd[2];
  }
  return p;
}

const MotionItem* WallMotion::first_rotation() const {
  for (const MotionItem& it : items)
    if (it.kind == MotionItem::Kind::rotation && norm(it.vec) > 0) return &it;
  return nullptr;
}

double WallMotion::displacement_bound(double t0, double t1, const std::vector<double>& reach) const {
  // Telescoping over the items (each placement is an isometry): the move of
  // a point is at most the sum over items i of how far item i's change from
  // t0 to t1 moves the points as the items before it left them at t0, which
  // lie within cum_i of their reference position.
  double bound = 0.0, cum = 0.0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const MotionItem& it = items[i];
    if (it.kind == MotionItem::Kind::rotation) {
      const double w = norm(it.vec);
      const double r = (i < reach.size() ? reach[i] : std::numeric_limits<double>::infinity()) + cum;
      const double a0 = w * it.elapsed(t0), a1 = w * it.elapsed(t1);
      if (a1 != a0) bound += std::fabs(a1 - a0) * r;  // chord <= arc
      if (a0 > 0.0) cum += std::min(a0, 2.0) * r;    // |R(a) - I| = 2 sin(a/2) <= min(a, 2)
      continue;
    }
    double d0[3], d1[3], u[3];
    translation_of(it, t0, d0, u);
    if (it.kind == MotionItem::Kind::servo && it.servo) {
      // the travel's history is not kept: bound it by the speed limit
      const double e0 = std::clamp(t0, it.start, it.end), e1 = std::clamp(t1, it.start, it.end);
      if (e1 != e0) bound += it.servo->max_velocity * std::fabs(e1 - e0);
      cum += std::fabs(it.servo->travel(e1)) + (e1 != e0 ? it.servo->max_velocity * std::fabs(e1 - e0) : 0.0);  // >= |travel(e0)|
      continue;
    }
    translation_of(it, t1, d1, u);
    const double diff[3] = {d1[0] - d0[0], d1[1] - d0[1], d1[2] - d0[2]};
    bound += norm(diff);
    cum += norm(d0);
  }
  return bound;
}

}  // namespace domel::platform
