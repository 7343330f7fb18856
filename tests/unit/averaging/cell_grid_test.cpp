// SPDX-License-Identifier: MIT
// Guards the Eulerian cell averages (platform/averaging/cell_grid.cpp) against
// analytic values: volume fraction of a simple cubic lattice (pi/6), Favre
// velocity and kinetic stress of a known velocity set, the contact virial of
// a lattice under known pair forces and of a wall contact (p > 0 in
// compression), the accessible-volume weight of cells cut by a cylinder wall,
// the mean over samples, and the accessible-volume weighting of the profile.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "averaging/cell_grid.hpp"
#include "core/error.hpp"
#include "core/particle_store.hpp"
#include "geometry/wall.hpp"

using domel::platform::CellFields;
using domel::platform::CellGrid;
using domel::platform::CellGridSpec;
using domel::platform::ContactRecord;
using domel::platform::LayerProfile;
using domel::platform::ParticleStore;
using domel::platform::RuntimeError;
using domel::platform::WallPrimitive;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Pure floating-point round-off of sums of O(100) terms: a few ulp per term.
constexpr double kRoundOff = 1e-12;

CellGridSpec box_spec(double lo, double hi, int nx, int ny, int nz) {
  CellGridSpec s;
  s.name = "g";
  for (int a = 0; a < 3; ++a) {
    s.lo[a] = lo;
    s.hi[a] = hi;
  }
  s.cells[0] = nx;
  s.cells[1] = ny;
  s.cells[2] = nz;
  return s;
}

const std::vector<const std::vector<ContactRecord>*> kNoRecords;

/// A pair contact of particles i and j of s (partner position: j's own).
ContactRecord pair(const ParticleStore& s, std::uint32_t i, std::uint32_t j, double fx, double fy, double fz) {
  return ContactRecord{i, j, fx, fy, fz, s.x[j], s.y[j], s.z[j]};
}

double sum(const std::vector<double>& v) {
  double t = 0;
  for (double x : v) t += x;
  return t;
}

/// Exact area of the square [x0,x1]x[y0,y1] inside the disk of radius R at
/// the origin: the chord-length integral, by the midpoint rule on 200000
/// strips (integrand continuous, error well below 1e-7 of the cell area).
double disk_square_area(double x0, double x1, double y0, double y1, double R) {
  const int n = 200000;
  const double dx = (x1 - x0) / n;
  double area = 0;
  for (int k = 0; k < n; ++k) {
    const double x = x0 + (k + 0.5) * dx;
    if (std::abs(x) >= R) continue;
    const double s = std::sqrt(R * R - x * x);
    const double len = std::min(y1, s) - std::max(y0, -s);
    if (len > 0) area += len * dx;
  }
  return area;
}

}  // namespace

TEST(CellGrid, SimpleCubicLatticeHasVolumeFractionPiOverSix) {
  // 10^3 touching spheres (a = 2r = 0.1) in a unit box of 2^3 cells: 125 per cell.
  CellGrid grid(box_spec(0, 1, 2, 2, 2));
  ParticleStore s;
  const double a = 0.1;
  std::uint64_t id = 0;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) s.add(id++, (i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a, a / 2, 2500);
  grid.sample(s, kNoRecords, 0.0);
  const CellFields& f = grid.latest();
  ASSERT_EQ(f.volume_fraction.size(), 8u);
  for (std::size_t c = 0; c < 8; ++c) {
    EXPECT_EQ(f.count[c], 125);
    EXPECT_NEAR(f.volume_fraction[c], kPi / 6, kRoundOff);
    EXPECT_NEAR(f.mass[c], 125 * 2500 * kPi / 6 * a * a * a, kRoundOff);
    EXPECT_EQ(f.pressure[c], 0);  // at rest, no contacts
  }
  const LayerProfile p = grid.profile(f, 2);
  ASSERT_EQ(p.volume_fraction.size(), 2u);
  EXPECT_NEAR(p.volume_fraction[0], kPi / 6, kRoundOff);
  EXPECT_NEAR(p.centre[1], 0.75, kRoundOff);
  EXPECT_EQ(p.count[1], 500);
}

TEST(CellGrid, FavreVelocityAndKineticStressOfKnownVelocities) {
  // One cell of volume V = 8. Masses 1 and 3 with v1 = (4,2,-3), v2 = (0,2,1):
  // u = (1,2,0); v1' = (3,0,-3), v2' = (-1,0,1);
  // sum m v'v': xx = 9 + 3 = 12, zz = 9 + 3 = 12, xz = -9 - 3 = -12, y* = 0.
  CellGrid grid(box_spec(-1, 1, 1, 1, 1));
  ParticleStore s;
  s.add(0, 0.1, 0.1, 0.1, 0.01, 1000);
  s.add(1, -0.1, 0.2, 0.3, 0.01, 1000);
  s.add(2, 0.5, 0.5, 0.5, 0.02, 1000, /*fixed=*/true);  // counts, but no velocity
  s.mass = {1.0, 3.0, 7.0};
  s.vx = {4, 0, 100};
  s.vy = {2, 2, 100};
  s.vz = {-3, 1, 100};
  grid.sample(s, kNoRecords, 0.5);
  const CellFields& f = grid.latest();
  EXPECT_EQ(f.count[0], 3);
  EXPECT_EQ(f.count_fixed[0], 1);
  EXPECT_EQ(f.mass[0], 11.0);
  EXPECT_EQ(f.mobile_mass[0], 4.0);
  EXPECT_NEAR(f.volume_fraction[0], 4.0 / 3.0 * kPi * (2 * 1e-6 + 8e-6) / 8.0, kRoundOff);
  EXPECT_NEAR(f.vx[0], 1.0, kRoundOff);
  EXPECT_NEAR(f.vy[0], 2.0, kRoundOff);
  EXPECT_NEAR(f.vz[0], 0.0, kRoundOff);
  const double expected[9] = {12, 0, -12, 0, 0, 0, -12, 0, 12};
  for (int e = 0; e < 9; ++e) {
    EXPECT_NEAR(f.stress_kinetic[e], expected[e] / 8.0, kRoundOff) << "component " << e;
    EXPECT_NEAR(f.stress[e], expected[e] / 8.0, kRoundOff) << "component " << e;
  }
  EXPECT_NEAR(f.pressure[0], 24.0 / 3.0 / 8.0, kRoundOff);
  EXPECT_EQ(f.time, 0.5);
}

TEST(CellGrid, ContactStressOfCubicLatticeUnderPairForces) {
  // 4^3 particles, spacing l, every x-neighbour pair pushed apart by F:
  // 3*4*4 = 48 bonds, sigma_xx = 48 l F / V (physics.md §8), all else 0.
  // Two cells along x: the 16 bonds crossing the cell face are split 1/2:1/2,
  // so each cell holds 24 bond virials over half the volume: the same sigma.
  const double l = 0.01, F = 3.0, L = 4 * l;
  CellGridSpec spec = box_spec(0, L, 2, 1, 1);
  CellGrid grid(spec);
  ParticleStore s;
  auto at = [](int i, int j, int k) { return static_cast<std::uint32_t>(i + 4 * (j + 4 * k)); };
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) s.add(at(i, j, k), (i + 0.5) * l, (j + 0.5) * l, (k + 0.5) * l, l / 2, 2500);
  std::vector<ContactRecord> repulsive, attractive;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 3; ++i) {
        // force on the left particle from its right neighbour: pushes it to -x
        repulsive.push_back(pair(s, at(i, j, k), at(i + 1, j, k), -F, 0, 0));
        attractive.push_back(pair(s, at(i + 1, j, k), at(i, j, k), -F, 0, 0));  // right one pulled to -x
      }
  const double V = L * L * L;
  grid.sample(s, {&repulsive, nullptr}, 0.0);
  for (std::size_t c = 0; c < 2; ++c) {
    const double* st = &grid.latest().stress[9 * c];
    EXPECT_NEAR(st[0], 48 * l * F / V, 1e-9 * 48 * l * F / V) << "cell " << c;
    for (int e = 1; e < 9; ++e) EXPECT_EQ(st[e], 0.0) << "cell " << c << " component " << e;
    EXPECT_GT(grid.latest().pressure[c], 0.0) << "compression must give p > 0";
    EXPECT_NEAR(grid.latest().pressure[c], 16 * l * F / V, 1e-9 * 16 * l * F / V);
  }
  grid.sample(s, {&attractive}, 0.0);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_NEAR(grid.latest().stress[9 * c], -48 * l * F / V, 1e-9 * 48 * l * F / V);
    EXPECT_LT(grid.latest().pressure[c], 0.0) << "tension must give p < 0";
  }
}

TEST(CellGrid, WallContactVirialUsesTheContactPoint) {
  // A sphere of radius r resting on the floor z = 0 with weight W: the floor
  // pushes it up with W at (x, y, 0). Virial (x_i - p) (x) F = r W in zz.
  const double r = 0.002, W = 0.5;
  CellGrid grid(box_spec(0, 0.01, 1, 1, 1));
  ParticleStore s;
  s.add(0, 0.005, 0.004, r, r, 2500);
  std::vector<ContactRecord> rec = {ContactRecord{0, ContactRecord::kWall, 0, 0, W, 0.005, 0.004, 0.0}};
  grid.sample(s, {&rec}, 0.0);
  const double V = 1e-6;
  const CellFields& f = grid.latest();
  EXPECT_NEAR(f.stress[8], r * W / V, 1e-12 * r * W / V);
  for (int e = 0; e < 8; ++e) EXPECT_EQ(f.stress[e], 0.0);
  EXPECT_GT(f.pressure[0], 0.0);
}

TEST(CellGrid, PairWithOnePartnerOutsideKeepsOnlyTheInsideHalf) {
  // Also: a particle outside the box is ignored in every field.
  CellGrid grid(box_spec(0, 1, 1, 1, 1));
  ParticleStore s;
  s.add(0, 0.9, 0.5, 0.5, 0.1, 1000);
  s.add(1, 1.1, 0.5, 0.5, 0.1, 1000);  // outside (x >= hi)
  s.add(2, 1.0, 0.5, 0.5, 0.1, 1000);  // on hi: outside, bins are [lo, hi)
  s.vx = {0, 5, 5};
  std::vector<ContactRecord> rec = {pair(s, 0, 1, -2.0, 0, 0)};  // repulsive, |l| = 0.2
  grid.sample(s, {&rec}, 0.0);
  const CellFields& f = grid.latest();
  EXPECT_EQ(f.count[0], 1);
  EXPECT_EQ(f.vx[0], 0.0);
  EXPECT_NEAR(f.volume_fraction[0], 4.0 / 3.0 * kPi * 1e-3, kRoundOff);
  EXPECT_NEAR(f.stress[0], 0.5 * 0.2 * 2.0, kRoundOff);
  EXPECT_EQ(grid.cell_of(1.0, 0.5, 0.5), -1);
  EXPECT_EQ(grid.cell_of(0.0, 0.0, 0.0), 0);
}

TEST(CellGrid, AccessibleVolumeOfCellsCutByCylinder) {
  // Cylinder mantle of radius R = 1 about z, particles inside; a 6x6 grid of
  // 0.4 m cells over [-1.2, 1.2]^2. w_c is the area fraction of the square
  // inside the disk. Sampling error with n points per axis: a wall cuts the
  // cell's sub-cell grid and each cut sub-cell is misclassified by at most
  // its own volume. For a plane parallel to a sub-cell row the errors add to
  // at most 1/(2n) of the cell (half a row), the worst case; a curved wall
  // cuts rows at varying depths, so its errors partly cancel: we allow 1/(2n)
  // (0.0625 at n = 8; 0.019 is measured here).
  // Over the whole disk the errors of the K ~ 8R/h_s sub-cells the circle
  // cuts (h_s = 0.05 m) have random signs, each uniform within +-h_s^2/2:
  // sigma = sqrt(K/12) h_s^2 per unit depth; we allow 3 sigma.
  CellGridSpec spec = box_spec(-1.2, 1.2, 6, 6, 1);
  spec.lo[2] = 0;
  spec.hi[2] = 0.5;
  CellGrid grid(spec);
  WallPrimitive cyl;
  cyl.shape = WallPrimitive::Shape::cylinder_inside;
  cyl.axis = 2;
  cyl.radius = 1.0;
  cyl.lo = -10;
  cyl.hi = 10;
  WallPrimitive gone;  // a plug already removed: must be ignored
  gone.n[2] = -1;      // would exclude everything above z = 0
  gone.remove_at = 0.0;
  grid.set_accessible({cyl, gone});
  const int n = spec.accessible_samples;
  double total = 0, max_err = 0;
  for (int iy = 0; iy < 6; ++iy)
    for (int ix = 0; ix < 6; ++ix) {
      const double x0 = -1.2 + 0.4 * ix, y0 = -1.2 + 0.4 * iy;
      const double exact = disk_square_area(x0, x0 + 0.4, y0, y0 + 0.4, 1.0) / 0.16;
      const double w = grid.accessible()[grid.index(ix, iy, 0)];
      max_err = std::max(max_err, std::abs(w - exact));
      EXPECT_NEAR(w, exact, 1.0 / (2 * n)) << "cell " << ix << "," << iy;
      total += w * grid.cell_volume();
    }
  const double h_s = 0.4 / n, cut = 8 * 1.0 / h_s;
  EXPECT_NEAR(total, kPi * 0.5, 3 * std::sqrt(cut / 12) * h_s * h_s * 0.5);
  // corner cells lie wholly outside, the four centre cells wholly inside
  EXPECT_EQ(grid.accessible()[grid.index(0, 0, 0)], 0.0);
  EXPECT_EQ(grid.accessible()[grid.index(2, 2, 0)], 1.0);
  EXPECT_EQ(grid.latest().accessible, grid.accessible());
  std::printf("accessible: max cell error %.4f (bound %.4f), total %.5f vs %.5f\n", max_err, 1.0 / (2 * n), total,
              kPi * 0.5);
}

TEST(CellGrid, ProfileWeightsByAccessibleVolume) {
  // Box [0,2]x[0,1]x[0,1], 2x1x1 cells; a plane at x = 1.5 facing -x leaves
  // exactly half of cell 1 accessible (8 sub-samples per axis, 4 on each side).
  CellGridSpec spec;
  spec.name = "p";
  spec.hi[0] = 2;
  spec.hi[1] = 1;
  spec.hi[2] = 1;
  spec.cells[0] = 2;
  CellGrid grid(spec);
  WallPrimitive plane;
  plane.p[0] = 1.5;
  plane.n[0] = -1;
  plane.n[2] = 0;
  grid.set_accessible({plane});
  ASSERT_EQ(grid.accessible()[0], 1.0);
  ASSERT_EQ(grid.accessible()[1], 0.5);
  ParticleStore s;
  s.add(0, 0.5, 0.5, 0.5, 0.3, 1000);
  s.add(1, 1.2, 0.5, 0.5, 0.2, 1000);
  s.mass = {1.0, 2.0};
  s.vx = {3.0, 0.0};
  grid.sample(s, kNoRecords, 0.0);
  const double v0 = 4.0 / 3.0 * kPi * 0.027, v1 = 4.0 / 3.0 * kPi * 0.008;
  const CellFields& f = grid.latest();
  EXPECT_NEAR(f.volume_fraction[0], v0, kRoundOff);
  EXPECT_NEAR(f.volume_fraction[1], v1 / 0.5, kRoundOff);
  const LayerProfile p = grid.profile(f, 2);
  ASSERT_EQ(p.centre.size(), 1u);
  EXPECT_NEAR(p.accessible_volume[0], 1.5, kRoundOff);
  EXPECT_NEAR(p.volume_fraction[0], (v0 + v1) / 1.5, kRoundOff);
  EXPECT_NEAR(p.vx[0], 3.0 / 3.0, kRoundOff);  // mass-weighted: (1*3 + 2*0)/3
  EXPECT_THROW(grid.profile(f, 3), std::invalid_argument);
}

TEST(CellGrid, MeanSinceLastTakeAveragesSamples) {
  CellGrid grid(box_spec(0, 1, 1, 1, 1));
  ParticleStore s;
  s.add(0, 0.5, 0.5, 0.5, 0.1, 1000);
  s.mass = {2.0};
  s.vx = {1.0};
  grid.sample(s, kNoRecords, 1.0);
  // second sample: a second particle (mass 6, at rest) enters the cell
  s.add(1, 0.2, 0.2, 0.2, 0.1, 1000);
  s.mass[1] = 6.0;
  grid.sample(s, kNoRecords, 2.0);
  EXPECT_EQ(grid.samples_pending(), 2u);
  EXPECT_NEAR(grid.latest().vx[0], 2.0 / 8.0, kRoundOff);
  const CellFields m = grid.mean_since_last_take();
  EXPECT_EQ(m.samples, 2u);
  EXPECT_EQ(m.time, 2.0);
  EXPECT_EQ(m.count[0], 1.5);
  EXPECT_NEAR(m.volume_fraction[0], 1.5 * 4.0 / 3.0 * kPi * 1e-3, kRoundOff);
  EXPECT_EQ(m.mass[0], 5.0);
  // Favre over time: momentum (2 + 2) / mass (2 + 8)
  EXPECT_NEAR(m.vx[0], 0.4, kRoundOff);
  // kinetic stress: sample 1 has none (one particle); sample 2:
  // 2 (1 - 0.25)^2 + 6 (0.25)^2 = 1.5; mean 0.75
  EXPECT_NEAR(m.stress_kinetic[0], 0.75, kRoundOff);
  EXPECT_NEAR(m.pressure[0], 0.25, kRoundOff);
  EXPECT_EQ(grid.samples_pending(), 0u);
  const CellFields empty = grid.mean_since_last_take();
  EXPECT_EQ(empty.samples, 0u);
  EXPECT_EQ(sum(empty.count), 0.0);
  EXPECT_EQ(empty.accessible, std::vector<double>{1.0});
}

TEST(CellGrid, RejectsBadSpecAndRecords) {
  CellGridSpec bad = box_spec(0, 1, 1, 1, 1);
  bad.cells[1] = 0;
  EXPECT_THROW(CellGrid{bad}, std::invalid_argument);
  bad = box_spec(1, 1, 1, 1, 1);
  EXPECT_THROW(CellGrid{bad}, std::invalid_argument);
  bad = box_spec(0, 1, 1, 1, 1);
  bad.every = 0;
  EXPECT_THROW(CellGrid{bad}, std::invalid_argument);
  bad.every = 15;
  bad.name = "a/b";
  EXPECT_THROW(CellGrid{bad}, std::invalid_argument);

  CellGrid grid(box_spec(0, 1, 1, 1, 1));
  EXPECT_TRUE(grid.due(30));
  EXPECT_FALSE(grid.due(31));
  ParticleStore s;
  s.add(0, 0.5, 0.5, 0.5, 0.1, 1000);
  std::vector<ContactRecord> rec = {ContactRecord{0, 7, 1, 0, 0, 0, 0, 0}};  // 7: out of range
  EXPECT_THROW(grid.sample(s, {&rec}, 0.0), RuntimeError);
}
