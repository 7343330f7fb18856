// SPDX-License-Identifier: MIT
// The builders of the couplings between levels, the checks of the space the
// levels share, and the scene's box for drawing walls (build.hpp).
#include "scenario/build.hpp"

#include "coupling/coupling.hpp"
#include "geometry/region.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace domel::platform::scenario_detail {

/// The parent map of /couplings (fine -> coarse), read before the subdomains
/// are built: a coupled fine level takes its particle size from its parent.
void scan_couplings(Build& b) {
  if (!b.doc.contains("couplings")) return;
  const json& cs = b.doc["couplings"];
  for (std::size_t c = 0; c < cs.size(); ++c) {
    const std::string fine = cs[c]["fine"].get<std::string>();
    if (b.parent.count(fine) != 0) {
      b.ck.add(idx("/couplings", c) + "/fine", "subdomain '" + fine + "' is already the fine level of " +
                                                   idx("/couplings", b.parent[fine].second) +
                                                   "; a level has one parent (nest a third level under it instead)");
      continue;
    }
    b.parent[fine] = {cs[c]["coarse"].get<std::string>(), c};
  }
}

/// True when `level` is a finer level of `ancestor` through the parent map
/// of /couplings (a loop in the map ends the walk).
bool descends_from(const Build& b, const std::string& level, const std::string& ancestor) {
  std::string up = level;
  for (std::size_t hops = 0; hops <= b.parent.size(); ++hops) {
    const auto it = b.parent.find(up);
    if (it == b.parent.end()) return false;
    up = it->second.first;
    if (up == ancestor) return true;
  }
  return false;
}

bool walls_and_regions_bounds(Build& b, double lo[3], double hi[3], bool all);

/// Bounding box of a top-level domain: when the walls enclose a finite
/// region (a cylinder, a cone or a mesh), their bounding box together with
/// the pour, insertion and deletion regions (particles fall out of an outlet
/// into a deletion region). False with planes alone: the domain is unbounded.
bool domain_bounds(Build& b, double lo[3], double hi[3]) {
  bool enclosed = false;
  for (const auto& w : b.sim.walls)
    enclosed = enclosed || w.shape == WallPrimitive::Shape::cylinder_inside ||
               w.shape == WallPrimitive::Shape::cone_inside || w.shape == WallPrimitive::Shape::mesh;
  if (!enclosed) return false;
  return walls_and_regions_bounds(b, lo, hi, false);
}

/// Where a top-level level's particle centres can be: the box of
/// domain_bounds() when cylinders, cones or meshes enclose the scene (else
/// all space), cut down by every axis-aligned plane that stands from the
/// start to the end of the run (a box's faces, a floor): nothing stays
/// behind a plane. Unbounded sides are infinite. False when nothing bounds
/// it at all.
bool reachable_box(Build& b, double lo[3], double hi[3]) {
  bool any = domain_bounds(b, lo, hi);
  if (!any)
    for (int a = 0; a < 3; ++a) lo[a] = -HUGE_VAL, hi[a] = HUGE_VAL;
  for (const auto& w : b.sim.walls) {
    if (w.shape != WallPrimitive::Shape::plane || w.moving || std::isfinite(w.remove_at) || w.active_from > 0)
      continue;
    for (int a = 0; a < 3; ++a) {
      if (std::fabs(w.n[a]) < 1.0 - 1e-12) continue;
      if (w.n[a] > 0) lo[a] = std::max(lo[a], w.p[a]);
      else hi[a] = std::min(hi[a], w.p[a]);
      any = true;
    }
  }
  return any;
}

/// The box of the enclosing walls (mantles, meshes) and of every region
/// (deletion, pour, insertion); with `all`, also of every other finite wall
/// (disks, a box's faces, a container's bottom) and a plane's point.
bool walls_and_regions_bounds(Build& b, double lo[3], double hi[3], bool all) {
  bool any = false;
  auto grow = [&](const double a[3], const double z[3]) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = any ? std::min(lo[k], a[k]) : a[k];
      hi[k] = any ? std::max(hi[k], z[k]) : z[k];
    }
    any = true;
  };
  auto grow_region = [&](const domel_region_v1& r) {
    double a[3], z[3];
    region_box(r, a, z);
    grow(a, z);
  };
  for (const auto& w : b.sim.walls) {
    double a[3], z[3];
    if (w.shape == WallPrimitive::Shape::cylinder_inside || w.shape == WallPrimitive::Shape::cone_inside) {
      const double r = std::max(w.radius, w.radius_hi);
      for (int k = 0; k < 3; ++k) {
        a[k] = k == w.axis ? w.lo : w.c[k] - r;
        z[k] = k == w.axis ? w.hi : w.c[k] + r;
      }
      grow(a, z);
    } else if (w.shape == WallPrimitive::Shape::mesh && w.verts.size() >= 3) {
      for (int k = 0; k < 3; ++k) a[k] = z[k] = w.verts[k];
      for (std::size_t v = 0; v + 2 < w.verts.size(); v += 3)
        for (int k = 0; k < 3; ++k) a[k] = std::min(a[k], w.verts[v + k]), z[k] = std::max(z[k], w.verts[v + k]);
      grow(a, z);
    } else if (all && w.shape == WallPrimitive::Shape::plane && w.draw_in_box) {
      grow(w.draw_lo, w.draw_hi);
    } else if (all) {  // a plane's point; a disk or a container's bottom as far as it is drawn
      const double r = w.shape == WallPrimitive::Shape::annulus && std::isfinite(w.r_outer) ? w.r_outer
                                                                                             : w.draw_radius;
      for (int k = 0; k < 3; ++k) {
        a[k] = w.p[k] - r;
        z[k] = w.p[k] + r;
      }
      grow(a, z);
    }
  }
  if (b.doc.contains("deletion_regions"))
    for (const auto& d : b.doc["deletion_regions"]) grow_region(make_region(d["region"]));
  for (const auto& p : b.sim.flow.pours) grow_region(p.region);
  for (const auto& sd : b.doc["subdomains"])
    if (sd.contains("insert"))
      for (const auto& ins : sd["insert"])
        if (ins.contains("region")) grow_region(make_region(ins["region"]));
  return any;
}

/// Subdomains never touch each other's particles: two that share space
/// without a coupling between them (directly or through other levels) are
/// most likely a mixture written as two subdomains, whose particles pass
/// through each other. Warned, not refused: overlaid independent runs (a
/// parameter study in one file) are legitimate.
void warn_shared_space(Build& b) {
  const auto& sds = b.sim.subdomains;
  const std::size_t n = sds.size();
  // coupled families (union-find over the couplings' levels)
  std::vector<std::size_t> root(n);
  for (std::size_t k = 0; k < n; ++k) root[k] = k;
  auto find = [&](std::size_t k) {
    while (root[k] != k) k = root[k] = root[root[k]];
    return k;
  };
  auto index_of = [&](const json& name) {
    for (std::size_t k = 0; k < n; ++k)
      if (sds[k]->name() == name.get<std::string>()) return k;
    return n;
  };
  if (b.doc.contains("couplings"))
    for (const auto& c : b.doc["couplings"]) {
      const std::size_t x = index_of(c["coarse"]), y = index_of(c["fine"]);
      if (x < n && y < n) root[find(x)] = find(y);
    }
  // each subdomain's box: its particles at the start and its pour regions
  std::vector<std::array<double, 6>> box(n);
  std::vector<bool> any(n, false);
  auto grow = [&](std::size_t k, const double lo[3], const double hi[3]) {
    for (int a = 0; a < 3; ++a) {
      box[k][a] = any[k] ? std::min(box[k][a], lo[a]) : lo[a];
      box[k][3 + a] = any[k] ? std::max(box[k][3 + a], hi[a]) : hi[a];
    }
    any[k] = true;
  };
  for (std::size_t k = 0; k < n; ++k) {
    const ParticleStore& s = sds[k]->store();
    for (std::size_t q = 0; q < s.size(); ++q) {
      const double lo[3] = {s.x[q] - s.radius[q], s.y[q] - s.radius[q], s.z[q] - s.radius[q]};
      const double hi[3] = {s.x[q] + s.radius[q], s.y[q] + s.radius[q], s.z[q] + s.radius[q]};
      grow(k, lo, hi);
    }
  }
  for (const auto& p : b.sim.flow.pours) {
    double lo[3], hi[3];
    region_box(p.region, lo, hi);
    if (p.subdomain < n) grow(p.subdomain, lo, hi);
  }
  for (std::size_t x = 0; x < n; ++x)
    for (std::size_t y = x + 1; y < n; ++y) {
      if (!any[x] || !any[y] || find(x) == find(y)) continue;
      bool overlap = true;
      for (int a = 0; a < 3; ++a)
        overlap = overlap && box[x][a] < box[y][3 + a] && box[y][a] < box[x][3 + a];
      if (overlap)
        spdlog::warn("subdomains '{}' and '{}' share space but no coupling joins them: subdomains never touch, so "
                     "their particles pass through each other; for a mixture use several materials in one subdomain "
                     "(an insertion's \"material\", docs/getting-started.md, \"Mixtures\")",
                     sds[x]->name(), sds[y]->name());
    }
}

/// The scene's box for drawing walls (output.wall_surfaces): the walls, the
/// regions and the particles at the start, padded by 5 % of its diagonal (a
/// plane alone: 1 m about its point).
void scene_bounds(Build& b) {
  Simulation& sim = b.sim;
  double lo[3], hi[3];
  bool any = walls_and_regions_bounds(b, lo, hi, true);
  for (const auto& sd : sim.subdomains) {
    const ParticleStore& s = sd->store();
    for (std::size_t k = 0; k < s.size(); ++k) {
      const double x[3] = {s.x[k], s.y[k], s.z[k]};
      for (int a = 0; a < 3; ++a) {
        lo[a] = any ? std::min(lo[a], x[a] - s.radius[k]) : x[a] - s.radius[k];
        hi[a] = any ? std::max(hi[a], x[a] + s.radius[k]) : x[a] + s.radius[k];
      }
      any = true;
    }
  }
  if (!any)
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = 0.0;
  double diag = 0;
  for (int a = 0; a < 3; ++a) diag += (hi[a] - lo[a]) * (hi[a] - lo[a]);
  const double pad = diag > 0 ? 0.05 * std::sqrt(diag) : 0.5;
  for (int a = 0; a < 3; ++a) {
    b.out.scene_lo[a] = lo[a] - pad;
    b.out.scene_hi[a] = hi[a] + pad;
  }
}

/// /couplings: levels, region and cells, faces, timing, controllers.
void build_couplings(Build& b) {
  if (!b.doc.contains("couplings")) return;
  const json& cs = b.doc["couplings"];
  Simulation& sim = b.sim;
  const double macro = sim.macro_step();
  std::vector<std::string> names;
  for (const auto& sd : sim.subdomains) names.push_back(sd->name());
  std::vector<CouplingSpec> specs;
  std::vector<int> requested;  // control_steps of each
  std::vector<const json*> blocks;
  for (std::size_t c = 0; c < cs.size(); ++c) {
    const json& cj = cs[c];
    const std::string base = idx("/couplings", c);
    const std::size_t before = b.ck.diags.size();
    CouplingSpec s;
    s.name = cj["name"].get<std::string>();
    s.where = base;
    for (std::size_t h = 0; h < c; ++h)
      if (cs[h]["name"] == cj["name"]) b.ck.add(base + "/name", "duplicate coupling name '" + s.name + "'");
    if (s.name.find('/') != std::string::npos) b.ck.add(base + "/name", "a coupling name names files: no '/'");
    s.coarse = subdomain_index(b, cj["coarse"], base + "/coarse");
    s.fine = subdomain_index(b, cj["fine"], base + "/fine");
    if (b.ck.diags.size() > before) continue;
    if (b.parent.at(names[s.fine]).second != c) continue;  // a second parent, refused by scan_couplings
    if (s.coarse == s.fine) {
      b.ck.add(base + "/fine", "subdomain '" + names[s.fine] + "' is coupled to itself",
               "a coupling joins a coarse subdomain and a finer one");
      continue;
    }
    // the coupling inserts, counts and controls one material: a mixture's levels are not coupled (yet)
    bool mixture = false;
    for (std::size_t k : {s.coarse, s.fine})
      if (sim.subdomains[k]->materials().size() > 1) {
        b.ck.add(base + (k == s.coarse ? "/coarse" : "/fine"),
                 "subdomain '" + names[k] + "' holds several materials (a mixture); a coupling joins levels of "
                 "one material each",
                 "couple levels of one material, or run the mixture in one subdomain without a coupling");
        mixture = true;
      }
    if (mixture) continue;
    Subdomain& coarse = *sim.subdomains[s.coarse];
    Subdomain& fine = *sim.subdomains[s.fine];
    if (fine.coarse_grain() >= coarse.coarse_grain()) {
      b.ck.add(base + "/fine", "expected a fine level with a smaller coarse-grain ratio than the coarse level's " +
                                   fmt_num(coarse.coarse_grain()) + ", found '" + names[s.fine] + "' at " +
                                   fmt_num(fine.coarse_grain()));
      continue;
    }
    // a cycle: the coarse level descends from the fine one
    if (descends_from(b, names[s.coarse], names[s.fine]))
      b.ck.add(base + "/coarse", "the couplings form a loop: '" + names[s.coarse] + "' is itself a finer level of '" +
                                     names[s.fine] + "'");
    if (b.ck.diags.size() > before) continue;
    // region and cells
    const json& rj = cj["region"];
    const double d_coarse = 2 * b.radii.at(names[s.coarse])[1];
    s.grid.name = s.name;
    bool box = true;
    bool cells_ok = true;
    for (int a = 0; a < 3; ++a) {
      s.grid.lo[a] = rj["min"][a].get<double>();
      s.grid.hi[a] = rj["max"][a].get<double>();
      s.grid.cells[a] = rj["cells"][a].get<int>();
      if (s.grid.hi[a] <= s.grid.lo[a]) {
        box = false;
        b.ck.add(base + "/region/max/" + std::to_string(a), "expected max > min along " + std::string(1, "xyz"[a]) +
                                                                ", found max " + fmt_num(s.grid.hi[a]) + " <= min " +
                                                                fmt_num(s.grid.lo[a]));
        continue;
      }
      const double edge = (s.grid.hi[a] - s.grid.lo[a]) / s.grid.cells[a];
      if (edge < 2 * d_coarse * (1 - 1e-9)) {
        cells_ok = false;
        b.ck.add(base + "/region/cells/" + std::to_string(a),
                 "expected cells of at least 2 coarse parcel diameters (" + fmt_num(2 * d_coarse) + " m) along " +
                     std::string(1, "xyz"[a]) + ", found " + fmt_num(edge) + " m",
                 "use at most " + std::to_string(std::max(1, static_cast<int>((s.grid.hi[a] - s.grid.lo[a]) /
                                                                               (2 * d_coarse)))) +
                     " cells along " + std::string(1, "xyz"[a]));
      }
    }
    if (!box || !cells_ok) continue;
    const double n_region_cells = static_cast<double>(s.grid.cells[0]) * s.grid.cells[1] * s.grid.cells[2];
    if (n_region_cells > static_cast<double>(kMaxGridCells)) {
      b.ck.add(base + "/region/cells", "the region has " + fmt_num(n_region_cells) + " cells, more than the " +
                                           std::to_string(kMaxGridCells) + " a grid may have",
               "use fewer, larger cells");
      continue;
    }
    // inside the coarse level's domain
    if (auto it = b.parent.find(names[s.coarse]); it != b.parent.end()) {
      const json& pr = cs[it->second.second]["region"];
      for (int a = 0; a < 3; ++a)
        if (s.grid.lo[a] < pr["min"][a].get<double>() - 1e-12 || s.grid.hi[a] > pr["max"][a].get<double>() + 1e-12) {
          b.ck.add(base + "/region", "the fine region lies outside the coarse level's domain: '" + names[s.coarse] +
                                         "' lives only in the region of " + idx("/couplings", it->second.second) +
                                         ", and this region leaves it along " + std::string(1, "xyz"[a]));
          break;
        }
    } else {
      double lo[3], hi[3];
      auto bound = [](double v) { return std::isfinite(v) ? fmt_num(v) : std::string(v < 0 ? "-inf" : "inf"); };
      if (reachable_box(b, lo, hi))
        for (int a = 0; a < 3; ++a)
          if (s.grid.lo[a] < lo[a] - 1e-12 || s.grid.hi[a] > hi[a] + 1e-12) {
            b.ck.add(base + "/region", "the fine region lies outside the coarse level's domain along " +
                                           std::string(1, "xyz"[a]) + ": [" + fmt_num(s.grid.lo[a]) + ", " +
                                           fmt_num(s.grid.hi[a]) + "] m against [" + bound(lo[a]) + ", " +
                                           bound(hi[a]) + "] m (the walls, planes, pour, insertion and deletion regions)");
            break;
          }
    }
    // behind a plane wall at a slant: every corner on the wall's far side
    for (const auto& w : sim.walls) {
      if (b.ck.diags.size() > before) break;  // outside the box already (an axis-aligned plane's far side)
      if (w.shape != WallPrimitive::Shape::plane || w.moving || std::isfinite(w.remove_at) || w.active_from > 0)
        continue;
      bool behind = true;
      for (int corner = 0; corner < 8 && behind; ++corner) {
        double d = 0;
        for (int a = 0; a < 3; ++a) d += ((corner >> a & 1 ? s.grid.hi[a] : s.grid.lo[a]) - w.p[a]) * w.n[a];
        behind = d < 0;
      }
      if (behind) {
        b.ck.add(base + "/region", "the fine region [" + fmt_num(s.grid.lo[0]) + ", " + fmt_num(s.grid.hi[0]) +
                                       "] x [" + fmt_num(s.grid.lo[1]) + ", " + fmt_num(s.grid.hi[1]) + "] x [" +
                                       fmt_num(s.grid.lo[2]) + ", " + fmt_num(s.grid.hi[2]) +
                                       "] m lies behind the plane '" + w.name + "' (" + idx("/walls", w.wall) +
                                       "), where no particle can be");
        break;
      }
    }
    // Material poured into the region: the fine level receives what crosses
    // its inflow faces, and what lies inside at the start is refined
    // (Coupling::refine_at_start), but a coarse parcel poured inside it later
    // would never reach the fine level.
    auto inside = [&](double x, double y, double z) {
      const double p[3] = {x, y, z};
      for (int a = 0; a < 3; ++a)
        if (!(p[a] > s.grid.lo[a] && p[a] < s.grid.hi[a])) return false;
      return true;
    };
    for (std::size_t q = 0; q < sim.flow.pours.size(); ++q) {
      const Pour& p = sim.flow.pours[q];
      if (p.subdomain != s.coarse) continue;
      double lo[3], hi[3];
      region_box(p.region, lo, hi);
      bool reaches = false;
      constexpr int kSamples = 9;
      for (int i = 0; i < kSamples && !reaches; ++i)
        for (int j = 0; j < kSamples && !reaches; ++j)
          for (int k = 0; k < kSamples && !reaches; ++k) {
            const double x = lo[0] + (hi[0] - lo[0]) * i / (kSamples - 1.0);
            const double y = lo[1] + (hi[1] - lo[1]) * j / (kSamples - 1.0);
            const double z = lo[2] + (hi[2] - lo[2]) * k / (kSamples - 1.0);
            reaches = region_contains(p.region, x, y, z) && inside(x, y, z);
          }
      if (reaches)
        b.ck.add(p.where + "/insert/region",
                 "the pour of '" + names[s.coarse] + "' places parcels inside the fine region of " + base +
                     "; they never cross its inflow faces, so their material would never reach the fine level '" +
                     names[s.fine] + "'",
                 "pour above or beside the fine region");
    }
    // two fine regions that overlap (a nested region lies inside its parent's, which is fine)
    for (std::size_t h = 0; h < specs.size(); ++h) {
      const CouplingSpec& o = specs[h];
      const bool nested = descends_from(b, names[s.fine], names[o.fine]) || descends_from(b, names[o.fine], names[s.fine]);
      bool overlap = true;
      for (int a = 0; a < 3; ++a) overlap = overlap && s.grid.lo[a] < o.grid.hi[a] && o.grid.lo[a] < s.grid.hi[a];
      if (overlap && !nested)
        b.ck.add(base + "/region", "this fine region overlaps the one of " + o.where +
                                       "; fine regions side by side must not overlap (nest one inside the other's "
                                       "level instead)");
    }
    // faces
    for (const auto& f : cj["inflow_faces"]) s.inflow[face_from_name(f.get<std::string>())] = true;
    s.shell_depth = cj.contains("shell_depth") ? cj["shell_depth"].get<double>() : 2 * d_coarse;
    for (int face = 0; face < kFaces; ++face)
      if (s.inflow[face] && s.shell_depth > s.grid.hi[face / 2] - s.grid.lo[face / 2])
        b.ck.add(base + (cj.contains("shell_depth") ? "/shell_depth" : "/region"),
                 "the insertion shell (" + fmt_num(s.shell_depth) + " m) is deeper than the region along " +
                     std::string(1, "xyz"[face / 2]));
    s.fill_target = cj["fill_target"].get<double>();
    s.attempts = cj["insertion_attempts"].get<int>();
    s.grid_interval = cj["grid_interval"].get<double>();
    s.match_outflow = cj["match_outflow"].get<bool>();
    s.growth_steps = cj["refine_growth_steps"].get<int>();
    s.fine_density = sim.materials[fine.material()].density;
    s.alpha_ratio = fine.coarse_grain() / coarse.coarse_grain();
    // one seed per coupling: the run's seed and the coupling's index mixed as the pours' seeds are
    s.seed = sim.seed * 6364136223846793005ull + (c + 1) * 1442695040888963407ull;
    requested.push_back(cj["control_steps"].get<int>());
    specs.push_back(std::move(s));
    blocks.push_back(&cj);
  }
  if (specs.size() != cs.size()) return;
  // One control clock for every coupling (several couplings add their forces
  // into the same level): the most frequent request, in whole macro steps.
  std::uint64_t control_macro = std::numeric_limits<std::uint64_t>::max();
  for (std::size_t c = 0; c < specs.size(); ++c) {
    const int n_f = substeps_of(macro, sim.subdomains[specs[c].fine]->time_step());
    control_macro = std::min<std::uint64_t>(control_macro, (static_cast<std::uint64_t>(requested[c]) + n_f - 1) / n_f);
  }
  sim.control_macro = control_macro;
  for (std::size_t c = 0; c < specs.size(); ++c) {
    CouplingSpec& s = specs[c];
    const json& cj = *blocks[c];
    const std::string base = s.where;
    const int n_f = substeps_of(macro, sim.subdomains[s.fine]->time_step());
    const int n_c = substeps_of(macro, sim.subdomains[s.coarse]->time_step());
    s.control_macro = control_macro;
    // the steps of a control interval are counted in an int: levels whose
    // time steps differ by 5e8 (an empty fine level given 1000 s, the coarse
    // one 2e-6 s: the run-time fuzzer) overflowed it
    const double most = static_cast<double>(std::max(n_f, n_c)) * static_cast<double>(control_macro);
    if (!(most <= static_cast<double>(std::numeric_limits<int>::max()))) {
      b.ck.add(base, "the control interval of " + std::to_string(control_macro) + " macro step(s) of " + fmt_num(macro) +
                         " s is " + fmt_num(most) + " steps of the level with the shorter time step (" +
                         fmt_num(macro / std::max(n_f, n_c)) + " s), more than a control interval can count (" +
                         std::to_string(std::numeric_limits<int>::max()) + ")",
                 "check the levels' time steps: the macro step is the largest of them (" +
                     sim.subdomains[n_f >= n_c ? s.coarse : s.fine]->name() + "'s)");
      continue;
    }
    s.fine_steps = static_cast<int>(control_macro) * n_f;
    s.coarse_steps = static_cast<int>(control_macro) * n_c;
    if (s.fine_steps != requested[c])
      spdlog::info("{}: control interval {} fine steps (asked {}): {} macro step(s) of {:.4g} s, the coarsest level's "
                   "step, so that every exchange falls on a step of every level",
                   base, s.fine_steps, requested[c], control_macro, macro);
    const int tmax = cj["transfer_max_steps"].get<int>();
    s.transfer_controls =
        std::max<std::uint64_t>(1, (static_cast<std::uint64_t>(tmax) + static_cast<std::uint64_t>(s.fine_steps) - 1) /
                                       static_cast<std::uint64_t>(s.fine_steps));
    const double dt_f = macro / n_f, dt_c = macro / n_c;
    // What the controllers are set up for (ABI 2.5): the levels' steps per
    // control interval and time steps, the grid, and the inflow cells (those
    // touching an inflow face, each with its inward normal), from which the
    // models take their defaults.
    std::vector<uint32_t> inflow_cells;
    std::vector<int32_t> inflow_dirs;
    for (int iz = 0; iz < s.grid.cells[2]; ++iz)
      for (int iy = 0; iy < s.grid.cells[1]; ++iy)
        for (int ix = 0; ix < s.grid.cells[0]; ++ix) {
          const int i3[3] = {ix, iy, iz};
          int32_t dir[3] = {0, 0, 0};
          bool touches = false;
          for (int face = 0; face < kFaces; ++face) {
            const int a = face / 2;
            const bool at = face % 2 == 0 ? i3[a] == 0 : i3[a] == s.grid.cells[a] - 1;
            if (!s.inflow[face] || !at) continue;
            touches = true;
            dir[a] += face % 2 == 0 ? 1 : -1;  // inward: away from the face
          }
          if (!touches) continue;
          inflow_cells.push_back(static_cast<uint32_t>(ix + s.grid.cells[0] * (iy + s.grid.cells[1] * iz)));
          inflow_dirs.insert(inflow_dirs.end(), dir, dir + 3);
        }
    const domel_control_level_setup_v1 level_setup[2] = {
        {sizeof(domel_control_level_setup_v1), 0, sim.subdomains[s.fine]->name().c_str(),
         sim.subdomains[s.fine]->coarse_grain(), dt_f, static_cast<uint64_t>(s.fine_steps)},
        {sizeof(domel_control_level_setup_v1), 0, sim.subdomains[s.coarse]->name().c_str(),
         sim.subdomains[s.coarse]->coarse_grain(), dt_c, static_cast<uint64_t>(s.coarse_steps)}};
    domel_control_setup_v1 setup_view{};
    setup_view.struct_size = sizeof setup_view;
    setup_view.level_count = 2;
    setup_view.interval = static_cast<double>(control_macro) * macro;
    setup_view.levels = level_setup;
    setup_view.nx = static_cast<uint32_t>(s.grid.cells[0]);
    setup_view.ny = static_cast<uint32_t>(s.grid.cells[1]);
    setup_view.nz = static_cast<uint32_t>(s.grid.cells[2]);
    setup_view.n_cells = static_cast<std::size_t>(s.grid.cells[0]) * s.grid.cells[1] * s.grid.cells[2];
    for (int a = 0; a < 3; ++a) {
      setup_view.origin[a] = s.grid.lo[a];
      setup_view.spacing[a] = (s.grid.hi[a] - s.grid.lo[a]) / s.grid.cells[a];
    }
    setup_view.n_inflow_cells = inflow_cells.size();
    setup_view.inflow_cell = inflow_cells.data();
    setup_view.inflow_direction = inflow_dirs.data();
    // A controller block is the model's own (validated against its schema,
    // its defaults filled, by check_models): the block less "enabled" and
    // "model" is what the model is created with.
    auto controller = [&](const char* key, ControllerSetup& setup) {
      const json& blk = cj[key];
      setup.enabled = blk["enabled"].get<bool>();
      if (!setup.enabled) return;
      const std::string model = blk["model"].get<std::string>();
      const RegisteredModel* m = b.registry.find(DOMEL_KIND_CONTROLLER, model);
      if (m == nullptr) {  // check_models reported it
        setup.enabled = false;
        return;
      }
      const json params = plugin_params(blk, DOMEL_KIND_CONTROLLER);
      try {
        setup.model = std::make_shared<ModelInstance>(*m, params, base + "/" + key);
        setup.model->control_setup(setup_view);
        setup.params = params;
      } catch (const PluginError& e) {
        b.ck.add(base + "/" + key, e.what());
        setup.enabled = false;
      }
    };
    controller("stress_control", s.stress);
    controller("velocity_control", s.velocity);
    sim.subdomains[s.fine]->store().enable_external_force();
    sim.subdomains[s.coarse]->store().enable_external_force();
    sim.couplings.push_back(std::make_unique<Coupling>(std::move(s)));
  }
  sim.flow.expect_external();
}

}  // namespace domel::platform::scenario_detail
