// SPDX-License-Identifier: MIT
// Refinement and coarsening with exact books (conversion.hpp; the choices
// are docs/adaptive.md's).
#include "coupling/conversion.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace domel::platform {

namespace {

constexpr double kPi = 3.14159265358979323846;
/// The children of a parcel start this much apart (a fraction of their
/// spacing), so that none touches another or the parcel's surface.
constexpr double kStartGap = 1e-3;
/// Units a whole particle may lack and still be made: a parcel of an integer
/// ratio holds exactly k^3 fine particles, but its mass and theirs are
/// rounded apart (a few of its 1e-18 kg units), and it must not make k^3 - 1
/// of them and carry almost one. The carried mass may then be negative by
/// at most this: the books stay exact in integers either way.
MassUnits slack(MassUnits unit) { return unit / 1000000; }

/// A uniform draw in [0, 1) from the generator's top 53 bits (the same on
/// every standard library, unlike std::uniform_real_distribution).
double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

void cross(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

double ConversionBooks::momentum_residual() const {
  double r = 0;
  for (int a = 0; a < 3; ++a) r = std::max(r, std::abs(momentum_in[a] - momentum_out[a]));
  return r;
}

double ConversionBooks::momentum_relative() const {
  double scale = 0;
  for (int a = 0; a < 3; ++a) scale = std::max({scale, std::abs(momentum_in[a]), std::abs(momentum_out[a])});
  return scale > 0 ? momentum_residual() / scale : 0.0;
}

void ConversionBooks::add(const ConversionBooks& o) {
  in += o.in;
  out += o.out;
  mass_in += o.mass_in;
  mass_out += o.mass_out;
  for (int a = 0; a < 3; ++a) {
    momentum_in[a] += o.momentum_in[a];
    momentum_out[a] += o.momentum_out[a];
    angular_in[a] += o.angular_in[a];
    angular_out[a] += o.angular_out[a];
  }
  kinetic_in += o.kinetic_in;
  kinetic_out += o.kinetic_out;
  fluctuation += o.fluctuation;
  smallest_start = std::min(smallest_start, o.smallest_start);
}

namespace {

/// The n lattice points closest to c (cubic cell of side a, four points per
/// cell), centred on their centroid, unturned; `reach` their largest distance from it.
std::vector<std::array<double, 3>> closest_points(std::size_t n, const double c[3], double& reach) {
  const double a = std::sqrt(2.0);
  const double basis[4][3] = {{0, 0, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {0.5, 0.5, 0}};
  // points within rho of c: the sphere holding n at the lattice's density (4/a^3), plus two cells
  double rho = std::cbrt(3.0 * static_cast<double>(n) / (4.0 * kPi * 4.0 / (a * a * a))) + 2 * a;
  std::vector<std::pair<double, std::array<double, 3>>> near;
  for (;;) {
    near.clear();
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      lo[d] = static_cast<int>(std::floor((c[d] - rho) / a));
      hi[d] = static_cast<int>(std::ceil((c[d] + rho) / a));
    }
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int k = lo[2]; k <= hi[2]; ++k)
          for (const auto& b : basis) {
            const std::array<double, 3> p = {(i + b[0]) * a - c[0], (j + b[1]) * a - c[1], (k + b[2]) * a - c[2]};
            const double d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
            if (d2 <= rho * rho) near.emplace_back(d2, p);
          }
    if (near.size() >= n) break;
    rho *= 1.5;
  }
  // the n closest (a strict order: distance, then position, so that ties cannot depend on the sort)
  std::sort(near.begin(), near.end());
  std::vector<std::array<double, 3>> pts;
  pts.reserve(n);
  double centroid[3] = {0, 0, 0};
  for (std::size_t q = 0; q < n; ++q) {
    pts.push_back(near[q].second);
    for (int d = 0; d < 3; ++d) centroid[d] += near[q].second[d];
  }
  reach = 0;
  for (auto& p : pts) {
    for (int d = 0; d < 3; ++d) p[d] -= centroid[d] / static_cast<double>(n);
    reach = std::max(reach, std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
  }
  return pts;
}

}  // namespace

std::vector<std::array<double, 3>> fcc_cluster(std::size_t n, std::mt19937_64& rng, double& reach) {
  reach = 0;
  if (n == 0) return {};
  // the most compact of a few clusters about random points of the cell (the fewer the points, the more
  // their reach depends on where the centre falls: 8 of them reach 1.0 to 1.4 spacings)
  constexpr int kTries = 8;
  std::vector<std::array<double, 3>> best;
  for (int t = 0; t < kTries; ++t) {
    const double a = std::sqrt(2.0);
    const double c[3] = {a * uniform(rng), a * uniform(rng), a * uniform(rng)};
    double r = 0;
    auto pts = closest_points(n, c, r);
    if (best.empty() || r < reach) best = std::move(pts), reach = r;
  }
  // a uniformly random rotation (Shoemake's unit quaternion); the centroid stays at the origin
  const double u1 = uniform(rng), u2 = 2 * kPi * uniform(rng), u3 = 2 * kPi * uniform(rng);
  const double qx = std::sqrt(1 - u1) * std::sin(u2), qy = std::sqrt(1 - u1) * std::cos(u2);
  const double qz = std::sqrt(u1) * std::sin(u3), qw = std::sqrt(u1) * std::cos(u3);
  const double R[9] = {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw),     2 * (qx * qz + qy * qw),
                       2 * (qx * qy + qz * qw),     1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw),
                       2 * (qx * qz - qy * qw),     2 * (qy * qz + qx * qw),     1 - 2 * (qx * qx + qy * qy)};
  double centroid[3] = {0, 0, 0};
  for (auto& p : best) {
    const std::array<double, 3> q = p;
    for (int d = 0; d < 3; ++d) p[d] = R[3 * d] * q[0] + R[3 * d + 1] * q[1] + R[3 * d + 2] * q[2];
    for (int d = 0; d < 3; ++d) centroid[d] += p[d];
  }
  // the rotation moves the centroid by its round-off: take it off again, so that sum m r = 0 holds to
  // the last bits (the children's momentum about the mean is then zero)
  reach = 0;
  for (auto& p : best) {
    for (int d = 0; d < 3; ++d) p[d] -= centroid[d] / static_cast<double>(n);
    reach = std::max(reach, std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
  }
  return best;
}

void refine_parcel(const ConvertedBody& parcel, double fine_radius, double fine_mass, CarriedMass& carried,
                   std::mt19937_64& rng, std::vector<ConvertedBody>& made, ConversionBooks& books) {
  if (!(fine_mass > 0) || !(fine_radius > 0))
    throw std::invalid_argument("refine_parcel: the fine particles' mass and radius must be positive");
  const MassUnits unit = mass_units(fine_mass);
  const MassUnits parcel_units = mass_units(parcel.mass);
  const MassUnits total = carried.units + parcel_units;
  const auto n = total + slack(unit) > 0 ? static_cast<std::size_t>((total + slack(unit)) / unit) : 0;
  const MassUnits rest = total - static_cast<MassUnits>(n) * unit;

  // the mass left over goes on with this parcel's velocity; the children
  // carry the rest of the momentum (the carried mass's included)
  double momentum[3], carried_after[3];
  const double m_rest = mass_kg(rest);
  for (int a = 0; a < 3; ++a) {
    momentum[a] = carried.momentum[a] + parcel.mass * parcel.v[a];
    carried_after[a] = n > 0 ? m_rest * parcel.v[a] : momentum[a];
  }
  books.in += 1;
  books.mass_in += parcel_units;
  const double inertia = sphere_inertia(parcel.mass, parcel.radius);
  for (int a = 0; a < 3; ++a) {
    books.momentum_in[a] += parcel.mass * parcel.v[a];
    books.angular_in[a] += inertia * parcel.w[a];
  }
  books.kinetic_in += 0.5 * parcel.mass * dot(parcel.v, parcel.v) + 0.5 * inertia * dot(parcel.w, parcel.w);

  double made_momentum[3] = {0, 0, 0};
  if (n > 0) {
    double mean_v[3];
    const double children_mass = static_cast<double>(n) * fine_mass;
    for (int a = 0; a < 3; ++a) mean_v[a] = (momentum[a] - carried_after[a]) / children_mass;
    double reach = 0;
    const auto pts = fcc_cluster(n, rng, reach);
    const double scale = parcel.radius / (reach + 0.5);  // every child's sphere inside the parcel's
    const double start = std::min(fine_radius, 0.5 * scale * (1 - kStartGap));
    const double fine_inertia = sphere_inertia(fine_mass, fine_radius);
    for (const auto& p : pts) {
      ConvertedBody b;
      double r[3], wr[3];
      for (int a = 0; a < 3; ++a) r[a] = scale * p[a];
      cross(parcel.w, r, wr);
      for (int a = 0; a < 3; ++a) {
        b.x[a] = parcel.x[a] + r[a];
        b.v[a] = mean_v[a] + wr[a];
        b.w[a] = parcel.w[a];
      }
      b.radius = fine_radius;
      b.mass = fine_mass;
      b.start_radius = start;
      double rv[3];
      cross(r, b.v, rv);
      for (int a = 0; a < 3; ++a) {
        made_momentum[a] += fine_mass * b.v[a];
        books.angular_out[a] += fine_mass * rv[a] + fine_inertia * b.w[a];
      }
      books.kinetic_out += 0.5 * fine_mass * dot(b.v, b.v) + 0.5 * fine_inertia * dot(b.w, b.w);
      books.fluctuation += 0.5 * fine_mass * dot(wr, wr);
      made.push_back(b);
    }
    books.out += n;
    books.smallest_start = std::min(books.smallest_start, start / fine_radius);
  }
  books.mass_out += static_cast<MassUnits>(n) * unit + (rest - carried.units);
  for (int a = 0; a < 3; ++a) books.momentum_out[a] += made_momentum[a] + (carried_after[a] - carried.momentum[a]);
  carried.units = rest;
  for (int a = 0; a < 3; ++a) carried.momentum[a] = carried_after[a];
}

void coarsen_add(const ConvertedBody& fine, double parcel_radius, double parcel_mass, CoarsenGather& g,
                 std::vector<ConvertedBody>& made, ConversionBooks& books) {
  if (!(parcel_mass >= fine.mass) || !(fine.mass > 0) || !(parcel_radius > 0))
    throw std::invalid_argument("coarsen_add: a parcel must be positive and at least as heavy as a fine particle");
  const MassUnits unit = mass_units(parcel_mass);
  const MassUnits fine_units = mass_units(fine.mass);
  const MassUnits units_before = g.units;
  double momentum_before[3] = {g.momentum[0], g.momentum[1], g.momentum[2]};
  if (g.units == 0) {
    g = CoarsenGather{};
    for (int a = 0; a < 3; ++a) g.ref[a] = fine.x[a];
  }
  // the body's own terms, about ref: mass, first moment, momentum, m r x v, I w, energy
  const double m = fine.mass, inertia = sphere_inertia(fine.mass, fine.radius);
  double r[3], rv[3], p[3], s[3];
  for (int a = 0; a < 3; ++a) r[a] = fine.x[a] - g.ref[a], p[a] = m * fine.v[a], s[a] = inertia * fine.w[a];
  cross(r, fine.v, rv);
  const double kin = 0.5 * m * dot(fine.v, fine.v) + 0.5 * inertia * dot(fine.w, fine.w);
  const double kin_translation = 0.5 * m * dot(fine.v, fine.v);
  g.units += fine_units;
  g.mass += m;
  for (int a = 0; a < 3; ++a) g.moment[a] += m * r[a], g.momentum[a] += p[a], g.cross[a] += m * rv[a], g.spin[a] += s[a];
  g.kinetic += kin;
  g.translation += kin_translation;
  books.in += 1;
  books.mass_in += fine_units;
  for (int a = 0; a < 3; ++a) books.momentum_in[a] += p[a];
  double made_momentum[3] = {0, 0, 0};
  MassUnits made_units = 0;
  if (g.units + slack(unit) >= unit) {
    // the part of this body beyond the parcel's mass stays gathered: fraction f of its terms
    const MassUnits over = g.units - unit;
    const double f = std::clamp(mass_kg(over) / m, 0.0, 1.0);
    double M = g.mass - f * m, P[3], S[3], C[3], L[3];
    for (int a = 0; a < 3; ++a) {
      P[a] = g.momentum[a] - f * p[a];
      S[a] = g.moment[a] - f * m * r[a];
      C[a] = g.cross[a] - f * m * rv[a];
    }
    double d[3], dP[3];
    for (int a = 0; a < 3; ++a) d[a] = S[a] / M;
    cross(d, P, dP);
    for (int a = 0; a < 3; ++a) L[a] = C[a] - dP[a] + (g.spin[a] - f * s[a]);
    ConvertedBody b;
    for (int a = 0; a < 3; ++a) {
      b.x[a] = g.ref[a] + d[a];
      b.v[a] = P[a] / parcel_mass;
    }
    // the energy about the mean motion that the spin may take (none is created)
    const double kin_share = g.kinetic - f * kin;
    const double kin_mean = 0.5 * parcel_mass * dot(b.v, b.v);
    const double available = std::max(0.0, kin_share - kin_mean);
    const double I = sphere_inertia(parcel_mass, parcel_radius);
    double spin_scale = 1;
    const double spin_energy = 0.5 * dot(L, L) / I;
    if (spin_energy > available) spin_scale = std::sqrt(available / spin_energy);
    for (int a = 0; a < 3; ++a) b.w[a] = spin_scale * L[a] / I;
    b.radius = parcel_radius;
    b.start_radius = parcel_radius;
    b.mass = parcel_mass;
    made.push_back(b);
    for (int a = 0; a < 3; ++a) {
      made_momentum[a] = parcel_mass * b.v[a];
      books.angular_in[a] += L[a];
      books.angular_out[a] += I * b.w[a];
    }
    books.kinetic_in += kin_share;
    books.kinetic_out += kin_mean + 0.5 * I * dot(b.w, b.w);
    // the translation energy about the mean velocity is what went as granular temperature
    books.fluctuation += std::max(0.0, g.translation - f * kin_translation - kin_mean);
    books.out += 1;
    made_units = unit;
    // what stays: fraction f of this body, about its own centre
    const CoarsenGather keep = [&] {
      CoarsenGather k;
      k.units = over;
      k.mass = f * m;
      for (int a = 0; a < 3; ++a) k.ref[a] = fine.x[a], k.momentum[a] = f * p[a], k.spin[a] = f * s[a];
      k.kinetic = f * kin;
      k.translation = f * kin_translation;
      return k;
    }();
    g = keep;
  }
  books.mass_out += made_units + (g.units - units_before);
  for (int a = 0; a < 3; ++a) books.momentum_out[a] += made_momentum[a] + (g.momentum[a] - momentum_before[a]);
}

}  // namespace domel::platform
