// SPDX-License-Identifier: MIT
// Coupling: removal at the region's faces, face counting of coarse parcels,
// transfer by sequential simple inhibition (docs/physics.md §5.5, §6.2), the
// controller views (§5.3, §5.4) and the interface balance.
// About 770 lines in one file: the steps of an exchange work in order on the
// same gathered levels, face books and queues (coupling.hpp), whose exact
// books (counted = inserted + pending) hold only across all of them;
// read top to bottom the file is the exchange as physics.md §5-§6 gives it.
#include "coupling/coupling.hpp"

#include "core/interrupt.hpp"

#include "core/abi_views.hpp"

#include "core/archive.hpp"
#include "core/error.hpp"
#include "coupling/conversion.hpp"
#include "geometry/wall_clearance.hpp"
#include "io/cell_grid_output.hpp"
#include "io/csv_series.hpp"
#include "loop/ranks.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

namespace domel::platform {

namespace {

constexpr double kPi = 3.14159265358979323846;
const char* const kFaceNames[kFaces] = {"-x", "+x", "-y", "+y", "-z", "+z"};

double sphere_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

bool inside_box(const CellGridSpec& g, double x, double y, double z) {
  return x >= g.lo[0] && x <= g.hi[0] && y >= g.lo[1] && y <= g.hi[1] && z >= g.lo[2] && z <= g.hi[2];
}

/// The face of the box beyond which a point lies farthest, -1 inside.
int face_beyond(const CellGridSpec& g, double x, double y, double z) {
  const double p[3] = {x, y, z};
  int face = -1;
  double beyond = 0;
  for (int a = 0; a < 3; ++a) {
    if (g.lo[a] - p[a] > beyond) beyond = g.lo[a] - p[a], face = 2 * a;
    if (p[a] - g.hi[a] > beyond) beyond = p[a] - g.hi[a], face = 2 * a + 1;
  }
  return face;
}

/// A coupling's two controllers, with the checkpoint section of each one's state.
std::array<std::pair<const ControllerSetup*, const char*>, 2> controllers_of(const CouplingSpec& s) {
  return {{{&s.stress, "stress_state"}, {&s.velocity, "velocity_state"}}};
}

/// Consecutive transfers with a growing backlog before the warning.
constexpr int kBacklogWarnAfter = 5;

}  // namespace

const char* face_name(int face) { return face >= 0 && face < kFaces ? kFaceNames[face] : "?"; }

int face_from_name(const std::string& name) {
  for (int f = 0; f < kFaces; ++f)
    if (name == kFaceNames[f]) return f;
  return -1;
}

Coupling::Coupling(CouplingSpec spec) : spec_(std::move(spec)), rng_(spec_.seed) {
  CellGridSpec g = spec_.grid;
  g.write_interval = spec_.grid_interval;
  g.name = spec_.name + "_fine";
  g.every = spec_.fine_steps;
  fine_grid_ = std::make_unique<CellGrid>(g);
  g.name = spec_.name + "_coarse";
  g.every = spec_.coarse_steps;
  coarse_grid_ = std::make_unique<CellGrid>(g);
}

Coupling::~Coupling() = default;

double Coupling::shell_volume(int face) const {
  const int a = face / 2;
  double area = 1;
  for (int b = 0; b < 3; ++b)
    if (b != a) area *= spec_.grid.hi[b] - spec_.grid.lo[b];
  return area * spec_.shell_depth;
}

void Coupling::start(std::vector<std::unique_ptr<Subdomain>>& subdomains, const std::vector<WallPrimitive>& walls,
                     const std::filesystem::path& out) {
  fine_grid_->set_accessible(walls, 0.0);
  coarse_grid_->set_accessible(walls, 0.0);
  const GatheredParticles all_c = ranks_->gather(*subdomains[spec_.coarse], true);
  const GatheredParticles all_f = ranks_->gather(*subdomains[spec_.fine], true);
  const ParticleStore& c = *all_c;
  const ParticleStore& f = *all_f;
  const double scale = subdomains[spec_.fine]->coarse_grain() / subdomains[spec_.coarse]->coarse_grain();
  for (double r : f.radius) fine_dmax_ = std::max(fine_dmax_, 2 * r);
  for (double r : c.radius) fine_dmax_ = std::max(fine_dmax_, 2 * r * scale);
  coarse_last_.clear();
  for (std::size_t q = 0; q < c.size(); ++q) coarse_last_[c.id[q]] = {c.x[q], c.y[q], c.z[q], c.mass[q]};
  if (out.empty()) return;
  std::vector<std::string> cols = {"time"};
  for (int face = 0; face < kFaces; ++face) {
    const std::string n = kFaceNames[face];
    if (spec_.inflow[face])
      for (const char* k : {".counted_kg", ".inserted_kg", ".pending_kg", ".backlog", ".velocity_z"})
        cols.push_back(n + k);
    cols.push_back(n + ".removed_kg");
  }
  for (const char* k : {"outlet_removed_kg", "holdup_kg", "fine_particles", "fine_balance_residual_kg"})
    cols.emplace_back(k);
  if (spec_.match_outflow)
    for (const char* k : {"fine_lost_kg", "coarse_lost_kg", "coarse_sink_kg", "outflow_deficit_kg"}) cols.emplace_back(k);
  balance_ = std::make_unique<io::CsvSeries>(out / (spec_.name + "_balance.csv"), cols, 20);
  if (spec_.grid_interval > 0) {
    vtk_fine_ = std::make_unique<io::CellGridVtkSeries>(out, spec_.name + "_fine");
    vtk_coarse_ = std::make_unique<io::CellGridVtkSeries>(out, spec_.name + "_coarse");
    grid_files_ = Cadence::in_time(spec_.grid_interval, spec_.grid_interval, macro_step_of(subdomains));
  }
}

void Coupling::fit_in_region(const ConvertedBody& parcel, std::vector<ConvertedBody>& made) const {
  // A parcel whose centre lies within the children's reach of a face would
  // have children beyond it, which the next exchange removes as escaped.
  // Such a cluster is shrunk by s about its centre and moved inwards by d
  // (per axis), the least shrinking for which every child's centre is in the
  // region and the cluster still lies inside the parcel's sphere (|d| <= (1 -
  // s) R), so it touches nothing the parcel did not. Velocities stay as made.
  const CellGridSpec& g = spec_.grid;
  const double* X = parcel.x;
  const double R = parcel.radius;
  double reach = 0;
  for (const ConvertedBody& b : made)
    reach = std::max(reach, std::hypot(b.x[0] - X[0], b.x[1] - X[1], b.x[2] - X[2]));
  auto shift = [&](double s, double d[3]) {
    double n2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double out_hi = X[a] + s * reach - g.hi[a], out_lo = g.lo[a] - (X[a] - s * reach);
      d[a] = (out_hi > 0 ? -out_hi : 0.0) + (out_lo > 0 ? out_lo : 0.0);
      n2 += d[a] * d[a];
    }
    return std::sqrt(n2);
  };
  double d[3];
  if (shift(1.0, d) == 0.0) return;
  double lo = 0.0, hi = 1.0;  // lo is feasible: a point at X
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (shift(mid, d) <= (1.0 - mid) * R ? lo : hi) = mid;
  }
  const double s = lo;
  shift(s, d);
  for (ConvertedBody& b : made) {
    for (int a = 0; a < 3; ++a) b.x[a] = X[a] + d[a] + s * (b.x[a] - X[a]);
    b.start_radius *= s;
  }
}

void Coupling::refine_at_start(std::vector<std::unique_ptr<Subdomain>>& subdomains, ParticleFlow& flow) {
  Subdomain& fine = *subdomains[spec_.fine];
  Subdomain& coarse = *subdomains[spec_.coarse];
  // the whole sets, the same on every rank, so that every rank makes the
  // same particles and keeps its own (as a transfer does)
  GatheredParticles all_f = ranks_->gather(fine, true);
  ParticleStore& f = *all_f;
  if (f.size() > 0) return;  // the fine level brings its own material for the region
  GatheredParticles all_c = ranks_->gather(coarse, true);
  const ParticleStore& c = *all_c;
  std::vector<std::size_t> inside;
  for (std::size_t q = 0; q < c.size(); ++q)
    if (inside_box(spec_.grid, c.x[q], c.y[q], c.z[q])) inside.push_back(q);
  if (inside.empty()) return;
  std::sort(inside.begin(), inside.end(), [&](std::size_t a, std::size_t b) { return c.id[a] < c.id[b]; });
  // a parcel still growing (refined just now from a coarser level) is refined at its own size
  std::size_t grow_to = SIZE_MAX;
  for (std::size_t a = 0; a < c.aux_names().size(); ++a)
    if (c.aux_names()[a] == "grow_to") grow_to = a;
  auto full_radius = [&](std::size_t q) {
    return grow_to != SIZE_MAX ? std::max(c.radius[q], c.aux[grow_to][q]) : c.radius[q];
  };
  fine.enable_growth();  // on every rank: the fields travel with ghosts whether or not this rank keeps a particle
  const double growth_time = spec_.growth_steps * fine.time_step();
  std::map<double, CarriedMass> carried;  // per parcel radius: a kind of fine particle
  ConversionBooks books;
  std::vector<ConvertedBody> made;
  std::unordered_map<std::uint64_t, std::pair<double, double>> growth;  // id -> radius to grow to, rate
  const std::size_t first = f.size();
  for (std::size_t q : inside) {
    ConvertedBody p;
    p.x[0] = c.x[q], p.x[1] = c.y[q], p.x[2] = c.z[q];
    p.v[0] = c.vx[q], p.v[1] = c.vy[q], p.v[2] = c.vz[q];
    p.w[0] = c.wx[q], p.w[1] = c.wy[q], p.w[2] = c.wz[q];
    p.radius = full_radius(q);
    p.mass = c.mass[q];
    refined_.parcel_units += mass_units(p.mass);
    const double rf = p.radius * spec_.alpha_ratio;
    // the particle store's own mass of a sphere (ParticleStore::add), so that the books are the store's
    const double mf = spec_.fine_density * 4.0 / 3.0 * M_PI * rf * rf * rf;
    made.clear();
    refine_parcel(p, rf, mf, carried[p.radius], rng_, made, books);
    fit_in_region(p, made);
    for (const ConvertedBody& b : made) {
      const std::uint64_t id = flow.next_id++;
      f.add(id, b.x[0], b.x[1], b.x[2], rf, spec_.fine_density, false);
      const std::size_t k = f.size() - 1;
      f.vx[k] = b.v[0], f.vy[k] = b.v[1], f.vz[k] = b.v[2];
      f.wx[k] = b.w[0], f.wy[k] = b.w[1], f.wz[k] = b.w[2];
      f.radius[k] = b.start_radius;
      growth[id] = {rf, (rf - b.start_radius) / growth_time};
      flow.count_inserted(spec_.fine, f.mass[k]);
      refined_.particle_units += mass_units(f.mass[k]);
      ++refined_.particles;
    }
    ++refined_.parcels;
  }
  for (const auto& [r, m] : carried) refined_.carried_units += m.units;
  refined_.momentum_residual = books.momentum_residual();
  auto norm = [](const double* v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  refined_.angular_in = norm(books.angular_in);
  refined_.angular_out = norm(books.angular_out);
  refined_.kinetic_in = books.kinetic_in;
  refined_.kinetic_out = books.kinetic_out;
  refined_.fluctuation = books.fluctuation;
  refined_.smallest_start = books.smallest_start;
  refined_.growth_time = growth_time;
  const auto [begin, end] = ranks_->keep_added(fine, f, first);
  ParticleStore& own = fine.particles_to_edit();
  for (std::size_t k = begin; k < end; ++k) {
    const auto& [to, rate] = growth.at(own.id[k]);
    fine.grow(k, to, rate);
  }
  if (end > begin) fine.apply_body_forces(begin, end);
  if (ranks_->rank() == 0)
    spdlog::info("{}: {} coarse parcel(s) ({:.6g} kg) lie in the region at the start: refined into {} fine particles "
                 "({:.6g} kg, {:.3g} kg carried short of a whole particle), placed at {:.3g} of their radius and "
                 "upward, growing to it over {:.4g} s ({} fine steps); kinetic energy {:.4g} J -> {:.4g} J, of "
                 "which {:.4g} J about the parcels' motion",
                 spec_.where, refined_.parcels, mass_kg(refined_.parcel_units), refined_.particles,
                 mass_kg(refined_.particle_units), mass_kg(refined_.carried_units), refined_.smallest_start,
                 growth_time, spec_.growth_steps, refined_.kinetic_in, refined_.kinetic_out, refined_.fluctuation);
}

void Coupling::exchange(double t, std::vector<std::unique_ptr<Subdomain>>& subdomains,
                        const std::vector<WallPrimitive>& walls, ParticleFlow& flow) {
  Subdomain& fine = *subdomains[spec_.fine];
  Subdomain& coarse = *subdomains[spec_.coarse];
  const double interval = t - last_t_;
  last_t_ = t;
  ++controls_;
  ++since_transfer_;
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  // the levels' whole sets of particles: on ranks, gathered (file comment);
  // what is removed from them, each rank removes from its own
  GatheredParticles all_f = ranks_->gather(fine, true);
  GatheredParticles all_c = ranks_->gather(coarse, true);
  ParticleStore& f = *all_f;
  ParticleStore& c = *all_c;
  std::vector<std::uint64_t> gone_f = remove_escaped(f, flow), gone_c;
  count_inflow(c);
  if (spec_.match_outflow) gone_c = match_outflow(c, coarse, flow);
  ranks_->removed(fine, std::move(gone_f));
  ranks_->removed(coarse, std::move(gone_c));
  auto t1 = clock::now();
  timing_.count += std::chrono::duration<double>(t1 - t0).count();
  // Due at the longest interval, or earlier once what a face counted since
  // the last transfer fills fill_target of its shell (m_dot T/(rho_p A L)).
  bool due = since_transfer_ >= spec_.transfer_controls;
  for (int face = 0; face < kFaces && !due; ++face)
    if (spec_.inflow[face]) due = faces_[face].volume_open >= spec_.fill_target * shell_volume(face);
  if (due) transfer(t, fine, f, walls, flow);
  auto t2 = clock::now();
  timing_.transfer += std::chrono::duration<double>(t2 - t1).count();
  control(t, interval, fine, f, coarse, c);
  timing_.control += std::chrono::duration<double>(clock::now() - t2).count();
}

std::vector<std::uint64_t> Coupling::remove_escaped(ParticleStore& s, ParticleFlow& flow) {
  const CellGridSpec& g = spec_.grid;
  std::vector<std::uint8_t> mark(s.size(), 0);
  std::vector<std::uint64_t> gone;
  for (std::size_t q = 0; q < s.size(); ++q) {
    const int face = face_beyond(g, s.x[q], s.y[q], s.z[q]);
    if (face < 0) continue;
    mark[q] = 1;
    gone.push_back(s.id[q]);
    faces_[face].removed += mass_units(s.mass[q]);
    ++faces_[face].n_removed;
    flow.count_removed(spec_.fine, s.id[q], s.mass[q]);
  }
  if (!gone.empty()) s.remove_marked(mark);
  return gone;
}

void Coupling::count_inflow(const ParticleStore& s) {
  const CellGridSpec& g = spec_.grid;
  // Only parcels within one cell of the region are followed: one farther
  // away cannot cross a face before the next count unless it moves faster
  // than a cell edge per control interval (15 mm per 0.3 ms, 50 m/s, in the
  // silo), so the rest of the coarse level costs one box test each.
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const double margin = fine_grid_->cell_size()[a];
    lo[a] = g.lo[a] - margin;
    hi[a] = g.hi[a] + margin;
  }
  std::unordered_map<std::uint64_t, std::array<double, 4>> now;
  now.reserve(coarse_last_.size() + 64);
  for (std::size_t q = 0; q < s.size(); ++q) {
    const std::array<double, 4> p = {s.x[q], s.y[q], s.z[q], s.mass[q]};
    if (p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2]) continue;
    now.emplace(s.id[q], p);
    const auto it = coarse_last_.find(s.id[q]);
    if (it == coarse_last_.end()) continue;  // new since the last count
    const auto& prev = it->second;
    if (inside_box(g, prev[0], prev[1], prev[2]) || !inside_box(g, p[0], p[1], p[2])) continue;
    // Entered the box: the face crossed last on the segment prev -> now.
    int face = -1;
    double last = -1;
    for (int a = 0; a < 3; ++a) {
      const double d = p[a] - prev[a];
      if (prev[a] < g.lo[a] && d > 0) {
        const double u = (g.lo[a] - prev[a]) / d;
        if (u > last) last = u, face = 2 * a;
      } else if (prev[a] > g.hi[a] && d < 0) {
        const double u = (g.hi[a] - prev[a]) / d;
        if (u > last) last = u, face = 2 * a + 1;
      }
    }
    if (face < 0 || !spec_.inflow[face] || !counted_ids_[face].insert(s.id[q]).second) continue;
    FaceBalance& fb = faces_[face];
    const double m = s.mass[q];
    fb.counted += mass_units(m);
    ++fb.parcels;
    fb.mass_open += m;
    fb.volume_open += sphere_volume(s.radius[q]);
    fb.momentum[0] += m * s.vx[q];
    fb.momentum[1] += m * s.vy[q];
    fb.momentum[2] += m * s.vz[q];
    // (alpha_c/alpha_f)^3 fine particles of the resolved size times alpha_f,
    // exactly the parcel's mass: count = m_parcel / m_fine (physics.md §5.5)
    const double r_fine = s.radius[q] * spec_.alpha_ratio;
    const double m_fine = spec_.fine_density * sphere_volume(r_fine);
    const double owed = fb.fraction + m / m_fine;
    // a ratio that is a whole number up to round-off gives that many particles
    const double whole = std::floor(owed + 1e-9);
    fb.fraction = std::max(0.0, owed - whole);
    for (double k = 0; k < whole; ++k) fb.queue.push_back(r_fine);
    fine_dmax_ = std::max(fine_dmax_, 2 * r_fine);
  }
  if (spec_.match_outflow) {
    // What the coarse parcels discharged by themselves: inside at the last
    // count, and now gone (deleted by the coarse level's own outlet; a parcel
    // cannot leave the followed margin within one interval, see above) or
    // outside through a face that is not an inflow face. A parcel that goes
    // out through an inflow face (a bounce during a fill) is the transfer's
    // business: it comes back, and that face counts it once.
    for (const auto& [id, prev] : coarse_last_) {
      if (!inside_box(g, prev[0], prev[1], prev[2])) continue;
      const auto it = now.find(id);
      if (it != now.end()) {
        const int face = face_beyond(g, it->second[0], it->second[1], it->second[2]);
        if (face < 0 || spec_.inflow[face]) continue;
      }
      outflow_.coarse += mass_units(prev[3]);
    }
  }
  coarse_last_.swap(now);
}

std::vector<std::uint64_t> Coupling::match_outflow(ParticleStore& s, const Subdomain& level, ParticleFlow& flow) {
  // the fine discharge: everything the fine level lost (its faces and its
  // deletion regions) but what left through an inflow face
  MassUnits fine_out = flow.accounts().at(spec_.fine).removed;
  for (int face = 0; face < kFaces; ++face)
    if (spec_.inflow[face]) fine_out -= faces_[face].removed;
  outflow_.fine = fine_out;
  double owed = outflow_.deficit();
  if (owed <= 0) return {};  // nothing owed: no scan (the coarse level leads or is level)
  double smallest = std::numeric_limits<double>::infinity();
  const CellGridSpec& g = spec_.grid;
  std::vector<std::pair<double, std::size_t>> inside;  // (height along -gravity, index)
  const double* gr = level.body_forces().gravity;
  const double gn = std::sqrt(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]);
  const double up[3] = {gn > 0 ? -gr[0] / gn : 0.0, gn > 0 ? -gr[1] / gn : 0.0, gn > 0 ? -gr[2] / gn : 1.0};
  for (std::size_t q = 0; q < s.size(); ++q) {
    if (!inside_box(g, s.x[q], s.y[q], s.z[q])) continue;
    inside.emplace_back(up[0] * s.x[q] + up[1] * s.y[q] + up[2] * s.z[q], q);
    smallest = std::min(smallest, s.mass[q]);
  }
  if (inside.empty() || owed < 0.5 * smallest) return {};
  std::sort(inside.begin(), inside.end());
  std::vector<std::uint8_t> mark(s.size(), 0);
  std::vector<std::uint64_t> gone;
  // lowest first, each parcel removed while at least half its mass is owed:
  // the deficit then stays within half a parcel of zero
  for (const auto& [h, q] : inside) {
    if (owed < 0.5 * s.mass[q]) break;
    mark[q] = 1;
    gone.push_back(s.id[q]);
    outflow_.sink += mass_units(s.mass[q]);
    ++outflow_.n_sink;
    owed -= s.mass[q];
    coarse_last_.erase(s.id[q]);  // booked here, not again as a parcel that vanished
    flow.count_removed(spec_.coarse, s.id[q], s.mass[q]);
  }
  if (!gone.empty()) s.remove_marked(mark);
  return gone;
}

void Coupling::transfer(double t, Subdomain& level, ParticleStore& s, const std::vector<WallPrimitive>& walls,
                        ParticleFlow& flow) {
  ++transfers_;
  since_transfer_ = 0;
  const std::size_t first = s.size();
  for (int face = 0; face < kFaces; ++face) {
    if (!spec_.inflow[face]) continue;
    FaceBalance& fb = faces_[face];
    if (fb.mass_open > 0)
      for (int a = 0; a < 3; ++a) fb.velocity[a] = fb.momentum[a] / fb.mass_open;
    // The limit of random sequential insertion (physics.md §6.2): one control
    // interval's count alone beyond 0.3 of the shell cannot be made shorter
    const double fill = fb.volume_open / shell_volume(face);
    if (fill > 0.3 && !fb.warned_fill) {
      fb.warned_fill = true;
      spdlog::warn("{}: face {} counted material for {:.2f} of its insertion shell in one transfer at t = {:.4g} s, "
                   "above the 0.3 that random insertion reaches (m_dot T / (rho_p A L) <= 0.3, docs/physics.md "
                   "§6.2): a deeper shell_depth or a shorter control_steps keeps it below",
                   spec_.where, kFaceNames[face], fill, t);
    }
    fb.mass_open = 0;
    fb.volume_open = 0;
    fb.momentum[0] = fb.momentum[1] = fb.momentum[2] = 0;
    const std::size_t before = s.size();
    insert_face(face, t, s, walls, flow.next_id);
    for (std::size_t k = before; k < s.size(); ++k) {
      fb.inserted += mass_units(s.mass[k]);
      ++fb.n_inserted;
      flow.count_inserted(spec_.fine, s.mass[k]);
    }
    const std::uint64_t backlog = fb.queue.size();
    fb.growing = backlog > fb.backlog && backlog > 0 ? fb.growing + 1 : 0;
    fb.backlog = backlog;
    if (fb.growing >= kBacklogWarnAfter && !fb.warned) {
      fb.warned = true;
      spdlog::warn("{}: face {} could not place its fine particles for {} transfers in a row (backlog {} at t = "
                   "{:.4g} s): the material behind the face is packed; the backlog waits for room (a larger "
                   "shell_depth gives it more)",
                   spec_.where, kFaceNames[face], fb.growing, backlog, t);
    }
  }
  // the new particles' first half kick sees their body forces; on ranks,
  // each rank keeps those whose id falls to it
  const auto [begin, end] = ranks_->keep_added(level, s, first);
  if (end > begin) level.apply_body_forces(begin, end);
  write_row(t, s, flow);
}

std::size_t Coupling::insert_face(int face, double t, ParticleStore& s, const std::vector<WallPrimitive>& walls,
                                  std::uint64_t& next_id) {
  FaceBalance& fb = faces_[face];
  if (fb.queue.empty()) return 0;
  const CellGridSpec& g = spec_.grid;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = g.lo[a], hi[a] = g.hi[a];
  const int ax = face / 2;
  if (face % 2 == 1) lo[ax] = hi[ax] - spec_.shell_depth;
  else hi[ax] = lo[ax] + spec_.shell_depth;
  double rmax = 0;
  for (double r : fb.queue) rmax = std::max(rmax, r);
  for (double r : s.radius) rmax = std::max(rmax, r);
  // A uniform hash of the fine particles near the shell (cell edge at least
  // 2 r_max): a candidate overlaps only particles in its own and the 26 cells
  // around. Its cells grow until there are at most 4e6 of them, counted as
  // doubles (a region 1e6 m long asked for 3e9 cells of 4 mm, found by the
  // run-time fuzzer).
  double h = 2 * rmax;
  int n[3];
  double o[3];
  for (;;) {
    double count = 1;
    for (int a = 0; a < 3; ++a) count *= std::max(1.0, std::ceil((hi[a] - lo[a] + 2 * h) / h));
    if (count <= 4.0e6) break;
    h *= std::max(1.25, std::cbrt(count / 2.0e6));
  }
  for (int a = 0; a < 3; ++a) {
    o[a] = lo[a] - h;
    n[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a] + 2 * h) / h)));
  }
  std::vector<std::vector<std::uint32_t>> bins(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  auto bin_of = [&](double x, double y, double z, int c[3]) {
    const double p[3] = {x, y, z};
    for (int a = 0; a < 3; ++a) c[a] = static_cast<int>(std::floor((p[a] - o[a]) / h));
    return c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && c[0] < n[0] && c[1] < n[1] && c[2] < n[2];
  };
  auto add_to_bins = [&](std::size_t k) {
    int c[3];
    if (bin_of(s.x[k], s.y[k], s.z[k], c))
      bins[c[0] + static_cast<std::size_t>(n[0]) * (c[1] + static_cast<std::size_t>(n[1]) * c[2])].push_back(
          static_cast<std::uint32_t>(k));
  };
  for (std::size_t k = 0; k < s.size(); ++k) add_to_bins(k);
  // `walls` hold their reference state: a moving one is placed at t first
  std::vector<WallPrimitive> at_t;
  std::vector<WallPrimitive> meshes;  // their closest triangles: WallClearance (which places them itself)
  for (const auto& w : walls) {
    if (!w.active(t)) continue;
    if (w.shape == WallPrimitive::Shape::mesh) {
      meshes.push_back(w);
    } else {
      at_t.push_back(w);
      at_t.back().place(w, t);
    }
  }
  const WallClearance mesh_clearance(meshes, t, rmax);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::size_t placed = 0;
  std::size_t tried = 0;  // attempts of this transfer: a stop request is looked at every 4096
  while (!fb.queue.empty()) {
    const double r = fb.queue.front();
    bool ok = false;
    double p[3];
    for (int attempt = 0; attempt < spec_.attempts && !ok; ++attempt) {
      if ((++tried & 4095) == 0) stop_point("the inflow of coupling '" + spec_.name + "'");
      bool room = true;
      for (int a = 0; a < 3; ++a) {
        const double a0 = lo[a] + r, a1 = hi[a] - r;
        if (a1 < a0) room = false;
        p[a] = a0 + (a1 - a0) * u01(rng_);
      }
      if (!room) break;
      ok = true;
      for (const WallPrimitive& w : at_t)
        if (w.near(p[0], p[1], p[2], r)) {
          ok = false;
          break;
        }
      ok = ok && (mesh_clearance.empty() || mesh_clearance.clear(p, r));
      if (!ok) continue;
      int c[3];
      bin_of(p[0], p[1], p[2], c);
      for (int dz = -1; dz <= 1 && ok; ++dz)
        for (int dy = -1; dy <= 1 && ok; ++dy)
          for (int dx = -1; dx <= 1 && ok; ++dx) {
            const int b[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
            if (b[0] < 0 || b[1] < 0 || b[2] < 0 || b[0] >= n[0] || b[1] >= n[1] || b[2] >= n[2]) continue;
            for (std::uint32_t k : bins[b[0] + static_cast<std::size_t>(n[0]) * (b[1] + static_cast<std::size_t>(n[1]) * b[2])]) {
              const double dxp = p[0] - s.x[k], dyp = p[1] - s.y[k], dzp = p[2] - s.z[k];
              const double rr = r + s.radius[k];
              if (dxp * dxp + dyp * dyp + dzp * dzp < rr * rr) {
                ok = false;
                break;
              }
            }
          }
    }
    if (!ok) break;  // the shell has no room for this one: it and the rest wait
    s.add(next_id++, p[0], p[1], p[2], r, spec_.fine_density, false);
    const std::size_t k = s.size() - 1;
    s.vx[k] = fb.velocity[0];
    s.vy[k] = fb.velocity[1];
    s.vz[k] = fb.velocity[2];
    add_to_bins(k);
    fb.queue.pop_front();
    ++placed;
  }
  return placed;
}

void Coupling::control(double t, double interval, Subdomain& fine_level, ParticleStore& fine, Subdomain& coarse_level,
                       ParticleStore& coarse) {
  if (!spec_.stress.enabled && !spec_.velocity.enabled) return;
  const CellFields& ff = fine_grid_->latest();
  const CellFields& fc = coarse_grid_->latest();
  const double tol = 1e-6 * interval;
  if (ff.samples == 0 || fc.samples == 0 || std::fabs(ff.time - t) > tol || std::fabs(fc.time - t) > tol)
    throw RuntimeError(spec_.where + ": the cell averages at t = " + std::to_string(t) + " s are missing (fine " +
                       std::to_string(ff.time) + " s, coarse " + std::to_string(fc.time) +
                       " s): the levels' sampling is out of step with the control interval");
  const std::size_t nc = fine_grid_->cell_count();
  auto grid_view = [&](const CellFields& f, std::vector<std::uint32_t>& count, std::vector<double>& stress) {
    count.resize(nc);
    stress.resize(6 * nc);
    for (std::size_t c = 0; c < nc; ++c) {
      count[c] = static_cast<std::uint32_t>(f.count[c]);
      // ABI: xx, yy, zz, xy, xz, yz with compression negative; CellFields: 9 entries, compression positive
      const double* sg = &f.stress[9 * c];
      const int pick[6] = {0, 4, 8, 1, 2, 5};
      for (int e = 0; e < 6; ++e) stress[6 * c + e] = -sg[pick[e]];
    }
    domel_cell_grid_v1 v{};
    v.struct_size = sizeof v;
    v.nx = static_cast<uint32_t>(spec_.grid.cells[0]);
    v.ny = static_cast<uint32_t>(spec_.grid.cells[1]);
    v.nz = static_cast<uint32_t>(spec_.grid.cells[2]);
    for (int a = 0; a < 3; ++a) {
      v.origin[a] = spec_.grid.lo[a];
      v.spacing[a] = fine_grid_->cell_size()[a];
    }
    v.n_cells = nc;
    v.count = count.data();
    v.volume_fraction = f.volume_fraction.data();
    v.mass = f.mass.data();
    v.ux = f.vx.data(), v.uy = f.vy.data(), v.uz = f.vz.data();
    v.u_min_x = f.vmin_x.data(), v.u_min_y = f.vmin_y.data(), v.u_min_z = f.vmin_z.data();
    v.u_max_x = f.vmax_x.data(), v.u_max_y = f.vmax_y.data(), v.u_max_z = f.vmax_z.data();
    v.stress = stress.data();
    return v;
  };
  domel_cell_grid_v1 gf = grid_view(ff, count_f_, stress_f_);
  domel_cell_grid_v1 gc = grid_view(fc, count_c_, stress_c_);
  struct Forces {
    std::vector<double> x, y, z;
  } force_f, force_c;
  auto particle_view = [&](ParticleStore& s, std::vector<std::uint32_t>& cell, Forces& force) {
    const std::size_t n = s.size();
    cell.resize(n);
    for (std::size_t q = 0; q < n; ++q) {
      const std::ptrdiff_t c = fine_grid_->cell_of(s.x[q], s.y[q], s.z[q]);
      cell[q] = c < 0 ? UINT32_MAX : static_cast<std::uint32_t>(c);
    }
    force.x.assign(n, 0.0), force.y.assign(n, 0.0), force.z.assign(n, 0.0);
    return particles_view(s, cell.data(), force.x.data(), force.y.data(), force.z.data());
  };
  domel_particles_v1 pf = particle_view(fine, cell_f_, force_f);
  domel_particles_v1 pc = particle_view(coarse, cell_c_, force_c);
  domel_level_v1 lf{sizeof(domel_level_v1), 0, fine_level.name().c_str(), fine_level.coarse_grain(), &gf, &pf};
  domel_level_v1 lc{sizeof(domel_level_v1), 0, coarse_level.name().c_str(), coarse_level.coarse_grain(), &gc, &pc};
  domel_level_v1* levels[2] = {&lf, &lc};
  domel_control_step_v1 step{sizeof(domel_control_step_v1), 2, t, interval, levels};
  try {
    if (spec_.stress.enabled) spec_.stress.model->control(step);
    if (spec_.velocity.enabled) spec_.velocity.model->control(step);
  } catch (const PluginError& e) {
    throw RuntimeError(spec_.where + ": a controller failed at t = " + std::to_string(t) + " s: " + e.what());
  }
  // Into the level's own particles, found in the whole set (on one process
  // the whole set is the store; on ranks the gathered set, in id order)
  auto apply = [this](Subdomain& level, const ParticleStore& whole, const Forces& f) {
    const std::vector<std::size_t> at = ranks_->where_in_gathered(level, whole, spec_.where);
    ParticleStore& s = level.store();
    for (std::size_t q = 0; q < at.size(); ++q) {
      s.ext_fx[q] += f.x[at[q]];
      s.ext_fy[q] += f.y[at[q]];
      s.ext_fz[q] += f.z[at[q]];
    }
  };
  apply(fine_level, fine, force_f);
  apply(coarse_level, coarse, force_c);
}

void Coupling::write_row(double t, const ParticleStore& s, const ParticleFlow& flow) {
  if (!balance_ || t <= last_row_t_) return;
  last_row_t_ = t;
  std::vector<double> row = {t};
  MassUnits at_faces = 0;
  for (int face = 0; face < kFaces; ++face) {
    const FaceBalance& fb = faces_[face];
    if (spec_.inflow[face]) {
      row.push_back(mass_kg(fb.counted));
      row.push_back(mass_kg(fb.inserted));
      row.push_back(mass_kg(fb.pending()));
      row.push_back(static_cast<double>(fb.backlog));
      row.push_back(fb.velocity[2]);
    }
    row.push_back(mass_kg(fb.removed));
    at_faces += fb.removed;
  }
  MassUnits present = 0;
  for (double m : s.mass) present += mass_units(m);
  row.push_back(mass_kg(flow.accounts().at(spec_.fine).removed - at_faces));
  row.push_back(mass_kg(present));
  row.push_back(static_cast<double>(s.size()));
  row.push_back(mass_kg(flow.residual(spec_.fine, s)));
  if (spec_.match_outflow) {
    row.push_back(mass_kg(outflow_.fine));
    row.push_back(mass_kg(outflow_.coarse));
    row.push_back(mass_kg(outflow_.sink));
    row.push_back(outflow_.deficit());
  }
  balance_->append(row);
}

void Coupling::write_grids(std::uint64_t tick, double t, bool final) {
  if (!vtk_fine_) return;
  if (!final && !grid_files_.due(tick)) return;
  grid_files_.advance(tick);
  if (fine_grid_->samples_pending() > 0) vtk_fine_->write(t, *fine_grid_, fine_grid_->mean_since_last_take());
  if (coarse_grid_->samples_pending() > 0)
    vtk_coarse_->write(t, *coarse_grid_, coarse_grid_->mean_since_last_take());
}

// ---- checkpoints ----------------------------------------------------------

void Coupling::fields(CheckpointFields& f) {
  const bool load = f.loading();
  const std::string& p = f.prefix();
  std::vector<MassUnits> units;
  std::vector<std::uint64_t> counts;
  std::vector<double> reals;
  std::vector<std::vector<double>> queues(kFaces);
  if (!load) {
    for (int face = 0; face < kFaces; ++face) {
      const FaceBalance& fb = faces_[face];
      units.insert(units.end(), {fb.counted, fb.inserted, fb.removed});
      counts.insert(counts.end(), {fb.parcels, fb.n_inserted, fb.n_removed, fb.backlog,
                                   static_cast<std::uint64_t>(fb.growing), fb.warned ? 1u : 0u,
                                   fb.warned_fill ? 1u : 0u});
      reals.insert(reals.end(), {fb.fraction, fb.mass_open, fb.momentum[0], fb.momentum[1], fb.momentum[2],
                                 fb.velocity[0], fb.velocity[1], fb.velocity[2], fb.volume_open});
      queues[face].assign(fb.queue.begin(), fb.queue.end());
    }
    units.insert(units.end(), {outflow_.fine, outflow_.coarse, outflow_.sink});
  }
  mass_units_field(f, "units", units);
  f("face_counts", counts);
  f("face_reals", reals);
  for (int face = 0; face < kFaces; ++face) f("face" + std::to_string(face) + "_queue", queues[face]);
  if (load) {
    if (units.size() != 3 * kFaces + 3 || counts.size() != 7 * kFaces || reals.size() != 9 * kFaces)
      f.reader().fail(p + "units", "does not hold the books of a coupling's six faces");
    for (int face = 0; face < kFaces; ++face) {
      FaceBalance& fb = faces_[face];
      const MassUnits* u = &units[3 * face];
      fb.counted = u[0], fb.inserted = u[1], fb.removed = u[2];
      const std::uint64_t* c = &counts[7 * face];
      fb.parcels = c[0], fb.n_inserted = c[1], fb.n_removed = c[2], fb.backlog = c[3];
      fb.growing = static_cast<int>(c[4]), fb.warned = c[5] != 0, fb.warned_fill = c[6] != 0;
      const double* x = &reals[9 * face];
      fb.fraction = x[0], fb.mass_open = x[1];
      for (int a = 0; a < 3; ++a) fb.momentum[a] = x[2 + a], fb.velocity[a] = x[5 + a];
      fb.volume_open = x[8];
      fb.queue.assign(queues[face].begin(), queues[face].end());
    }
    outflow_.fine = units[3 * kFaces], outflow_.coarse = units[3 * kFaces + 1], outflow_.sink = units[3 * kFaces + 2];
  }
  // the followed parcels and the counted ids, sorted (the maps' order is not
  // the state: nothing iterates them in an order that changes a result)
  std::vector<std::uint64_t> ids;
  std::vector<double> last;
  if (!load) {
    for (const auto& [id, v] : coarse_last_) ids.push_back(id);
    std::sort(ids.begin(), ids.end());
    for (std::uint64_t id : ids) {
      const auto& v = coarse_last_.at(id);
      last.insert(last.end(), v.begin(), v.end());
    }
  }
  f("followed_ids", ids);
  f("followed", last);
  if (load) {
    if (last.size() != 4 * ids.size()) f.reader().fail(p + "followed", "disagrees with followed_ids in length");
    coarse_last_.clear();
    for (std::size_t k = 0; k < ids.size(); ++k)
      coarse_last_[ids[k]] = {last[4 * k], last[4 * k + 1], last[4 * k + 2], last[4 * k + 3]};
  }
  for (int face = 0; face < kFaces; ++face) {
    std::vector<std::uint64_t> counted(counted_ids_[face].begin(), counted_ids_[face].end());
    std::sort(counted.begin(), counted.end());
    f("face" + std::to_string(face) + "_counted_ids", counted);
    if (load) counted_ids_[face] = std::unordered_set<std::uint64_t>(counted.begin(), counted.end());
  }
  // the refinement at the start, for the summary (in a checkpoint only when it made something)
  if (load ? f.reader().has(p + "refined_units") : refined_.parcels > 0) {
    std::vector<MassUnits> ru;
    std::vector<std::uint64_t> rc;
    std::vector<double> rr;
    if (!load) {
      ru = {refined_.parcel_units, refined_.particle_units, refined_.carried_units};
      rc = {refined_.parcels, refined_.particles};
      rr = {refined_.momentum_residual, refined_.angular_in, refined_.angular_out, refined_.kinetic_in,
            refined_.kinetic_out, refined_.fluctuation, refined_.smallest_start, refined_.growth_time};
    }
    mass_units_field(f, "refined_units", ru);
    f("refined_counts", rc);
    f("refined_reals", rr);
    if (load) {
      if (ru.size() != 3 || rc.size() != 2 || rr.size() != 8)
        f.reader().fail(p + "refined_units", "does not hold the books of a refinement at the start");
      refined_.parcel_units = ru[0], refined_.particle_units = ru[1], refined_.carried_units = ru[2];
      refined_.parcels = rc[0], refined_.particles = rc[1];
      refined_.momentum_residual = rr[0], refined_.angular_in = rr[1], refined_.angular_out = rr[2];
      refined_.kinetic_in = rr[3], refined_.kinetic_out = rr[4], refined_.fluctuation = rr[5];
      refined_.smallest_start = rr[6], refined_.growth_time = rr[7];
    }
  }
  std::string rng_text;
  if (!load) {
    std::ostringstream rng;
    rng << rng_;
    rng_text = rng.str();
  }
  f("rng", rng_text);
  if (load) {
    std::istringstream rng(rng_text);
    rng >> rng_;
    if (!rng) f.reader().fail(p + "rng", "does not hold the state of a 64-bit Mersenne Twister");
  }
  std::uint64_t grid_files = grid_files_.index(), balance_bytes = 0;
  f("controls", controls_);
  f("transfers", transfers_);
  f("since_transfer", since_transfer_);
  f("sink_parcels", outflow_.n_sink);
  f("grid_files", grid_files);
  f("last_t", last_t_);
  f("last_row_t", last_row_t_);
  f("fine_dmax", fine_dmax_);
  f("timing_count", timing_.count);
  f("timing_transfer", timing_.transfer);
  f("timing_control", timing_.control);
  f("timing_averaging", timing_.averaging);
  if (balance_ && !load) {
    balance_->flush();
    balance_bytes = balance_->size();
  }
  f("balance_bytes", balance_bytes);
  std::vector<double> fine_times = vtk_fine_ ? vtk_fine_->frame_times() : std::vector<double>{};
  std::vector<double> coarse_times = vtk_coarse_ ? vtk_coarse_->frame_times() : std::vector<double>{};
  f("vtk_fine_times", fine_times);
  f("vtk_coarse_times", coarse_times);
  if (load) {
    grid_files_.resume(grid_files);
    if (balance_ && balance_bytes > 0) balance_->resume(balance_bytes);
    if (vtk_fine_) vtk_fine_->resume(fine_times);
    if (vtk_coarse_) vtk_coarse_->resume(coarse_times);
  }
  // the controllers' states (ABI 2.3 save_state), in their own format
  for (const auto& [c, key] : controllers_of(spec_)) {
    if (!c->enabled) continue;
    std::string bytes;
    if (!load) {
      const auto state = c->model->save_state();
      bytes.assign(state.begin(), state.end());
    }
    f(key, bytes);
    if (!load) continue;
    try {
      c->model->load_state(std::vector<unsigned char>(bytes.begin(), bytes.end()));
    } catch (const PluginError& e) {
      f.reader().fail(p + key, std::string("holds a state the controller refuses: ") + e.what());
    }
  }
}

void Coupling::save(ArchiveWriter& w, const std::string& p) {
  fine_grid_->save(w, p + "fine_grid/");
  coarse_grid_->save(w, p + "coarse_grid/");
  save_fields(w, p, [&](CheckpointFields& f) { fields(f); });
}

void Coupling::load(const ArchiveReader& r, const std::string& p) {
  fine_grid_->load(r, p + "fine_grid/");
  coarse_grid_->load(r, p + "coarse_grid/");
  load_fields(r, p, [&](CheckpointFields& f) { fields(f); });
}

nlohmann::json Coupling::summary(const std::vector<std::unique_ptr<Subdomain>>& subdomains, const ParticleStore& all,
                                 const ParticleFlow& flow) {
  const Subdomain& fine = *subdomains[spec_.fine];
  if (balance_) {
    write_row(last_t_, all, flow);
    balance_->flush();
  }
  nlohmann::json faces = nlohmann::json::object();
  MassUnits at_faces = 0, counted = 0, inserted = 0, pending = 0;
  for (int face = 0; face < kFaces; ++face) {
    const FaceBalance& fb = faces_[face];
    at_faces += fb.removed;
    nlohmann::json j = {{"removed_kg", mass_kg(fb.removed)}, {"removed", fb.n_removed}};
    if (spec_.inflow[face]) {
      counted += fb.counted;
      inserted += fb.inserted;
      pending += fb.pending();
      j["counted_kg"] = mass_kg(fb.counted);
      j["counted_parcels"] = fb.parcels;
      j["inserted_kg"] = mass_kg(fb.inserted);
      j["inserted"] = fb.n_inserted;
      j["pending_kg"] = mass_kg(fb.pending());
      j["backlog"] = fb.backlog;
      double owed = fb.fraction * spec_.fine_density * sphere_volume(fine_dmax_ / 2);
      for (double r : fb.queue) owed += spec_.fine_density * sphere_volume(r);
      j["owed_particles"] = fb.queue.size();
      j["owed_kg"] = owed;  // the queue's own mass: pending_kg up to the parcels' round-off
    }
    faces[kFaceNames[face]] = j;
  }
  MassUnits present = 0;
  for (double m : all.mass) present += mass_units(m);
  return {{"coarse", subdomains[spec_.coarse]->name()},
          {"fine", fine.name()},
          {"control_interval_fine_steps", spec_.fine_steps},
          {"control_interval_coarse_steps", spec_.coarse_steps},
          {"control_intervals", controls_},
          {"transfers", transfers_},
          {"faces", faces},
          {"counted_kg", mass_kg(counted)},
          {"inserted_kg", mass_kg(inserted)},
          {"pending_kg", mass_kg(pending)},
          {"removed_at_faces_kg", mass_kg(at_faces)},
          {"removed_at_outlet_kg", mass_kg(flow.accounts().at(spec_.fine).removed - at_faces)},
          {"holdup_kg", mass_kg(present)},
          {"wall_time_s", {{"removal_and_counting", timing_.count},
                           {"transfers", timing_.transfer},
                           {"controllers", timing_.control},
                           {"averaging", timing_.averaging}}},
          {"match_outflow",
           spec_.match_outflow ? nlohmann::json{{"fine_lost_kg", mass_kg(outflow_.fine)},
                                                {"coarse_lost_kg", mass_kg(outflow_.coarse)},
                                                {"coarse_sink_kg", mass_kg(outflow_.sink)},
                                                {"coarse_sink_parcels", outflow_.n_sink},
                                                {"deficit_kg", outflow_.deficit()}}
                               : nlohmann::json(false)},
          {"refined_at_start",
           refined_.parcels > 0
               ? nlohmann::json{{"parcels", refined_.parcels},
                                {"parcels_kg", mass_kg(refined_.parcel_units)},
                                {"particles", refined_.particles},
                                {"particles_kg", mass_kg(refined_.particle_units)},
                                {"carried_kg", mass_kg(refined_.carried_units)},
                                {"mass_residual_units", static_cast<double>(refined_.parcel_units -
                                                                           refined_.particle_units -
                                                                           refined_.carried_units)},
                                {"momentum_residual", refined_.momentum_residual},
                                {"angular_momentum_in", refined_.angular_in},
                                {"angular_momentum_out", refined_.angular_out},
                                {"kinetic_in_J", refined_.kinetic_in},
                                {"kinetic_out_J", refined_.kinetic_out},
                                {"fluctuation_J", refined_.fluctuation},
                                {"smallest_start_radius", refined_.smallest_start},
                                {"growth_time_s", refined_.growth_time}}
               : nlohmann::json(false)},
          {"stress_control", spec_.stress.enabled ? spec_.stress.params : nlohmann::json(false)},
          {"velocity_control", spec_.velocity.enabled ? spec_.velocity.params : nlohmann::json(false)}};
}

}  // namespace domel::platform
