// Guards refinement and coarsening (coupling/conversion.hpp): exact mass
// books in integer units, momentum to round-off, children placed without
// overlap inside their parcel and moving with its rigid motion, parcels at
// their group's centre of mass with its momentum and, where the energy
// allows, its angular momentum; no energy ever created by coarsening.
// Cost: well under a second.
#include "coupling/conversion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace domel::platform {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRho = 2500;  // [kg/m^3] glass

double sphere_mass(double r) { return kRho * 4.0 / 3.0 * kPi * r * r * r; }
double norm(const double a[3]) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

ConvertedBody a_parcel(double radius) {
  ConvertedBody p;
  p.x[0] = 0.31, p.x[1] = -0.12, p.x[2] = 1.7;  // away from the origin, as in a real scene
  p.v[0] = 0.4, p.v[1] = -0.25, p.v[2] = -1.1;
  p.w[0] = 30, p.w[1] = -55, p.w[2] = 12;
  p.radius = radius;
  p.mass = sphere_mass(radius);
  p.start_radius = radius;
  return p;
}

// Round-off of sums of a few hundred terms of one sign, relative to the largest (the tolerance of every
// "to round-off" check below): some 1e-16 per term, with a margin of ten.
constexpr double kRoundOff = 1e-13;

TEST(Refine, AParcelOfRatioTwoMakesEightChildrenWithExactBooks) {
  const double rf = 0.5e-3, rc = 2 * rf;
  const ConvertedBody parcel = a_parcel(rc);
  CarriedMass carried;
  std::mt19937_64 rng(7);
  std::vector<ConvertedBody> made;
  ConversionBooks books;
  refine_parcel(parcel, rf, sphere_mass(rf), carried, rng, made, books);
  ASSERT_EQ(made.size(), 8u);
  EXPECT_EQ(books.in, 1u);
  EXPECT_EQ(books.out, 8u);
  EXPECT_EQ(books.mass_residual(), 0);
  // what is carried is the rounding of the two masses apart, a few 1e-18 kg units either way
  EXPECT_LE(carried.units < 0 ? -carried.units : carried.units, 100);
  EXPECT_LE(books.momentum_relative(), kRoundOff);

  // inside the parcel, clear of each other, and starting smaller than their own radius
  for (std::size_t i = 0; i < made.size(); ++i) {
    const auto& c = made[i];
    EXPECT_EQ(c.radius, rf);
    EXPECT_EQ(c.mass, sphere_mass(rf));
    EXPECT_GT(c.start_radius, 0.6 * rf);  // the most compact FCC cluster of 8 in a sphere of 2 rf: 0.653 rf
    EXPECT_LT(c.start_radius, rf);
    double d[3];
    for (int a = 0; a < 3; ++a) d[a] = c.x[a] - parcel.x[a];
    EXPECT_LE(norm(d) + c.start_radius, rc);
    for (std::size_t j = 0; j < i; ++j) {
      double e[3];
      for (int a = 0; a < 3; ++a) e[a] = c.x[a] - made[j].x[a];
      EXPECT_GE(norm(e), c.start_radius + made[j].start_radius);
    }
  }
  // the rigid motion: v_i - V = w x r_i, every child spinning with w; V the parcel's (the carried
  // mass is a rounding, so V differs from it at round-off)
  double J_w[3] = {0, 0, 0}, fluct = 0;
  const double m = sphere_mass(rf);
  for (const auto& c : made) {
    double r[3], wr[3];
    for (int a = 0; a < 3; ++a) r[a] = c.x[a] - parcel.x[a];
    wr[0] = parcel.w[1] * r[2] - parcel.w[2] * r[1];
    wr[1] = parcel.w[2] * r[0] - parcel.w[0] * r[2];
    wr[2] = parcel.w[0] * r[1] - parcel.w[1] * r[0];
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(c.v[a], parcel.v[a] + wr[a], 1e-12 * norm(parcel.v));
      EXPECT_EQ(c.w[a], parcel.w[a]);
    }
    // r x (w x r) = |r|^2 w - (r.w) r
    const double rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2], rw = r[0] * parcel.w[0] + r[1] * parcel.w[1] + r[2] * parcel.w[2];
    for (int a = 0; a < 3; ++a) J_w[a] += m * (rr * parcel.w[a] - rw * r[a]);
    fluct += 0.5 * m * (wr[0] * wr[0] + wr[1] * wr[1] + wr[2] * wr[2]);
  }
  // the books' angular momentum and energies against the same sums written out
  const double If = 0.4 * m * rf * rf, Ic = 0.4 * parcel.mass * rc * rc;
  const double w2 = parcel.w[0] * parcel.w[0] + parcel.w[1] * parcel.w[1] + parcel.w[2] * parcel.w[2];
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(books.angular_in[a], Ic * parcel.w[a], 1e-14 * Ic * norm(parcel.w));
    EXPECT_NEAR(books.angular_out[a], J_w[a] + 8 * If * parcel.w[a], 1e-10 * Ic * norm(parcel.w));
  }
  EXPECT_NEAR(books.fluctuation, fluct, 1e-10 * fluct);
  const double v2 = parcel.v[0] * parcel.v[0] + parcel.v[1] * parcel.v[1] + parcel.v[2] * parcel.v[2];
  EXPECT_NEAR(books.kinetic_in, 0.5 * parcel.mass * v2 + 0.5 * Ic * w2, 1e-13 * books.kinetic_in);
  EXPECT_NEAR(books.kinetic_out, 0.5 * 8 * m * v2 + fluct + 0.5 * 8 * If * w2, 1e-10 * books.kinetic_out);
}

TEST(Refine, ARatioThatIsNotWholeCarriesTheRestAndKeepsExactBooksOverManyParcels) {
  // alpha 8 -> 6: (4/3)^3 = 2.370 fine particles per parcel
  const double rf = 0.45e-3, rc = rf * 8.0 / 6.0;
  const double mf = sphere_mass(rf);
  CarriedMass carried;
  std::mt19937_64 rng(11);
  std::vector<ConvertedBody> made;
  ConversionBooks books;
  std::mt19937_64 vel(3);
  const int parcels = 1000;
  for (int k = 0; k < parcels; ++k) {
    ConvertedBody p = a_parcel(rc);
    for (int a = 0; a < 3; ++a) p.v[a] = static_cast<double>(vel() % 2001) / 1000.0 - 1.0;
    ConversionBooks one;
    refine_parcel(p, rf, mf, carried, rng, made, one);
    EXPECT_EQ(one.mass_residual(), 0) << "parcel " << k;
    books.add(one);
  }
  EXPECT_EQ(books.mass_residual(), 0);
  EXPECT_LE(books.momentum_relative(), kRoundOff);
  const MassUnits unit = mass_units(mf);
  EXPECT_LT(carried.units, unit);
  EXPECT_GT(carried.units, -unit / 1000000 - 1);
  // every parcel's material is in the children or carried: n = floor(1000 mc / mf) give or take the carry
  const double expected = parcels * sphere_mass(rc) / mf;
  EXPECT_EQ(made.size(), static_cast<std::size_t>(std::floor(expected + 1e-6)));
  EXPECT_EQ(books.in, static_cast<std::uint64_t>(parcels));
}

TEST(Refine, TheSameGeneratorStateGivesTheSameChildren) {
  const double rf = 0.25e-3, rc = 4 * rf;
  std::vector<ConvertedBody> a, b;
  CarriedMass ca, cb;
  ConversionBooks ba, bb;
  std::mt19937_64 ra(99), rb(99);
  refine_parcel(a_parcel(rc), rf, sphere_mass(rf), ca, ra, a, ba);
  refine_parcel(a_parcel(rc), rf, sphere_mass(rf), cb, rb, b, bb);
  ASSERT_EQ(a.size(), 64u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(a[i].x[d], b[i].x[d]);
      EXPECT_EQ(a[i].v[d], b[i].v[d]);
    }
  // a larger cluster fills its sphere better: the children start closer to their own size
  EXPECT_GT(ba.smallest_start, 0.7);
}

TEST(Coarsen, EightParticlesMakeAParcelAtTheirCentreOfMassWithTheirMomentum) {
  const double rf = 0.5e-3, rc = 2 * rf, mf = sphere_mass(rf);
  std::mt19937_64 rng(5);
  auto u = [&rng] { return static_cast<double>(rng() % 100001) / 100000.0 - 0.5; };
  CoarsenGather g;
  std::vector<ConvertedBody> made;
  ConversionBooks books;
  double sx[3] = {0, 0, 0}, sp[3] = {0, 0, 0}, rot_in = 0;
  for (int k = 0; k < 8; ++k) {
    ConvertedBody f;
    for (int a = 0; a < 3; ++a) {
      f.x[a] = 1.3 + 2 * rc * u();
      f.v[a] = 2 * u();
      f.w[a] = 100 * u();
      sx[a] += mf * f.x[a];
      sp[a] += mf * f.v[a];
    }
    f.radius = rf;
    f.mass = mf;
    rot_in += 0.5 * 0.4 * mf * rf * rf * (f.w[0] * f.w[0] + f.w[1] * f.w[1] + f.w[2] * f.w[2]);
    coarsen_add(f, rc, sphere_mass(rc), g, made, books);
    EXPECT_EQ(made.size(), k < 7 ? 0u : 1u) << k;
  }
  ASSERT_EQ(made.size(), 1u);
  const auto& p = made[0];
  EXPECT_EQ(p.mass, sphere_mass(rc));
  EXPECT_EQ(p.radius, rc);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(p.x[a], sx[a] / (8 * mf), 1e-14 * 1.3);
    EXPECT_NEAR(p.v[a], sp[a] / sphere_mass(rc), 1e-12);
  }
  EXPECT_EQ(books.mass_residual(), 0);
  EXPECT_LE(books.momentum_relative(), kRoundOff);
  EXPECT_EQ(books.in, 8u);
  EXPECT_EQ(books.out, 1u);
  // random velocities: energy goes, none comes. What goes is the fluctuation and the particles' own spin
  // energy, less what the parcel's spin keeps: E_in - E_out = fluctuation + rot_in - 1/2 I w^2
  EXPECT_LT(books.kinetic_out, books.kinetic_in);
  EXPECT_GT(books.fluctuation, 0);
  const double Ic = 0.4 * p.mass * rc * rc;
  const double spin_out = 0.5 * Ic * (p.w[0] * p.w[0] + p.w[1] * p.w[1] + p.w[2] * p.w[2]);
  EXPECT_NEAR(books.kinetic_in - books.kinetic_out, books.fluctuation + rot_in - spin_out, 1e-12 * books.kinetic_in);
}

// Eight particles on a ring of radius a turning rigidly about z: L = 8 m a^2 w. A parcel of radius R holds it
// with spin L / (2/5 M R^2), whose energy is (a^2 / (0.4 R^2)) times the ring's: below it for a^2 < 0.4 R^2,
// and then the angular momentum is carried exactly; above, the spin takes all the ring's energy and no more.
void ring(double a, double R, ConversionBooks& books, ConvertedBody& parcel) {
  const double m = sphere_mass(R) / 8, w = 40.0, r_f = R / 2;
  CoarsenGather g;
  std::vector<ConvertedBody> made;
  for (int k = 0; k < 8; ++k) {
    const double phi = 2 * kPi * k / 8;
    ConvertedBody f;
    f.x[0] = 2.0 + a * std::cos(phi), f.x[1] = -1.0 + a * std::sin(phi), f.x[2] = 0.5;
    f.v[0] = -w * a * std::sin(phi), f.v[1] = w * a * std::cos(phi);
    f.radius = r_f * 1e-3;  // point-like, so that their own spin terms (none here) do not matter
    f.mass = m;
    coarsen_add(f, R, sphere_mass(R), g, made, books);
  }
  ASSERT_EQ(made.size(), 1u);
  parcel = made[0];
}

TEST(Coarsen, ARingTurningRigidlyKeepsItsAngularMomentumWhereTheEnergyAllowsIt) {
  const double R = 1e-3;
  {
    ConversionBooks books;
    ConvertedBody p;
    ring(0.5 * R, R, books, p);  // a^2 = 0.25 R^2 < 0.4 R^2
    const double L = sphere_mass(R) * 0.25 * R * R * 40.0;
    EXPECT_NEAR(books.angular_in[2], L, 1e-12 * L);
    EXPECT_NEAR(books.angular_out[2], L, 1e-12 * L);
    EXPECT_NEAR(p.w[2], L / (0.4 * sphere_mass(R) * R * R), 1e-9);
    EXPECT_NEAR(books.kinetic_out, books.kinetic_in * 0.25 / 0.4, 1e-10 * books.kinetic_in);
  }
  {
    ConversionBooks books;
    ConvertedBody p;
    ring(R, R, books, p);  // a^2 = R^2 > 0.4 R^2: the spin is lowered to the ring's energy
    const double L = sphere_mass(R) * R * R * 40.0;
    EXPECT_NEAR(books.angular_in[2], L, 1e-12 * L);
    EXPECT_LT(books.angular_out[2], L);
    EXPECT_NEAR(books.kinetic_out, books.kinetic_in, 1e-12 * books.kinetic_in);
    EXPECT_NEAR(books.angular_out[2], L * std::sqrt(0.4), 1e-9 * L);  // sqrt(2 E I) with E = L w / 2
  }
}

TEST(Coarsen, ARatioThatIsNotWholeSplitsTheLastParticleAndKeepsExactBooks) {
  const double rf = 0.45e-3, rc = rf * 8.0 / 6.0, mf = sphere_mass(rf), mc = sphere_mass(rc);
  std::mt19937_64 rng(17);
  auto u = [&rng] { return static_cast<double>(rng() % 100001) / 100000.0 - 0.5; };
  CoarsenGather g;
  std::vector<ConvertedBody> made;
  ConversionBooks books;
  const int n = 1000;
  for (int k = 0; k < n; ++k) {
    ConvertedBody f;
    for (int a = 0; a < 3; ++a) f.x[a] = 0.2 * u(), f.v[a] = u(), f.w[a] = 10 * u();
    f.radius = rf;
    f.mass = mf;
    coarsen_add(f, rc, mc, g, made, books);
  }
  EXPECT_EQ(made.size(), static_cast<std::size_t>(std::floor(n * mf / mc)));
  EXPECT_EQ(books.mass_residual(), 0);
  EXPECT_LE(books.momentum_relative(), kRoundOff);
  EXPECT_GE(g.units, 0);
  EXPECT_LT(g.units, mass_units(mc));
  EXPECT_LE(books.kinetic_out, books.kinetic_in * (1 + 1e-12));  // equal where a spin takes all it may
}

TEST(Conversion, RefiningThenCoarseningGivesTheParcelBack) {
  const double rf = 0.5e-3, rc = 2 * rf;
  const ConvertedBody parcel = a_parcel(rc);
  CarriedMass carried;
  std::mt19937_64 rng(23);
  std::vector<ConvertedBody> children, back;
  ConversionBooks refine_books, coarsen_books;
  refine_parcel(parcel, rf, sphere_mass(rf), carried, rng, children, refine_books);
  CoarsenGather g;
  for (const auto& c : children) coarsen_add(c, rc, parcel.mass, g, back, coarsen_books);
  ASSERT_EQ(back.size(), 1u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(back[0].x[a], parcel.x[a], 1e-15 * 2);
    EXPECT_NEAR(back[0].v[a], parcel.v[a], 1e-13);
  }
  EXPECT_EQ(back[0].mass, parcel.mass);
  EXPECT_EQ(refine_books.mass_residual() + coarsen_books.mass_residual(), 0);
}

TEST(Conversion, NonsenseSizesAreRefused) {
  CarriedMass carried;
  std::mt19937_64 rng(1);
  std::vector<ConvertedBody> made;
  ConversionBooks books;
  EXPECT_THROW(refine_parcel(a_parcel(1e-3), 0.0, 1.0, carried, rng, made, books), std::invalid_argument);
  CoarsenGather g;
  ConvertedBody heavy = a_parcel(1e-3);
  EXPECT_THROW(coarsen_add(heavy, 0.5e-3, sphere_mass(0.5e-3), g, made, books), std::invalid_argument);
}

}  // namespace
}  // namespace domel::platform
