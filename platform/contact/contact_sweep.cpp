// SPDX-License-Identifier: MIT
// The pair and wall sweeps of contact_sweep.hpp, with their shared gather
// (fill_slot) and scatter (load_of).
#include "contact/contact_sweep.hpp"

#include "core/error.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>

namespace domel::platform {

ContactScratch::ContactScratch(const ContactPipeline& pipeline)
    : ws(pipeline.make_workspace()),
      entry(ContactPipeline::kBatchSize),
      ci(ContactPipeline::kBatchSize),
      cj(ContactPipeline::kBatchSize) {}

void PackedPositions::fill(const ParticleStore& s, std::size_t first, std::size_t last) {
  double* out = xyzr.data();
  for (std::size_t k = first; k < last; ++k) {
    out[4 * k] = s.x[k];
    out[4 * k + 1] = s.y[k];
    out[4 * k + 2] = s.z[k];
    out[4 * k + 3] = s.radius[k];
  }
}

namespace {

// History rows are a few doubles (3 for Mindlin, 6 with a rolling model):
// copy them inline; std::copy_n becomes a memmove call that costs more than
// the copy itself at these sizes (perf: 6 % of a settle step).
inline void copy_row(const double* __restrict src, double* __restrict dst, uint32_t n) {
  switch (n) {
    case 0: return;
    case 1: dst[0] = src[0]; return;
    case 2: dst[0] = src[0]; dst[1] = src[1]; return;
    case 3: dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; return;
    case 4: dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; dst[3] = src[3]; return;
    case 5: dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; dst[3] = src[3]; dst[4] = src[4]; return;
    case 6:
      dst[0] = src[0]; dst[1] = src[1]; dst[2] = src[2]; dst[3] = src[3]; dst[4] = src[4]; dst[5] = src[5];
      return;
    default: std::copy_n(src, n, dst);
  }
}

/// The batch arrays the gather fills.
struct Slots {
  double *overlap, *nx, *ny, *nz, *radius_i, *radius_j, *r_eff, *m_eff, *mass_i, *mass_j, *vn, *vtx, *vty, *vtz,
      *wx, *wy, *wz;
  explicit Slots(ContactPipeline::Buffers& b)
      : overlap(b.overlap.data()), nx(b.nx.data()), ny(b.ny.data()), nz(b.nz.data()),
        radius_i(b.radius_i.data()), radius_j(b.radius_j.data()), r_eff(b.r_eff.data()), m_eff(b.m_eff.data()),
        mass_i(b.mass_i.data()), mass_j(b.mass_j.data()), vn(b.vn.data()), vtx(b.vtx.data()), vty(b.vty.data()),
        vtz(b.vtz.data()), wx(b.wx.data()), wy(b.wy.data()), wz(b.wz.data()) {}
};

/// The gather, shared by pairs and walls: slot q of the batch from the
/// contact's geometry and the relative velocity (rx, ry, rz) of its contact
/// points, split into the normal approach speed and the tangential part.
/// A wall is partner j with rj = 0 and mj = 0. The masses are stored only
/// when a stage reads them (ContactPipeline::reads_masses).
inline void fill_slot(const Slots& b, bool masses, uint32_t q, double delta, double nx, double ny, double nz,
                      double ri, double rj, double r_eff, double mi, double mj, double m_eff, double rx, double ry,
                      double rz, double wx, double wy, double wz) {
  const double vdotn = rx * nx + ry * ny + rz * nz;
  b.overlap[q] = delta;
  b.nx[q] = nx; b.ny[q] = ny; b.nz[q] = nz;
  b.radius_i[q] = ri;
  b.radius_j[q] = rj;
  b.r_eff[q] = r_eff;
  b.m_eff[q] = m_eff;
  if (masses) {
    b.mass_i[q] = mi;
    b.mass_j[q] = mj;
  }
  b.vn[q] = -vdotn;
  b.vtx[q] = rx - vdotn * nx; b.vty[q] = ry - vdotn * ny; b.vtz[q] = rz - vdotn * nz;
  b.wx[q] = wx; b.wy[q] = wy; b.wz[q] = wz;
}

/// The velocity of a particle's contact point at lever arm s along n: v + s (w x n).
inline void point_velocity(double vx, double vy, double vz, double wx, double wy, double wz, double s, double nx,
                           double ny, double nz, double& ox, double& oy, double& oz) {
  ox = vx + s * (wy * nz - wz * ny);
  oy = vy + s * (wz * nx - wx * nz);
  oz = vz + s * (wx * ny - wy * nx);
}

/// The scatter's arithmetic, shared by pairs and walls: the force on i,
/// F = F_n n + F_t, and n x F_t, whose product with -c is the lever torque.
struct Load {
  double fx, fy, fz, cx, cy, cz;
};
inline Load load_of(double fn, double nx, double ny, double nz, double ftx, double fty, double ftz) {
  return {fn * nx + ftx, fn * ny + fty, fn * nz + ftz, ny * ftz - nz * fty, nz * ftx - nx * ftz, nx * fty - ny * ftx};
}

/// A kernel failed on a batch: the same error, naming the batch's contacts
/// by particle id (the first few; `partner` names the other side).
template <class Partner>
[[noreturn]] void throw_batch_failure(const PluginError& e, const ParticleStore& s, const uint32_t* entry,
                                      uint32_t c, const uint32_t* particle_of_entry, Partner&& partner) {
  constexpr uint32_t kShown = 4;
  std::string what = std::string(e.what()) + "; the batch held " + std::to_string(c) + " contact(s): ";
  for (uint32_t q = 0; q < std::min(c, kShown); ++q)
    what += (q ? ", " : "") + std::string("particle id ") + std::to_string(s.id[particle_of_entry[entry[q]]]) +
            " with " + partner(entry[q]);
  if (c > kShown) what += ", ...";
  throw PluginError(what);
}

// a - b and a + (-b) are the same IEEE operation, so both sides use one add
inline void add(const ForceAccumulator& a, uint32_t k, double fx, double fy, double fz, double tx, double ty,
                double tz) {
  a.fx[k] += fx; a.fy[k] += fy; a.fz[k] += fz;
  a.tx[k] += tx; a.ty[k] += ty; a.tz[k] += tz;
}

/// Group the c contacts of a batch by key: slot_of[q] is the batch slot of
/// contact q (a stable counting sort: contacts of one key in their order),
/// and `runs` holds (first slot, key) of each key present, closed by (c, -).
/// The contacts keep their order for the gather and the scatter, which read
/// and write the particle arrays (in list order: what the cache and the
/// prefetcher follow); only the slots they fill, in the batch's own small
/// arrays, are grouped. `key(q)` < n_keys.
template <class KeyOf>
void group_by_key(uint32_t c, uint32_t n_keys, KeyOf&& key, std::vector<uint32_t>& count,
                  std::vector<uint32_t>& slot_of, std::vector<std::pair<uint32_t, uint32_t>>& runs) {
  count.assign(n_keys + 1, 0);
  slot_of.resize(ContactPipeline::kBatchSize);
  for (uint32_t q = 0; q < c; ++q) {
    const uint32_t k = key(q);
    slot_of[q] = k;  // the key for now, the slot below
    ++count[k + 1];
  }
  for (uint32_t k = 0; k < n_keys; ++k) count[k + 1] += count[k];
  runs.clear();
  for (uint32_t k = 0; k < n_keys; ++k)
    if (count[k + 1] > count[k]) runs.emplace_back(count[k], k);
  runs.emplace_back(c, 0);
  for (uint32_t q = 0; q < c; ++q) slot_of[q] = count[slot_of[q]]++;
}

/// A contact of list entry e opened: it is no longer touching and its
/// history ends. Rare, and out of line, so that the screen's loop keeps no
/// history pointer of its own.
[[gnu::noinline]] void opened(uint8_t* touching, double* history, std::size_t e, uint32_t stride) {
  touching[e] = 0;
  for (uint32_t h = 0; h < stride; ++h) history[e * stride + h] = 0.0;
}

/// Whether the spheres of particles i and j (rows of PackedPositions::xyzr)
/// overlap: |x_i - x_j|^2 < (r_i + r_j)^2, the separation's squares summed
/// x, y, then z (the same operations in the same order as on the store's
/// arrays, so the same result bit for bit). With SSE2 (every x86-64) on
/// 16-byte registers: the (x, y) difference and its squares in one register
/// each, the horizontal sum and the radii's square by a lane copy.
template <bool kPeriodic>
inline bool overlaps(const double* xyzr, std::size_t i, std::size_t j, const double* per, const double* inv_per) {
  const double* pi = xyzr + 4 * i;
  const double* pj = xyzr + 4 * j;
#if defined(__SSE2__)
  if constexpr (!kPeriodic) {
    const __m128d xy = _mm_sub_pd(_mm_load_pd(pi), _mm_load_pd(pj));   // (dx, dy)
    const __m128d zr_i = _mm_load_pd(pi + 2), zr_j = _mm_load_pd(pj + 2);
    const __m128d u = _mm_move_sd(_mm_add_pd(zr_i, zr_j), _mm_sub_pd(zr_i, zr_j));  // (dz, r_i + r_j)
    const __m128d sq = _mm_mul_pd(xy, xy);                              // (dx^2, dy^2)
    const __m128d u2 = _mm_mul_pd(u, u);                                // (dz^2, (r_i + r_j)^2)
    const __m128d dy2 = _mm_castsi128_pd(_mm_shuffle_epi32(_mm_castpd_si128(sq), 0xEE));
    const __m128d rsum2 = _mm_castsi128_pd(_mm_shuffle_epi32(_mm_castpd_si128(u2), 0xEE));
    return _mm_comilt_sd(_mm_add_sd(_mm_add_sd(sq, dy2), u2), rsum2) != 0;
  }
#endif
  double dx = pi[0] - pj[0], dy = pi[1] - pj[1], dz = pi[2] - pj[2];
  if constexpr (kPeriodic) {
    dx = min_image(dx, per[0], inv_per[0]);
    dy = min_image(dy, per[1], inv_per[1]);
    dz = min_image(dz, per[2], inv_per[2]);
  }
  const double rsum = pi[3] + pj[3];
  return dx * dx + dy * dy + dz * dz < rsum * rsum;
}

template <bool kZoned, bool kTorque, bool kMasses, bool kMixed, bool kPeriodic>
void pair_range(const PairSweep& sw, std::size_t first, std::size_t last, ContactScratch& ts, std::size_t own_lo,
                std::size_t own_hi, const ForceAccumulator& own, const ForceAccumulator& shared) {
  const ParticleStore& s = *sw.store;
  NeighborList& list = *sw.list;
  auto& buf = ts.ws->buf;
  const uint32_t stride = list.stride();
  std::size_t contacts = 0;
  double max_ratio = 0.0;

  const uint32_t* __restrict li = list.i.data();
  const uint32_t* __restrict lj = list.j.data();
  uint8_t* __restrict touching = list.touching.data();
  double* __restrict list_history = list.history.data();
  const double* __restrict px = s.x.data(); const double* __restrict py = s.y.data();
  const double* __restrict pz = s.z.data(); const double* __restrict pr = s.radius.data();
  const double* __restrict pvx = s.vx.data(); const double* __restrict pvy = s.vy.data();
  const double* __restrict pvz = s.vz.data();
  const double* __restrict pwx = s.wx.data(); const double* __restrict pwy = s.wy.data();
  const double* __restrict pwz = s.wz.data();
  const double* __restrict pm = s.mass.data();
  const double* __restrict packed = sw.packed;
  uint32_t* __restrict entry = ts.entry.data();
  double* __restrict lever_i = ts.ci.data();
  double* __restrict lever_j = ts.cj.data();
  const Slots slots(buf);
  double* __restrict b_hist = buf.history.data();
  constexpr uint32_t kBatch = ContactPipeline::kBatchSize;
  // unsigned k - zone_lo < zone_width: k in [own_lo, own_hi)
  const auto zone_lo = static_cast<uint32_t>(own_lo);
  const auto zone_width = static_cast<uint32_t>(own_hi - own_lo);
  const ForceAccumulator own_acc = own, shared_acc = shared;
  // periodic boundaries: the separation to the nearest image (core/neighbor_list.hpp)
  double per[3] = {0, 0, 0}, inv_per[3] = {0, 0, 0};
  if constexpr (kPeriodic) list.periodic().periods(per, inv_per);
  auto separation = [&](uint32_t i, uint32_t j, double& dx, double& dy, double& dz) {
    dx = px[i] - px[j]; dy = py[i] - py[j]; dz = pz[i] - pz[j];
    if constexpr (kPeriodic) {
      dx = min_image(dx, per[0], inv_per[0]);
      dy = min_image(dy, per[1], inv_per[1]);
      dz = min_image(dz, per[2], inv_per[2]);
    }
  };

  std::size_t e = first;
  while (e < last) {
    // Phase A: screen list entries for overlap, branch-free except for the
    // rare contact that just opened, until a batch is full. Most entries of a
    // Verlet list are not in contact (S1: ~5 of 6), so a data-dependent
    // branch here mispredicts often.
    // The positions come packed (PackedPositions): the same values and the
    // same operations, in the same order, as from the store's arrays.
    // An entry adds at most one contact, so kBatch - filled entries cannot
    // overfill the batch: the inner loop tests only its end.
    std::size_t filled = 0;  // a full-width count: it indexes entry[] with no extension
    while (e < last && filled < kBatch) {
      const std::size_t stop = std::min<std::size_t>(last, e + (kBatch - filled));
      for (; e < stop; ++e) {
        const uint32_t i = li[e], j = lj[e];
        const bool in = overlaps<kPeriodic>(packed, i, j, per, inv_per);
        if (touching[e] > static_cast<uint8_t>(in)) opened(touching, list_history, e, stride);
        entry[filled] = static_cast<uint32_t>(e);
        filled += in;
      }
    }
    const auto c = static_cast<uint32_t>(filled);
    if (c == 0) continue;
    // Several classes of material pairs: the batch's contacts grouped by
    // class, so that each run is evaluated with its own constants.
    const uint8_t* __restrict mat = s.material.data();
    const uint32_t nm = sw.n_materials;
    if constexpr (kMixed)
      group_by_key(c, sw.n_classes, [&](uint32_t q) {
        return static_cast<uint32_t>(sw.pair_class[mat[li[entry[q]]] * nm + mat[lj[entry[q]]]]);
      }, ts.key_count, ts.sorted, ts.runs);
    const uint32_t* slot_of = ts.sorted.data();
    // Phase B: the gather (contact geometry and relative velocities) of
    // contact q into slot sl (q itself, or its pair's run).
    for (uint32_t q = 0; q < c; ++q) {
      const uint32_t le = entry[q];
      uint32_t sl = q;
      if constexpr (kMixed) sl = slot_of[q];
      const uint32_t i = li[le], j = lj[le];
      const double ri = pr[i], rj = pr[j];
      double dx, dy, dz;
      separation(i, j, dx, dy, dz);
      const double rsum = ri + rj, inv_rsum = 1.0 / rsum;
      const double dist = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double inv = 1.0 / dist;
      const double nx = dx * inv, ny = dy * inv, nz = dz * inv;
      const double delta = rsum - dist;
      const double ci = ri - 0.5 * delta, cj = rj - 0.5 * delta;
      const double wix = pwx[i], wiy = pwy[i], wiz = pwz[i];
      const double wjx = pwx[j], wjy = pwy[j], wjz = pwz[j];
      double vix, viy, viz, vjx, vjy, vjz;
      point_velocity(pvx[i], pvy[i], pvz[i], wix, wiy, wiz, -ci, nx, ny, nz, vix, viy, viz);
      point_velocity(pvx[j], pvy[j], pvz[j], wjx, wjy, wjz, cj, nx, ny, nz, vjx, vjy, vjz);
      // one division for R* and the overlap ratio
      const double mi = pm[i], mj = pm[j];
      fill_slot(slots, kMasses, sl, delta, nx, ny, nz, ri, rj, ri * rj * inv_rsum, mi, mj, mi * mj / (mi + mj),
                vix - vjx, viy - vjy, viz - vjz, wix - wjx, wiy - wjy, wiz - wjz);
      copy_row(list_history + static_cast<std::size_t>(le) * stride, b_hist + static_cast<std::size_t>(sl) * stride,
               stride);
      touching[le] = 1;
      lever_i[sl] = ci;
      lever_j[sl] = cj;
      max_ratio = std::max(max_ratio, delta * inv_rsum);
    }
    try {
      if constexpr (kMixed) {
        for (std::size_t r = 0; r + 1 < ts.runs.size(); ++r)
          sw.pipeline->evaluate_range(*ts.ws, sw.pairs[ts.runs[r].second], sw.rolling[ts.runs[r].second], sw.dt,
                                      ts.runs[r].first,
                                      ts.runs[r + 1].first - ts.runs[r].first);
      } else {
        sw.pipeline->evaluate(*ts.ws, sw.pairs[0], sw.rolling[0], sw.dt, c);
      }
    } catch (const PluginError& err) {
      throw_batch_failure(err, s, entry, c, li, [&](uint32_t le) { return "particle id " + std::to_string(s.id[lj[le]]); });
    }
    // The scatter: forces and torques onto both particles, history back to the list.
    const double* __restrict fn_ = buf.fn.data();
    const double* __restrict ftx_ = buf.ftx.data(); const double* __restrict fty_ = buf.fty.data();
    const double* __restrict ftz_ = buf.ftz.data();
    const double* __restrict tqx_ = buf.tqx.data(); const double* __restrict tqy_ = buf.tqy.data();
    const double* __restrict tqz_ = buf.tqz.data();
    for (uint32_t q = 0; q < c; ++q) {
      const uint32_t le = entry[q];
      uint32_t sl = q;
      if constexpr (kMixed) sl = slot_of[q];
      const uint32_t i = li[le], j = lj[le];
      const Load l = load_of(fn_[sl], slots.nx[sl], slots.ny[sl], slots.nz[sl], ftx_[sl], fty_[sl], ftz_[sl]);
      const double ci = lever_i[sl], cj = lever_j[sl];
      double tix = -ci * l.cx, tiy = -ci * l.cy, tiz = -ci * l.cz;
      double tjx = -cj * l.cx, tjy = -cj * l.cy, tjz = -cj * l.cz;
      if constexpr (kTorque) {  // else the couple is zero, and adding it would change no bit (sums start at +0)
        tix += tqx_[sl]; tiy += tqy_[sl]; tiz += tqz_[sl];
        tjx -= tqx_[sl]; tjy -= tqy_[sl]; tjz -= tqz_[sl];
      }
      // A branch, not a select of the accumulator: it is taken the same way
      // for all but the few particles of the band other threads share, and
      // the own path keeps its pointers in registers (one writer: always).
      if (!kZoned || i - zone_lo < zone_width) add(own_acc, i, l.fx, l.fy, l.fz, tix, tiy, tiz);
      else add(shared_acc, i, l.fx, l.fy, l.fz, tix, tiy, tiz);
      if (!kZoned || j - zone_lo < zone_width) add(own_acc, j, -l.fx, -l.fy, -l.fz, tjx, tjy, tjz);
      else add(shared_acc, j, -l.fx, -l.fy, -l.fz, tjx, tjy, tjz);
      copy_row(b_hist + static_cast<std::size_t>(sl) * stride, list_history + static_cast<std::size_t>(le) * stride,
               stride);
    }
    if (sw.record)
      for (uint32_t q = 0; q < c; ++q) {
        const uint32_t le = entry[q];
        uint32_t sl = q;
        if constexpr (kMixed) sl = slot_of[q];
        const Load l = load_of(fn_[sl], slots.nx[sl], slots.ny[sl], slots.nz[sl], ftx_[sl], fty_[sl], ftz_[sl]);
        // the partner's position: j itself, or its image nearest to i through a periodic face
        const uint32_t i = li[le], j = lj[le];
        double dx, dy, dz;
        separation(i, j, dx, dy, dz);
        const double shift[3] = {(px[i] - px[j]) - dx, (py[i] - py[j]) - dy, (pz[i] - pz[j]) - dz};
        ts.records.push_back({i, j, l.fx, l.fy, l.fz, px[j] + shift[0], py[j] + shift[1], pz[j] + shift[2]});
      }
    contacts += c;
  }
  ts.pair_contacts += contacts;
  ts.pair_max_ratio = std::max(ts.pair_max_ratio, max_ratio);
}

}  // namespace

namespace {
template <bool kMasses, bool kMixed, bool kPeriodic>
PairRangeFn pair_kernel_of(bool has_torque, bool zoned) {
  if (has_torque)
    return zoned ? &pair_range<true, true, kMasses, kMixed, kPeriodic> : &pair_range<false, true, kMasses, kMixed, kPeriodic>;
  return zoned ? &pair_range<true, false, kMasses, kMixed, kPeriodic> : &pair_range<false, false, kMasses, kMixed, kPeriodic>;
}
template <bool kPeriodic>
PairRangeFn pair_kernel_periodic(const ContactPipeline& pipeline, bool zoned, bool mixed) {
  if (mixed)
    return pipeline.reads_masses() ? pair_kernel_of<true, true, kPeriodic>(pipeline.has_torque(), zoned)
                                   : pair_kernel_of<false, true, kPeriodic>(pipeline.has_torque(), zoned);
  return pipeline.reads_masses() ? pair_kernel_of<true, false, kPeriodic>(pipeline.has_torque(), zoned)
                                 : pair_kernel_of<false, false, kPeriodic>(pipeline.has_torque(), zoned);
}
}  // namespace

PairRangeFn pair_kernel(const ContactPipeline& pipeline, bool zoned, bool mixed, bool periodic) {
  return periodic ? pair_kernel_periodic<true>(pipeline, zoned, mixed) : pair_kernel_periodic<false>(pipeline, zoned, mixed);
}

void wall_range(const WallSweep& sw, ContactScratch& ts, std::size_t first, std::size_t last) {
  ParticleStore& s = *sw.store;
  auto& buf = ts.ws->buf;
  const Slots slots(buf);
  const uint32_t stride = sw.pipeline->history_stride();
  const bool masses = sw.pipeline->reads_masses();
  std::size_t contacts = 0;
  double max_ratio = 0.0;
  for (std::size_t w = 0; w < sw.lists->size(); ++w) {
    WallNeighbors& list = (*sw.lists)[w];
    const WallPrimitive& wall = (*sw.walls)[w];
    // removed walls are pruned by the subdomain; the time of the force
    // evaluation, as the walls' contacts may be finished in the next step
    if (!wall.active(sw.forces_time)) continue;
    const auto lo = std::lower_bound(list.particle.begin(), list.particle.end(), static_cast<uint32_t>(first));
    const auto hi =
        std::lower_bound(lo, list.particle.end(), static_cast<uint32_t>(std::min<std::size_t>(last, UINT32_MAX)));
    const std::size_t e_first = static_cast<std::size_t>(lo - list.particle.begin());
    const std::size_t e_last = static_cast<std::size_t>(hi - list.particle.begin());
    uint32_t c = 0;
    // this wall's pair constants, by the particle's local material
    const domel_pair_v2* wall_pairs = sw.pairs + w * sw.n_materials;
    const ModelInstance* const* wall_rolling = sw.rolling + w * sw.n_materials;
    const bool mixed = sw.n_materials > 1 && !sw.uniform[w];
    double* load = nullptr;
    if (wall.track_load) {
      if (ts.wall_load.size() < 3 * sw.lists->size()) ts.wall_load.resize(3 * sw.lists->size(), 0.0);
      load = ts.wall_load.data() + 3 * w;
    }
    auto flush = [&]() {
      if (c == 0) return;
      try {
        if (!mixed) {
          sw.pipeline->evaluate(*ts.ws, wall_pairs[0], wall_rolling[0], sw.dt, c);
        } else {
          for (std::size_t r = 0; r + 1 < ts.runs.size(); ++r)
            sw.pipeline->evaluate_range(*ts.ws, wall_pairs[ts.runs[r].second], wall_rolling[ts.runs[r].second],
                                        sw.dt, ts.runs[r].first, ts.runs[r + 1].first - ts.runs[r].first);
        }
      } catch (const PluginError& err) {
        throw_batch_failure(err, s, ts.entry.data(), c, list.particle.data(),
                            [&](uint32_t) { return "wall '" + wall.name + "'"; });
      }
      // in the particles' order (several materials: slot q of the k-th staged contact)
      const uint32_t* order = mixed ? ts.sorted.data() : nullptr;
      for (uint32_t k = 0; k < c; ++k) {
        const uint32_t q = order ? order[k] : k;
        const uint32_t e = ts.entry[q];
        const uint32_t i = list.particle[e];
        const double nx = buf.nx[q], ny = buf.ny[q], nz = buf.nz[q];
        const Load l = load_of(buf.fn[q], nx, ny, nz, buf.ftx[q], buf.fty[q], buf.ftz[q]);
        s.fx[i] += l.fx; s.fy[i] += l.fy; s.fz[i] += l.fz;
        const double ci = ts.ci[q];
        s.tx[i] += -ci * l.cx + buf.tqx[q]; s.ty[i] += -ci * l.cy + buf.tqy[q]; s.tz[i] += -ci * l.cz + buf.tqz[q];
        copy_row(buf.history.data() + q * stride, list.history.data() + e * stride, stride);
        if (sw.record)  // the contact point lies on the wall, ci from the centre along -n
          ts.records.push_back({i, ContactRecord::kWall, l.fx, l.fy, l.fz, s.x[i] - ci * nx, s.y[i] - ci * ny,
                                s.z[i] - ci * nz, static_cast<uint32_t>(w)});
      }
      if (load)  // a servo wall's load: a pass of its own, so that other walls pay nothing
        for (uint32_t q = 0; q < c; ++q) {
          const Load l = load_of(buf.fn[q], buf.nx[q], buf.ny[q], buf.nz[q], buf.ftx[q], buf.fty[q], buf.ftz[q]);
          load[0] += l.fx; load[1] += l.fy; load[2] += l.fz;
        }
      contacts += c;
      c = 0;
    };
    // One contact into the batch: entry e of the list, particle i, centre
    // distance d from the contact point, unit normal n (wall -> centre).
    // The wall is partner j: no radius, no rotation, its surface velocity
    // at the contact point x_i - c_i n when it moves.
    const bool moving = wall.moving;
    auto gather = [&](uint32_t q, std::size_t e, uint32_t i, double d, double nx, double ny, double nz) {
      const double delta = s.radius[i] - d;
      const double ci = s.radius[i] - delta;
      double rx, ry, rz;
      point_velocity(s.vx[i], s.vy[i], s.vz[i], s.wx[i], s.wy[i], s.wz[i], -ci, nx, ny, nz, rx, ry, rz);
      if (moving) {
        double ux, uy, uz;
        wall.surface_velocity(s.x[i] - ci * nx, s.y[i] - ci * ny, s.z[i] - ci * nz, ux, uy, uz);
        rx -= ux; ry -= uy; rz -= uz;
      }
      fill_slot(slots, masses, q, delta, nx, ny, nz, s.radius[i], 0.0, s.radius[i], s.mass[i], 0.0, s.mass[i], rx, ry, rz,
                s.wx[i], s.wy[i], s.wz[i]);
      copy_row(list.history.data() + e * stride, buf.history.data() + q * stride, stride);
      list.touching[e] = 1;
      ts.entry[q] = static_cast<uint32_t>(e);
      ts.ci[q] = ci;
      max_ratio = std::max(max_ratio, delta / (2.0 * s.radius[i]));
    };
    // Several materials: the contacts are staged, then each is gathered (in
    // the particles' order) into a slot of its material's run, so that each
    // run of one wall pair is evaluated with its own constants.
    auto flush_staged = [&]() {
      if (ts.staged.empty()) return;
      const auto n = static_cast<uint32_t>(ts.staged.size());
      group_by_key(n, sw.n_materials,
                   [&](uint32_t k) { return static_cast<uint32_t>(s.material[ts.staged[k].particle]); }, ts.key_count,
                   ts.sorted, ts.runs);
      for (uint32_t k = 0; k < n; ++k) {
        const auto& st = ts.staged[k];
        gather(ts.sorted[k], st.entry, st.particle, st.d, st.nx, st.ny, st.nz);
      }
      c = n;
      ts.staged.clear();
      flush();
    };
    auto push = [&](std::size_t e, uint32_t i, double d, double nx, double ny, double nz) {
      if (!mixed) {
        gather(c++, e, i, d, nx, ny, nz);
        if (c == ContactPipeline::kBatchSize) flush();
        return;
      }
      ts.staged.push_back({static_cast<uint32_t>(e), i, d, nx, ny, nz});
      if (ts.staged.size() == ContactPipeline::kBatchSize) flush_staged();
    };
    if (wall.shape == WallPrimitive::Shape::mesh) {
      // Per particle: the counted features of its candidate triangles
      // (resolve_mesh_contacts). A contact that moves from one triangle to
      // a neighbour (a sphere crossing a seam) keeps its history: a newly
      // counted entry takes the history of an entry of the same particle
      // that stopped counting this step.
      for (std::size_t e = e_first; e < e_last;) {
        const uint32_t i = list.particle[e];
        std::size_t e_end = e + 1;
        while (e_end < e_last && list.particle[e_end] == i) ++e_end;
        const std::size_t count = e_end - e;
        const double p[3] = {s.x[i], s.y[i], s.z[i]};
        resolve_mesh_contacts(*wall.mesh, wall.verts.data(), p, s.radius[i], list.triangle.data() + e, count,
                              ts.mesh, ts.mesh_out, wall.tri_bounds.empty() ? nullptr : wall.tri_bounds.data());
        ts.counted.assign(count, 0);
        for (const MeshContact& mc : ts.mesh_out) ts.counted[mc.slot] = 1;
        std::size_t released = SIZE_MAX;
        for (std::size_t k = 0; k < count; ++k) {
          if (!list.touching[e + k] || ts.counted[k]) continue;
          list.touching[e + k] = 0;
          if (released == SIZE_MAX) released = e + k;
          else std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>((e + k) * stride), stride, 0.0);
        }
        for (const MeshContact& mc : ts.mesh_out) {
          const std::size_t entry = e + mc.slot;
          if (!list.touching[entry] && released != SIZE_MAX) {
            std::copy_n(list.history.begin() + static_cast<std::ptrdiff_t>(released * stride), stride,
                        list.history.begin() + static_cast<std::ptrdiff_t>(entry * stride));
            std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>(released * stride), stride, 0.0);
            released = SIZE_MAX;
          }
          push(entry, i, mc.d, mc.n[0], mc.n[1], mc.n[2]);
        }
        if (released != SIZE_MAX)
          std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>(released * stride), stride, 0.0);
        e = e_end;
      }
      flush_staged();
      flush();
      continue;
    }
    for (std::size_t e = e_first; e < e_last; ++e) {
      const uint32_t i = list.particle[e];
      double d, nx, ny, nz;
      const bool has = wall.gap(s.x[i], s.y[i], s.z[i], d, nx, ny, nz);
      if (!has || d >= s.radius[i]) {
        if (list.touching[e]) {
          list.touching[e] = 0;
          std::fill_n(list.history.begin() + static_cast<std::ptrdiff_t>(e * stride), stride, 0.0);
        }
        continue;
      }
      push(e, i, d, nx, ny, nz);
    }
    flush_staged();
    flush();
  }
  ts.wall_contacts += contacts;
  ts.wall_max_ratio = std::max(ts.wall_max_ratio, max_ratio);
}

}  // namespace domel::platform
