// SPDX-License-Identifier: MIT
// Pours, deletion regions, mass-flow planes and the exact mass balance
// (particle_flow.hpp says why they run between steps and in batches).
#include "flow/particle_flow.hpp"

#include "core/archive.hpp"
#include "core/error.hpp"
#include "geometry/region.hpp"
#include "geometry/wall_clearance.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace domel::platform {

MassUnits mass_units(double kg) {
  // whole kilograms and the rest apart, so that no llround overflows (a single
  // llround of kg * 1e18 would above 9.2 kg); the same double always gives
  // the same units, which is all the exact balance needs
  const double whole = std::floor(kg);
  return static_cast<MassUnits>(static_cast<long long>(whole)) * static_cast<MassUnits>(1000000000000000000LL) +
         static_cast<MassUnits>(std::llround((kg - whole) * 1e18));
}

double mass_kg(MassUnits u) {
  // exact enough for printing: split into a high and a low part so that the
  // conversion of a 128-bit sum does not lose the low digits of a small residual
  const MassUnits unit = static_cast<MassUnits>(1000000000000000000LL);
  const MassUnits whole = u / unit, frac = u % unit;
  return static_cast<double>(whole) + static_cast<double>(frac) * 1e-18;
}

InsertionCandidates request_insertion(const ModelInstance& model, const domel_region_v1& region, std::uint64_t seed,
                                      double alpha, const ParticleStore* present, std::size_t max_count,
                                      const PeriodicBox& box, bool components) {
  domel_insert_request_v1 req{};
  req.struct_size = sizeof(req);
  req.region = region;
  req.seed = seed;
  req.length_scale = alpha;
  // Periodic axes: the model knows nothing of images, so it also gets the
  // images, one period away, of the particles within reach of a face
  // (4 of the largest radii, at most half the period): a new particle near
  // one face then keeps clear of those near the other.
  std::vector<double> ix, iy, iz, ir;
  if (present) {
    req.n_existing = present->size();
    req.ex_x = present->x.data(); req.ex_y = present->y.data(); req.ex_z = present->z.data();
    req.ex_r = present->radius.data();
    if (box.any() && present->size() > 0) {
      double rmax = 0;
      for (double r : present->radius) rmax = std::max(rmax, r);
      const std::vector<double>* pos[3] = {&present->x, &present->y, &present->z};
      ix = present->x; iy = present->y; iz = present->z; ir = present->radius;
      for (const auto& sh : box.image_shifts())
        for (std::size_t k = 0; k < present->size(); ++k) {
          bool near = true;
          double p[3];
          for (int a = 0; a < 3 && near; ++a) {
            const double v = (*pos[a])[k];
            p[a] = v + sh[a] * (box.axis[a] ? box.length(a) : 0.0);
            if (sh[a] == 0) continue;
            const double reach = std::min(0.5 * box.length(a), 4.0 * rmax);
            near = sh[a] > 0 ? v < box.lo[a] + reach : v >= box.hi[a] - reach;
          }
          if (near) {
            ix.push_back(p[0]); iy.push_back(p[1]); iz.push_back(p[2]); ir.push_back(present->radius[k]);
          }
        }
      req.n_existing = ix.size();
      req.ex_x = ix.data(); req.ex_y = iy.data(); req.ex_z = iz.data(); req.ex_r = ir.data();
    }
  }
  req.max_count = max_count;
  InsertionCandidates c;
  model.insert(req, c.x, c.y, c.z, c.r, components ? &c.component : nullptr);
  // a model of ABI 2.2 does not know max_count: the host refuses afterwards
  if (max_count != 0 && c.size() > max_count)
    throw PluginError(model.context() + ": the insertion placed " + std::to_string(c.size()) +
                      " particles, more than the " + std::to_string(max_count) +
                      " the run accepts (run.max_particles): check the units of the region and of the diameters, "
                      "or raise run.max_particles");
  return c;
}

double FlowSeries::slope(double t0, double t1) const {
  double st = 0, sv = 0, stt = 0, stv = 0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < t0 - 1e-12 || t[k] > t1 + 1e-12) continue;
    st += t[k]; sv += value[k]; stt += t[k] * t[k]; stv += t[k] * value[k];
    ++n;
  }
  if (n < 3) return std::nan("");
  const double den = n * stt - st * st;
  return den > 0 ? (n * stv - st * sv) / den : std::nan("");
}

std::vector<std::vector<char>> ParticleFlow::from_every_rank(const std::vector<char>& mine) const {
  return ranks_->all_gather(mine);
}

std::pair<MassUnits, std::uint64_t> ParticleFlow::present(const Subdomain& sd) const {
  const ParticleStore& s = sd.store();
  MassUnits mass = 0;
  for (std::size_t q = 0; q < sd.owned(); ++q) mass += mass_units(s.mass[q]);
  std::uint64_t n = sd.owned();
  std::vector<char> mine(sizeof(MassUnits) + sizeof(n));
  std::memcpy(mine.data(), &mass, sizeof(MassUnits));
  std::memcpy(mine.data() + sizeof(MassUnits), &n, sizeof(n));
  mass = 0;
  n = 0;
  for (const auto& b : ranks_->all_gather(mine)) {  // integers: exact in any order
    MassUnits m = 0;
    std::uint64_t c = 0;
    std::memcpy(&m, b.data(), sizeof(MassUnits));
    std::memcpy(&c, b.data() + sizeof(MassUnits), sizeof(c));
    mass += m;
    n += c;
  }
  return {mass, n};
}

void ParticleFlow::start(std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  accounts_.assign(subdomains.size(), MassAccount{});
  for (std::size_t k = 0; k < subdomains.size(); ++k) {
    const auto [mass, n] = present(*subdomains[k]);
    accounts_[k].inserted += mass;
    accounts_[k].n_inserted = n;
  }
  for (auto& pl : planes) pl.side.assign(subdomains.size(), {});
  check_planes(subdomains);
  const double macro = macro_step_of(subdomains);
  checks_ = Cadence::in_time(deletions.empty() ? 0.0 : deletion_interval, deletion_interval, macro);
  for (auto& p : pours) p.schedule = Cadence::in_time(p.interval, p.start, macro);
}

void ParticleFlow::update(const MacroStep& step, std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  // the ghosts' contact counts go home before any rank edits its particles
  // (an edit drops the ghosts; the outputs' gathers later in this macro
  // step then find the counts collected). Collective, so on every rank.
  for (auto& sd : subdomains) sd->collect_contact_counts();
  const double t = step.t;
  if (checks_.take(step.index)) {
    check_planes(subdomains);  // count crossings before the crossed particles are deleted
    delete_particles(subdomains);
  }
  for (auto& p : pours) {
    if (!p.schedule.due(step.index) || t >= p.end || p.inserted_mass >= p.total_mass) continue;
    pour(p, t, *subdomains[p.subdomain]);
    p.schedule.advance(step.index);
  }
}

void ParticleFlow::setup(RunContext& ctx) {
  if (!ctx.restart) start(ctx.subdomains);  // a restart's restore() started it
}

std::size_t drop_wall_overlaps(InsertionCandidates& c, const std::vector<WallPrimitive>& walls, double t) {
  if (walls.empty() || c.size() == 0) return 0;
  double r_max = 0;
  for (double r : c.r) r_max = std::max(r_max, r);
  const WallClearance clearance(walls, t, r_max);
  std::size_t kept = 0;
  for (std::size_t q = 0; q < c.size(); ++q) {
    const double p[3] = {c.x[q], c.y[q], c.z[q]};
    if (clearance.overlap(p, c.r[q]) > 1e-9 * c.r[q]) continue;  // more than round-off (a lattice touching a wall)
    c.x[kept] = c.x[q]; c.y[kept] = c.y[q]; c.z[kept] = c.z[q]; c.r[kept] = c.r[q];
    if (!c.component.empty()) c.component[kept] = c.component[q];
    ++kept;
  }
  const std::size_t dropped = c.size() - kept;
  c.x.resize(kept); c.y.resize(kept); c.z.resize(kept); c.r.resize(kept);
  if (!c.component.empty()) c.component.resize(kept);
  return dropped;
}

void ParticleFlow::finish(RunContext& ctx, nlohmann::json& out) {
  if (empty()) return;
  check_planes(ctx.subdomains);
  const nlohmann::json books = summary(ctx.subdomains);
  for (auto& [key, value] : books.items()) out[key] = value;
}

void ParticleFlow::probe_columns(std::vector<std::string>& names) const {
  for (const auto& c : columns()) names.push_back(c);
}

void ParticleFlow::probe_values(RunContext& ctx, double t, std::vector<double>& row) {
  check_planes(ctx.subdomains);
  append_row(t, row);
}

void ParticleFlow::pour(Pour& p, double t, Subdomain& sd) {
  // Cumulative target: each event inserts the mass of the interval it opens,
  // so the mean rate is exact and a shortfall (a full region) is made up later.
  const double elapsed = std::min(t, p.end) - p.start;
  const double target = std::min(p.total_mass, p.mass_rate * std::min(elapsed + p.interval, p.end - p.start));
  ++p.events;
  if (p.inserted_mass >= target) return;
  // the particles to keep clear of: all of them, on every rank when spread
  const GatheredParticles everywhere = ranks_->gather(sd, true);
  const ParticleStore& present = *everywhere;
  // one seed per event: the pour's seed and the event count mixed with the
  // multiplier and increment of Knuth's MMIX linear congruential generator
  const std::uint64_t seed = p.seed * 6364136223846793005ull + p.events * 1442695040888963407ull;
  InsertionCandidates c;
  try {
    c = request_insertion(*p.model, p.region, seed, p.alpha, &present, max_particles, sd.periodic(),
                          p.materials.mixture());
  } catch (const PluginError& e) {
    throw RuntimeError(p.where + ": the pour's insertion failed at t = " + std::to_string(t) + " s: " + e.what());
  }
  // no particle placed in a wall: a shortfall this leaves is made up later, as a full region's
  if (!p.fixed) drop_wall_overlaps(c, sd.reference_walls(), t);
  // The candidates are independent random draws in random order, so taking
  // them in order until the mass target is met keeps the size distribution.
  // Spread over ranks, every rank takes the same ones and keeps each new
  // particle by id (the next exchange moves it to its owner).
  ParticleStore* st = nullptr;  // the store to add to, once a particle is kept here
  ParticleStore elsewhere;      // a particle kept by another rank: its mass, computed alike
  std::size_t taken = 0, kept = 0;
  for (std::size_t q = 0; q < c.size() && p.inserted_mass < target; ++q) {
    const std::uint64_t id = next_id++;
    const bool mine = sd.keeps(id);
    if (mine && !st) st = &sd.particles_to_edit();
    ParticleStore& into = mine ? *st : elsewhere;
    into.add(id, c.x[q], c.y[q], c.z[q], c.r[q], p.materials.density_of(c, q), p.fixed, p.materials.material_of(c, q));
    const std::size_t k = into.size() - 1;
    into.vx[k] = p.velocity[0]; into.vy[k] = p.velocity[1]; into.vz[k] = p.velocity[2];
    p.inserted_mass += into.mass[k];
    count_inserted(p.subdomain, into.mass[k]);
    ++taken;
    kept += mine ? 1 : 0;
  }
  if (st) sd.apply_body_forces(st->size() - kept, st->size());  // their first half kick sees their body forces
  p.inserted += taken;
  const double deficit = target - p.inserted_mass;
  if (deficit > 0 && p.mass_rate * p.interval > 0) {
    p.shortfall = std::max(p.shortfall, deficit);
    if (!p.warned && deficit > 0.5 * p.mass_rate * p.interval) {
      p.warned = true;
      spdlog::warn("{}: the pour region held only {} free places at t = {:.4g} s; {:.3g} kg behind the rate of "
                   "{:.3g} kg/s (enlarge the region, raise the insertion's volume_fraction or shorten the interval)",
                   p.where, c.size(), t, deficit, p.mass_rate);
    }
  }
}

void ParticleFlow::count_inserted(std::size_t k, double mass) {
  accounts_.at(k).inserted += mass_units(mass);
  ++accounts_[k].n_inserted;
}

void ParticleFlow::count_removed(std::size_t k, std::uint64_t id, double mass) {
  accounts_.at(k).removed += mass_units(mass);
  ++accounts_[k].n_removed;
  for (auto& pl : planes)
    if (k < pl.side.size()) pl.side[k].erase(id);
}

void ParticleFlow::check_planes(std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  if (planes.empty()) return;
  // spread over ranks, every rank watches all particles (gathered in id
  // order), so the sides and the counts are the same on every rank and a
  // particle that changed rank between two checks is still followed
  std::vector<GatheredParticles> everywhere(subdomains.size());
  for (std::size_t k = 0; k < everywhere.size(); ++k) everywhere[k] = ranks_->gather(*subdomains[k], true);
  for (auto& pl : planes) {
    if (pl.side.size() != subdomains.size()) pl.side.assign(subdomains.size(), {});
    for (std::size_t k = 0; k < subdomains.size(); ++k) {
      if (pl.subdomain != kAllSubdomains && pl.subdomain != k) continue;
      const ParticleStore& s = *everywhere[k];
      auto& side = pl.side[k];
      for (std::size_t q = 0; q < s.size(); ++q) {
        const double d = (s.x[q] - pl.p[0]) * pl.n[0] + (s.y[q] - pl.p[1]) * pl.n[1] + (s.z[q] - pl.p[2]) * pl.n[2];
        const signed char now = d >= 0 ? 1 : -1;
        auto [it, fresh] = side.try_emplace(s.id[q], now);
        if (fresh || it->second == now) continue;
        // crossed since the last check: along n (from - to +) counts positive
        pl.mass += now > 0 ? s.mass[q] : -s.mass[q];
        pl.count += now > 0 ? 1 : -1;
        it->second = now;
      }
    }
  }
}

void ParticleFlow::delete_particles(std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  // Each rank removes its own particles and lists them (subdomain, region,
  // id, mass); then every rank books every rank's lists, in rank order, so
  // the books are the same everywhere (one process: its own list, in order).
  struct Removed {
    std::uint64_t subdomain, region, id;
    double mass;
  };
  std::vector<Removed> removed;
  std::vector<std::uint8_t> mark;
  for (std::size_t k = 0; k < subdomains.size(); ++k) {
    const ParticleStore& s = subdomains[k]->store();
    const std::size_t n = subdomains[k]->owned();
    mark.assign(n, 0);
    bool any = false;
    for (std::size_t q = 0; q < n; ++q) {
      for (std::size_t r = 0; r < deletions.size(); ++r) {
        const DeletionRegion& d = deletions[r];
        if ((d.subdomain != kAllSubdomains && d.subdomain != k) || !region_contains(d.region, s.x[q], s.y[q], s.z[q]))
          continue;
        mark[q] = 1;
        any = true;
        removed.push_back({k, r, s.id[q], s.mass[q]});
        break;  // a particle in two regions is counted by the first
      }
    }
    if (any) subdomains[k]->particles_to_edit().remove_marked(mark);
  }
  std::vector<char> mine(removed.size() * sizeof(Removed));
  if (!removed.empty()) std::memcpy(mine.data(), removed.data(), mine.size());
  for (const auto& b : from_every_rank(mine))
    for (std::size_t at = 0; at + sizeof(Removed) <= b.size(); at += sizeof(Removed)) {
      Removed e;
      std::memcpy(&e, b.data() + at, sizeof(Removed));
      DeletionRegion& d = deletions.at(e.region);
      ++d.removed;
      d.removed_mass += e.mass;
      count_removed(e.subdomain, e.id, e.mass);
    }
}

std::vector<std::string> ParticleFlow::columns() const {
  std::vector<std::string> c;
  for (const auto& d : deletions) {
    c.push_back(d.name + ".removed_kg");
    c.push_back(d.name + ".rate_kg_s");
  }
  for (const auto& pl : planes) {
    c.push_back(pl.name + ".mass_kg");
    c.push_back(pl.name + ".rate_kg_s");
  }
  return c;
}

void ParticleFlow::append_row(double t, std::vector<double>& row) {
  std::vector<double> now;
  for (auto& d : deletions) {
    d.series.t.push_back(t);
    d.series.value.push_back(d.removed_mass);
    now.push_back(d.removed_mass);
  }
  for (auto& pl : planes) {
    pl.series.t.push_back(t);
    pl.series.value.push_back(pl.mass);
    now.push_back(pl.mass);
  }
  const bool first = std::isnan(last_row_t_) || t <= last_row_t_;
  for (std::size_t k = 0; k < now.size(); ++k) {
    row.push_back(now[k]);
    row.push_back(first ? 0.0 : (now[k] - last_row_[k]) / (t - last_row_t_));
  }
  last_row_ = now;
  last_row_t_ = t;
}

MassUnits ParticleFlow::residual(std::size_t k, const ParticleStore& s) const {
  MassUnits present = 0;
  for (std::size_t q = 0; q < s.size(); ++q) present += mass_units(s.mass[q]);
  return accounts_.at(k).inserted - present - accounts_.at(k).removed;
}

nlohmann::json ParticleFlow::summary(const std::vector<std::unique_ptr<Subdomain>>& subdomains) const {
  nlohmann::json j = nlohmann::json::object();
  nlohmann::json balance = nlohmann::json::object();
  for (std::size_t k = 0; k < subdomains.size() && k < accounts_.size(); ++k) {
    const auto [present_mass, present_count] = present(*subdomains[k]);
    const MassUnits present = present_mass;
    const MassAccount& a = accounts_[k];
    const MassUnits res = a.inserted - present - a.removed;
    const long long res_units = static_cast<long long>(res);
    balance[subdomains[k]->name()] = {{"inserted_kg", mass_kg(a.inserted)},
                                      {"present_kg", mass_kg(present)},
                                      {"removed_kg", mass_kg(a.removed)},
                                      {"residual_kg", mass_kg(res)},
                                      {"residual_units_1e-18kg", res_units},
                                      {"exact", res == 0},
                                      {"inserted", a.n_inserted},
                                      {"present", present_count},
                                      {"removed", a.n_removed}};
  }
  j["mass_balance"] = balance;
  if (!pours.empty()) {
    nlohmann::json ps = nlohmann::json::array();
    for (const auto& p : pours)
      ps.push_back({{"block", p.where},
                    {"subdomain", subdomains[p.subdomain]->name()},
                    {"events", p.events},
                    {"inserted", p.inserted},
                    {"inserted_kg", p.inserted_mass},
                    {"mass_rate_kg_s", p.mass_rate},
                    {"largest_shortfall_kg", p.shortfall}});
    j["pours"] = ps;
  }
  auto rate_json = [](const FlowSeries& s, const double w[2]) {
    nlohmann::json r = nlohmann::json::object();
    if (!std::isnan(w[0])) {
      const double slope = s.slope(w[0], w[1]);
      r = {{"window_s", {w[0], w[1]}}, {"rate_kg_s", std::isnan(slope) ? nlohmann::json(nullptr) : nlohmann::json(slope)}};
    }
    return r;
  };
  if (!deletions.empty()) {
    nlohmann::json ds = nlohmann::json::object();
    for (const auto& d : deletions)
      ds[d.name] = {{"removed", d.removed}, {"removed_kg", d.removed_mass}, {"steady", rate_json(d.series, d.rate_window)}};
    j["deletion_regions"] = ds;
  }
  if (!planes.empty()) {
    nlohmann::json ps = nlohmann::json::object();
    for (const auto& pl : planes)
      ps[pl.name] = {{"net_count", pl.count}, {"net_kg", pl.mass}, {"steady", rate_json(pl.series, pl.rate_window)}};
    j["mass_flow"] = ps;
  }
  return j;
}

}  // namespace domel::platform

// ---- checkpoints ----------------------------------------------------------

namespace domel::platform {

void mass_units_field(CheckpointFields& f, const std::string& key, std::vector<MassUnits>& v) {
  std::vector<std::uint64_t> halves;
  for (MassUnits u : v) {
    const auto bits = static_cast<unsigned __int128>(u);
    halves.push_back(static_cast<std::uint64_t>(bits));
    halves.push_back(static_cast<std::uint64_t>(bits >> 64));
  }
  f(key, halves);
  if (!f.loading()) return;
  if (halves.size() % 2) f.reader().fail(f.prefix() + key, "does not hold pairs of 64-bit halves");
  v.clear();
  for (std::size_t k = 0; k < halves.size(); k += 2)
    v.push_back(static_cast<MassUnits>((static_cast<unsigned __int128>(halves[k + 1]) << 64) | halves[k]));
}

namespace {

void series_fields(CheckpointFields& f, const std::string& at, FlowSeries& s) {
  f(at + "series_t", s.t);
  f(at + "series_value", s.value);
  if (f.loading() && s.t.size() != s.value.size())
    f.reader().fail(f.prefix() + at + "series_t", "disagrees with series_value in length");
}

}  // namespace

void ParticleFlow::fields(CheckpointFields& f, std::size_t subdomains) {
  const bool load = f.loading();
  const std::string& p = f.prefix();
  auto same_count = [&](const std::string& key, std::uint64_t there, std::size_t here, const char* what) {
    if (load && there != here)
      f.reader().fail(p + key, "holds " + std::to_string(there) + " " + what + "; the scenario has " +
                                   std::to_string(here) + " (a restart keeps the particle flow of the checkpointed run)");
  };
  f("next_id", next_id);
  std::vector<MassUnits> units;
  std::vector<std::uint64_t> counts;
  for (const MassAccount& a : accounts_) {
    units.insert(units.end(), {a.inserted, a.removed});
    counts.insert(counts.end(), {a.n_inserted, a.n_removed});
  }
  mass_units_field(f, "accounts_units", units);
  f("accounts_counts", counts);
  if (load) {
    if (units.size() != 2 * accounts_.size() || counts.size() != 2 * accounts_.size())
      f.reader().fail(p + "accounts_units", "holds the books of another number of subdomains");
    for (std::size_t k = 0; k < accounts_.size(); ++k)
      accounts_[k] = MassAccount{units[2 * k], units[2 * k + 1], counts[2 * k], counts[2 * k + 1]};
  }
  std::uint64_t checks = checks_.index();
  f("checks", checks);
  if (load) checks_.resume(checks);
  f("last_row", last_row_t_);
  f("last_row_values", last_row_);
  std::uint64_t n = pours.size();
  f("pours", n);
  same_count("pours", n, pours.size(), "pours");
  for (std::size_t k = 0; k < pours.size(); ++k) {
    Pour& q = pours[k];
    const std::string at = "pour" + std::to_string(k) + "/";
    std::uint64_t events = q.schedule.index();
    f(at + "schedule", events);
    f(at + "events", q.events);
    f(at + "inserted", q.inserted);
    f(at + "warned", q.warned);
    f(at + "inserted_mass", q.inserted_mass);
    f(at + "shortfall", q.shortfall);
    if (load) q.schedule.resume(events);
  }
  n = deletions.size();
  f("deletions", n);
  same_count("deletions", n, deletions.size(), "deletion regions");
  for (std::size_t k = 0; k < deletions.size(); ++k) {
    DeletionRegion& d = deletions[k];
    const std::string at = "deletion" + std::to_string(k) + "/";
    f(at + "removed", d.removed);
    f(at + "removed_mass", d.removed_mass);
    series_fields(f, at, d.series);
  }
  n = planes.size();
  f("planes", n);
  same_count("planes", n, planes.size(), "mass-flow planes");
  for (std::size_t k = 0; k < planes.size(); ++k) {
    MassFlowPlane& pl = planes[k];
    const std::string at = "plane" + std::to_string(k) + "/";
    f(at + "mass", pl.mass);
    f(at + "count", pl.count);
    series_fields(f, at, pl.series);
    std::uint64_t sides = pl.side.size();
    f(at + "sides", sides);
    same_count(at + "sides", sides, subdomains, "subdomains");
    if (load) pl.side.assign(subdomains, {});
    for (std::size_t s = 0; s < pl.side.size(); ++s) {
      // sorted by id: the map's order is not the state
      std::vector<std::uint64_t> ids;
      std::vector<std::uint8_t> positive;
      if (!load) {
        std::vector<std::pair<std::uint64_t, signed char>> sorted(pl.side[s].begin(), pl.side[s].end());
        std::sort(sorted.begin(), sorted.end());
        for (const auto& [id, side] : sorted) {
          ids.push_back(id);
          positive.push_back(side > 0 ? 1 : 0);
        }
      }
      const std::string key = at + "side" + std::to_string(s);
      f(key + "_ids", ids);
      f(key + "_positive", positive);
      if (!load) continue;
      if (ids.size() != positive.size()) f.reader().fail(p + key + "_ids", "disagrees with its sides");
      pl.side[s].reserve(ids.size());
      for (std::size_t e = 0; e < ids.size(); ++e) pl.side[s].emplace(ids[e], positive[e] ? 1 : -1);
    }
  }
}

void ParticleFlow::save(ArchiveWriter& w, const std::string& p) {
  save_fields(w, p, [&](CheckpointFields& f) { fields(f, accounts_.size()); });
}

void ParticleFlow::restore(const ArchiveReader& r, const std::string& p,
                           std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  start(subdomains);  // the schedules and sizes; every value is then replaced by the checkpoint's
  load_fields(r, p, [&](CheckpointFields& f) { fields(f, subdomains.size()); });
}

}  // namespace domel::platform
