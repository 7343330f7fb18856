// Guards refinement in a level (coupling/conversion.hpp, Subdomain::grow;
// docs/adaptive.md): a settled column of 200 parcels refined at rest into
// eight fine particles each, placed inside their parcels at 0.65 of their
// radius and grown to it in 0.02 s (a particle pressing into a neighbour or
// a wall by more than 1 % of its diameter waits), regrows without bursting
// and comes to rest as high as the parcels stood: no two particles overlap
// where they are placed; the fine mass is the parcels' to the 1e-18 kg unit;
// every particle reaches its radius; the column's top never rises three fine
// diameters above the parcels' (grown at a fixed rate without the wait, it
// rose twelve: docs/adaptive.md); 0.1 s after the growth the kinetic energy is
// below a thousandth of what the particles would gain falling one fine
// radius each, and the top within a fine diameter of the parcels' (the same
// solid volume, packed alike). A run restarted halfway through the growth
// goes on bit for bit. The transient (the column sags while the particles
// are small, then regrows) is printed, not bounded: docs/adaptive.md.
// Cost: about 3 s on one thread (200 parcels settled for 0.25 s, then 1,600
// fine particles for 0.12 s, and again from the middle of the growth).
#include "core/archive.hpp"
#include "coupling/conversion.hpp"
#include "coupling/coupling.hpp"
#include "scheduler/simulation.hpp"
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <unistd.h>

namespace dt = domel::test;
using domel::platform::CarriedMass;
using domel::platform::ConversionBooks;
using domel::platform::ConvertedBody;
using nlohmann::json;

namespace {

constexpr double kDensity = 2500;
// the store's own mass of a sphere (ParticleStore::add), so that the books compare like with like
double mass_of(double r) { return kDensity * 4.0 / 3.0 * M_PI * r * r * r; }

/// A box 5 x 5 x 16 lattice spacings of `box_d`, open at the top, Hertz-Mindlin (e 0.5, mu 0.5), gravity;
/// with `fill`, a 5 x 5 x 8 lattice of spheres of diameter box_d in it.
json column(double box_d, bool fill) {
  json doc = dt::lattice_column(box_d);
  const double a = 1.02 * box_d;
  doc["walls"][0]["max"] = {5 * a, 5 * a, 16 * a};
  if (fill) doc["subdomains"][0]["insert"][0]["region"]["box"]["max"] = {5 * a, 5 * a, 8 * a};
  else doc["subdomains"][0].erase("insert");
  return doc;
}

double kinetic(const domel::platform::SubdomainStats& s) { return s.kinetic_translational + s.kinetic_rotational; }

double top(const domel::platform::ParticleStore& s) {
  double z = 0;
  for (std::size_t k = 0; k < s.size(); ++k) z = std::max(z, s.z[k] + s.radius[k]);
  return z;
}

}  // namespace

TEST(Refinement, AColumnRefinedAtRestRegrowsWithoutBurstingAndComesToRestAsHighAsItsParcels) {
  const double dc = 0.0028, rc = dc / 2, rf = rc / 2;
  auto coarse_sim = dt::build(column(dc, true));
  auto& coarse = *coarse_sim->subdomains[0];
  coarse.set_skin(0.5 * dc);
  coarse.setup();
  for (int k = 0; k < 25000; ++k) coarse.step_deferred();  // 0.25 s at 1e-5 s: at rest
  const auto cs = coarse.stats();
  const auto& parcels = coarse.store();
  ASSERT_EQ(parcels.size(), 200u);
  const double coarse_top = top(parcels);

  auto fine_sim = dt::build(column(dc, false));
  auto& fine = *fine_sim->subdomains[0];
  CarriedMass carried;
  ConversionBooks books;
  std::mt19937_64 rng(42);
  std::vector<ConvertedBody> made;
  domel::platform::MassUnits coarse_units = 0;
  for (std::size_t q = 0; q < parcels.size(); ++q) {
    ConvertedBody p;
    p.x[0] = parcels.x[q], p.x[1] = parcels.y[q], p.x[2] = parcels.z[q];
    p.v[0] = parcels.vx[q], p.v[1] = parcels.vy[q], p.v[2] = parcels.vz[q];
    p.w[0] = parcels.wx[q], p.w[1] = parcels.wy[q], p.w[2] = parcels.wz[q];
    p.radius = parcels.radius[q];
    p.mass = parcels.mass[q];
    coarse_units += domel::platform::mass_units(p.mass);
    refine_parcel(p, rf, mass_of(rf), carried, rng, made, books);
  }
  ASSERT_EQ(made.size(), 1600u);
  EXPECT_EQ(books.mass_residual(), 0);
  const double growth_time = 0.02;  // [s]
  auto& fs = fine.store();
  for (std::size_t k = 0; k < made.size(); ++k) {
    const ConvertedBody& c = made[k];
    fs.add(k + 1, c.x[0], c.x[1], c.x[2], rf, kDensity);
    fs.vx[k] = c.v[0], fs.vy[k] = c.v[1], fs.vz[k] = c.v[2];
    fs.wx[k] = c.w[0], fs.wy[k] = c.w[1], fs.wz[k] = c.w[2];
    fs.radius[k] = c.start_radius;
    fine.grow(k, rf, (rf - c.start_radius) / growth_time);
  }
  // the fine particles' mass is the parcels' less what is carried, to the unit
  domel::platform::MassUnits fine_units = 0;
  for (double m : fs.mass) fine_units += domel::platform::mass_units(m);
  EXPECT_EQ(fine_units + carried.units, coarse_units);
  // no two children overlap where they are placed
  double closest = 1e9;
  for (std::size_t a = 0; a < fs.size(); ++a)
    for (std::size_t b = a + 1; b < fs.size(); ++b) {
      const double d = std::hypot(fs.x[a] - fs.x[b], fs.y[a] - fs.y[b], fs.z[a] - fs.z[b]);
      closest = std::min(closest, d - fs.radius[a] - fs.radius[b]);
    }
  EXPECT_GE(closest, 0.0);

  const auto rep = fine.estimate_time_step(0.1);
  const double dt = std::min(rep.contact_time / 50.0, 1e-5);
  fine.set_time_step(dt);
  fine.set_skin(0.5 * 2 * rf);
  fine.setup();
  const auto steps = static_cast<int>(std::ceil((growth_time + 0.1) / dt));
  const int checkpoint_at = static_cast<int>(0.5 * growth_time / dt);  // halfway through the growth
  std::string saved;
  double peak_kinetic = 0, peak_overlap = 0, peak_top = 0;
  for (int k = 0; k < steps; ++k) {
    if (k == checkpoint_at) {
      domel::platform::ArchiveWriter w;
      fine.save(w, "fine/");
      saved = w.serialize("{}");
    }
    fine.step_deferred();
    if (k % 50 == 0 || k == steps - 1) {
      const auto s = fine.stats();
      peak_kinetic = std::max(peak_kinetic, kinetic(s));
      peak_overlap = std::max(peak_overlap, s.max_overlap_ratio);
      peak_top = std::max(peak_top, top(fine.store()));
    }
  }
  EXPECT_FALSE(fine.growing());
  for (double r : fine.store().radius) ASSERT_EQ(r, rf);
  const auto fs_end = fine.stats();
  const double fall_one_radius = 1600 * mass_of(rf) * 9.81 * rf;
  std::printf("parcels: top %.4f m, largest overlap/d %.3e; fine particles: top %.4f m at the end, %.4f m at the "
              "highest; largest overlap/d %.3e; kinetic energy at the peak %.3e J (one fine radius of fall each: "
              "%.3e J), at the end %.3e J; dt %.3e s\n",
              coarse_top, cs.max_overlap_ratio, top(fine.store()), peak_top, peak_overlap, peak_kinetic,
              fall_one_radius, kinetic(fs_end), dt);
  // no burst: the column's top never rises three fine diameters above the parcels' (the regrowth overshoots by
  // 1.3 to 1.9 of them, on one thread and two; grown at a fixed rate with no wait for overlaps the column rose
  // 12 of them, and was still moving at the end: docs/adaptive.md)
  EXPECT_LT(peak_top, coarse_top + 6 * rf);
  // at rest again (a millionth of the peak's scale), as high as the parcels within a fine diameter: the same
  // solid volume, packed alike
  EXPECT_LT(kinetic(fs_end), 1e-3 * fall_one_radius);
  EXPECT_NEAR(top(fine.store()), coarse_top, 2 * rf);

  // a run restarted halfway through the growth goes on bit for bit (the targets, rates and the lists' growth
  // since their build are in the checkpoint)
  auto twin_sim = dt::build(column(dc, false));
  auto& twin = *twin_sim->subdomains[0];
  twin.set_time_step(dt);
  twin.set_skin(0.5 * 2 * rf);
  twin.enable_growth();
  twin.restore(domel::platform::ArchiveReader(saved, "memory"), "fine/");
  EXPECT_TRUE(twin.growing());
  for (int k = checkpoint_at; k < steps; ++k) twin.step_deferred();
  const auto& a = fine.store();
  const auto& b = twin.store();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a.x[k], b.x[k]) << k;
    ASSERT_EQ(a.z[k], b.z[k]) << k;
    ASSERT_EQ(a.vz[k], b.vz[k]) << k;
  }
}

TEST(Refinement, ParcelsInAFineRegionAtTheStartBecomeItsMaterialWithExactBooks) {
  // A lattice of 2.8 mm parcels (alpha 2) 20 mm deep in a box 10 parcels
  // wide; the coupling's fine region (alpha 1) holds its lower 10 mm. The
  // fine level starts empty: each parcel whose centre lies in the region is
  // refined into eight 1.4 mm particles that grow to their size over 2000
  // fine steps (0.036 s, refine_growth_steps' default), counted into the
  // fine level's books. Checked after 0.06 s: the count made (eight per
  // parcel inside, counted here from the built scenario), the mass to the
  // unit (the ratio is whole: what is carried is the masses' rounding to
  // the unit, a few units a parcel), the fine books closed, every particle grown, and what
  // left through the region's top face while the packing regrew less than
  // a layer of the overshoot of a regrowing column (3 fine diameters:
  // Refinement.AColumnRefinedAtRest...). Cost: about 3 s.
  const double d = 0.0014, w = 10 * 1.02 * 2 * d;  // material diameter; the box's width (dt::refined_region)
  const double region_top = 0.01;
  const json doc = dt::refined_region(0.06);
  auto sim = dt::build(doc);
  const auto& parcels = sim->subdomains[0]->store();
  std::size_t inside = 0;
  domel::platform::MassUnits inside_units = 0;
  for (std::size_t q = 0; q < parcels.size(); ++q)
    if (parcels.z[q] <= region_top) ++inside, inside_units += domel::platform::mass_units(parcels.mass[q]);
  ASSERT_GT(inside, 200u);
  EXPECT_EQ(sim->subdomains[1]->store().size(), 0u);
  domel::platform::RunOptions opt;
  opt.progress = false;
  opt.output_directory = std::filesystem::temp_directory_path() / ("domel_refine_start_" + std::to_string(getpid()));
  sim->run(opt, dt::builtin_registry());
  std::filesystem::remove_all(opt.output_directory);

  const auto& r = sim->couplings.at(0)->start_refinement();
  EXPECT_EQ(r.parcels, inside);
  EXPECT_EQ(r.particles, 8 * inside);
  EXPECT_EQ(r.parcel_units, inside_units);
  EXPECT_EQ(r.particle_units + r.carried_units, r.parcel_units);  // exact, in units of 1e-18 kg
  // what is carried is the rounding of nine masses to the unit, at most 4.5 units a parcel (the ratio is whole)
  EXPECT_LE(std::abs(static_cast<double>(r.carried_units)), 4.5 * static_cast<double>(inside));
  EXPECT_GT(r.smallest_start, 0.6);
  const auto& f = sim->subdomains[1]->store();
  EXPECT_EQ(sim->flow.residual(1, f), 0);
  const double rf = d / 2;
  double highest = 0, smallest = 1;
  for (std::size_t k = 0; k < f.size(); ++k) {
    smallest = std::min(smallest, f.radius[k] / rf);
    highest = std::max(highest, f.z[k] + f.radius[k]);
  }
  const auto st = sim->subdomains[1]->stats();
  std::printf("[refined at start] %llu parcels -> %llu particles (start radius >= %.3f of theirs), carried %lld "
              "units; at 0.06 s: %zu fine particles, smallest radius %.4f of theirs, highest top %.2f mm, largest "
              "overlap %.2f %%, kinetic energy %.3g J; books of the operation: momentum residual %.2g kg m/s, "
              "kinetic %.3g -> %.3g J\n",
              static_cast<unsigned long long>(r.parcels), static_cast<unsigned long long>(r.particles),
              r.smallest_start, static_cast<long long>(r.carried_units), f.size(), smallest, 1e3 * highest,
              100 * st.max_overlap_ratio, st.kinetic_translational + st.kinetic_rotational, r.momentum_residual,
              r.kinetic_in, r.kinetic_out);
  // What left the fine level went out through the top face (the inflow face: a fine particle that crosses it
  // is removed, docs/multilevel.md) while the regrowing packing overshot; the other faces are the box's walls.
  // The overshoot of a regrowing column is below 3 fine diameters (Refinement.AColumnRefinedAtRest...): at most
  // the particles of a 3-diameter layer at a solid fraction of 0.6 leave.
  const auto& faces = sim->couplings.at(0)->faces();
  for (int face = 0; face < 5; ++face) EXPECT_EQ(faces[face].n_removed, 0u) << face;
  EXPECT_EQ(f.size() + faces[5].n_removed, r.particles + faces[5].n_inserted);
  const double layer = 0.6 * w * w * 6 * rf / (4.0 / 3.0 * M_PI * rf * rf * rf);
  std::printf("[refined at start] out through the top face: %llu (a 3-diameter layer holds %.0f), inserted "
              "there: %llu\n",
              static_cast<unsigned long long>(faces[5].n_removed), layer,
              static_cast<unsigned long long>(faces[5].n_inserted));
  EXPECT_LT(static_cast<double>(faces[5].n_removed), layer);
  EXPECT_EQ(smallest, 1.0);  // all grown: the growth caps at the radius exactly
  EXPECT_LT(highest, region_top + 2 * rf);  // what crosses the top face leaves at the next exchange
}
