// SPDX-License-Identifier: MIT
// CellGrid: binning by particle centre, two passes over the particles (sums,
// then fluctuations about the cell's Favre velocity), one pass over the
// contact records (virial), then division by the accessible cell volume.
// Formulas: docs/physics.md §5.2 and §8; choices: docs/averaging.md.
#include "averaging/cell_grid.hpp"

#include "core/archive.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "core/error.hpp"

namespace domel::platform {

namespace {

constexpr double kPi = 3.14159265358979323846;

const char* const kAxisName[3] = {"x", "y", "z"};

/// Add the outer product l (x) f, scaled by `scale`, to the 9 entries at t.
void add_outer(double* t, const double l[3], double fx, double fy, double fz, double scale) {
  const double f[3] = {fx, fy, fz};
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) t[3 * a + b] += scale * l[a] * f[b];
  }
}

}  // namespace

void CellFields::reset(std::size_t n) {
  for (std::vector<double>* v : {&count, &count_fixed, &mass, &mobile_mass, &volume_fraction, &vx, &vy, &vz,
                                 &vmin_x, &vmin_y, &vmin_z, &vmax_x, &vmax_y, &vmax_z, &pressure, &accessible}) {
    v->assign(n, 0.0);
  }
  stress.assign(9 * n, 0.0);
  stress_kinetic.assign(9 * n, 0.0);
  time = 0;
  samples = 0;
}

CellGrid::CellGrid(CellGridSpec spec) : spec_(std::move(spec)) {
  const std::string where = "cell grid '" + spec_.name + "': ";
  if (spec_.name.empty() || spec_.name.find('/') != std::string::npos) {
    throw std::invalid_argument(where + "name must be a non-empty file name");
  }
  n_cells_ = 1;
  for (int a = 0; a < 3; ++a) {
    if (!(spec_.hi[a] > spec_.lo[a]) || !std::isfinite(spec_.hi[a] - spec_.lo[a])) {
      throw std::invalid_argument(where + "hi." + kAxisName[a] + " must be greater than lo." + kAxisName[a]);
    }
    if (spec_.cells[a] < 1) {
      throw std::invalid_argument(where + "cells." + kAxisName[a] + " must be at least 1, got " +
                                  std::to_string(spec_.cells[a]));
    }
    h_[a] = (spec_.hi[a] - spec_.lo[a]) / spec_.cells[a];
    inv_h_[a] = 1.0 / h_[a];
    n_cells_ *= static_cast<std::size_t>(spec_.cells[a]);
  }
  if (n_cells_ > kMaxGridCells) {
    throw std::invalid_argument(where + "has " + std::to_string(n_cells_) + " cells, more than the " +
                                std::to_string(kMaxGridCells) + " a grid may have; use fewer, larger cells");
  }
  if (spec_.every < 1) {
    throw std::invalid_argument(where + "every must be at least 1, got " + std::to_string(spec_.every));
  }
  samples_ = Cadence::in_ticks(static_cast<std::uint64_t>(spec_.every));
  if (!(spec_.write_interval >= 0)) {
    throw std::invalid_argument(where + "write_interval must be >= 0");
  }
  if (spec_.accessible_samples < 1) {
    throw std::invalid_argument(where + "accessible_samples must be at least 1");
  }
  cell_volume_ = h_[0] * h_[1] * h_[2];
  accessible_.assign(n_cells_, 1.0);
  latest_.reset(n_cells_);
  latest_.accessible = accessible_;
  sum_.reset(n_cells_);
}

std::ptrdiff_t CellGrid::cell_of(double x, double y, double z) const {
  const double q[3] = {x, y, z};
  int ic[3];
  for (int a = 0; a < 3; ++a) {
    // Half-open [lo, hi): a centre exactly on hi belongs to no cell, so a
    // particle on a face shared by two grids is counted once.
    if (!(q[a] >= spec_.lo[a] && q[a] < spec_.hi[a])) return -1;
    ic[a] = static_cast<int>((q[a] - spec_.lo[a]) * inv_h_[a]);
    if (ic[a] >= spec_.cells[a]) ic[a] = spec_.cells[a] - 1;  // rounding just below hi
  }
  return static_cast<std::ptrdiff_t>(index(ic[0], ic[1], ic[2]));
}

void CellGrid::set_accessible(const std::vector<WallPrimitive>& walls, double time) {
  std::vector<const WallPrimitive*> active;
  for (const WallPrimitive& w : walls) {
    if (w.active(time)) active.push_back(&w);
  }
  const int n = spec_.accessible_samples;
  const double inv_points = 1.0 / (static_cast<double>(n) * n * n);
  for (int iz = 0; iz < spec_.cells[2]; ++iz) {
    for (int iy = 0; iy < spec_.cells[1]; ++iy) {
      for (int ix = 0; ix < spec_.cells[0]; ++ix) {
        const double base[3] = {spec_.lo[0] + ix * h_[0], spec_.lo[1] + iy * h_[1], spec_.lo[2] + iz * h_[2]};
        std::size_t inside = 0;
        // Midpoint rule on an n^3 sub-grid: the indicator is exact away from
        // the walls, so the only error is from the sub-cells a wall cuts.
        for (int kz = 0; kz < n; ++kz) {
          const double pz = base[2] + (kz + 0.5) * h_[2] / n;
          for (int ky = 0; ky < n; ++ky) {
            const double py = base[1] + (ky + 0.5) * h_[1] / n;
            for (int kx = 0; kx < n; ++kx) {
              const double px = base[0] + (kx + 0.5) * h_[0] / n;
              bool ok = true;
              for (const WallPrimitive* w : active) {
                double d, nx, ny, nz;
                if (w->gap(px, py, pz, d, nx, ny, nz) && d < 0.0) {
                  ok = false;
                  break;
                }
              }
              inside += ok ? 1 : 0;
            }
          }
        }
        accessible_[index(ix, iy, iz)] = static_cast<double>(inside) * inv_points;
      }
    }
  }
  latest_.accessible = accessible_;
}

void CellGrid::sample(const ParticleStore& s, const std::vector<const std::vector<ContactRecord>*>& records,
                      double time) {
  sample(s, s.size(), records, time, [](std::vector<double>&, std::vector<double>&) {});  // one process: nothing to add
}

void CellGrid::sample(const ParticleStore& s, std::size_t owned,
                      const std::vector<const std::vector<ContactRecord>*>& records, double time,
                      const RankReduction& over_ranks) {
  const std::size_t n = s.size();
  const bool consistent = s.x.size() == n && s.y.size() == n && s.z.size() == n && s.vx.size() == n &&
                          s.vy.size() == n && s.vz.size() == n && s.radius.size() == n &&
                          s.mass.size() == n && s.flags.size() == n;
  if (!consistent) {
    throw RuntimeError("cell grid '" + spec_.name + "': particle store arrays have different lengths");
  }

  CellFields& f = latest_;
  f.reset(n_cells_);
  f.accessible = accessible_;
  f.time = time;
  f.samples = 1;

  // Pass 1: counts, masses, solid volume, momentum of the mobile particles
  // (own particles only; the ghosts' cells place the contact records).
  cell_scratch_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    double q[3] = {s.x[k], s.y[k], s.z[k]};
    if (periodic_.any())  // a particle up to half a skin past a periodic face: binned at its image in the box
      for (int a = 0; a < 3; ++a)
        if (periodic_.axis[a] && (q[a] < periodic_.lo[a] || q[a] >= periodic_.hi[a]))
          q[a] -= periodic_.length(a) * std::floor((q[a] - periodic_.lo[a]) / periodic_.length(a));
    const std::ptrdiff_t c = cell_of(q[0], q[1], q[2]);
    cell_scratch_[k] = c;
    if (c < 0 || k >= owned) continue;
    const double r = s.radius[k];
    f.count[c] += 1;
    f.mass[c] += s.mass[k];
    f.volume_fraction[c] += (4.0 * kPi / 3.0) * r * r * r;  // sum V_i, divided below
    if (s.fixed(k)) {
      f.count_fixed[c] += 1;
      continue;
    }
    const bool first = f.mobile_mass[c] == 0;
    f.vmin_x[c] = first ? s.vx[k] : std::min(f.vmin_x[c], s.vx[k]);
    f.vmin_y[c] = first ? s.vy[k] : std::min(f.vmin_y[c], s.vy[k]);
    f.vmin_z[c] = first ? s.vz[k] : std::min(f.vmin_z[c], s.vz[k]);
    f.vmax_x[c] = first ? s.vx[k] : std::max(f.vmax_x[c], s.vx[k]);
    f.vmax_y[c] = first ? s.vy[k] : std::max(f.vmax_y[c], s.vy[k]);
    f.vmax_z[c] = first ? s.vz[k] : std::max(f.vmax_z[c], s.vz[k]);
    f.mobile_mass[c] += s.mass[k];
    f.vx[c] += s.mass[k] * s.vx[k];
    f.vy[c] += s.mass[k] * s.vy[k];
    f.vz[c] += s.mass[k] * s.vz[k];
  }
  // every rank's sums, and its extreme velocities (a cell without mobile
  // particles here: none, -inf), then the sample goes on alike everywhere
  {
    std::vector<double> sums, maxima;
    sums.reserve(8 * n_cells_);
    maxima.reserve(6 * n_cells_);
    for (const auto* v : {&f.count, &f.count_fixed, &f.mass, &f.volume_fraction, &f.mobile_mass, &f.vx, &f.vy, &f.vz})
      sums.insert(sums.end(), v->begin(), v->end());
    constexpr double none = -std::numeric_limits<double>::infinity();
    for (const auto* v : {&f.vmax_x, &f.vmax_y, &f.vmax_z})
      for (std::size_t c = 0; c < n_cells_; ++c) maxima.push_back(f.mobile_mass[c] > 0 ? (*v)[c] : none);
    for (const auto* v : {&f.vmin_x, &f.vmin_y, &f.vmin_z})
      for (std::size_t c = 0; c < n_cells_; ++c) maxima.push_back(f.mobile_mass[c] > 0 ? -(*v)[c] : none);
    over_ranks(sums, maxima);
    if (sums.size() != 8 * n_cells_ || maxima.size() != 6 * n_cells_)
      throw RuntimeError("cell grid '" + spec_.name + "': the ranks' sums came back with another length");
    std::size_t at = 0;
    for (auto* v : {&f.count, &f.count_fixed, &f.mass, &f.volume_fraction, &f.mobile_mass, &f.vx, &f.vy, &f.vz})
      for (std::size_t c = 0; c < n_cells_; ++c) (*v)[c] = sums[at++];
    at = 0;
    for (auto* v : {&f.vmax_x, &f.vmax_y, &f.vmax_z})
      for (std::size_t c = 0; c < n_cells_; ++c, ++at) (*v)[c] = f.mobile_mass[c] > 0 ? maxima[at] : 0.0;
    for (auto* v : {&f.vmin_x, &f.vmin_y, &f.vmin_z})
      for (std::size_t c = 0; c < n_cells_; ++c, ++at) (*v)[c] = f.mobile_mass[c] > 0 ? -maxima[at] : 0.0;
  }
  // Favre (mass-weighted) cell velocity, physics.md §5.2: u = sum m v / sum m.
  for (std::size_t c = 0; c < n_cells_; ++c) {
    if (f.mobile_mass[c] > 0) {
      const double inv = 1.0 / f.mobile_mass[c];
      f.vx[c] *= inv;
      f.vy[c] *= inv;
      f.vz[c] *= inv;
    }
  }

  // Pass 2: kinetic (streaming) stress about the cell velocity,
  // sum m v' (x) v' (physics.md §8), mobile particles only.
  for (std::size_t k = 0; k < owned; ++k) {
    const std::ptrdiff_t c = cell_scratch_[k];
    if (c < 0 || s.fixed(k)) continue;
    const double v[3] = {s.vx[k] - f.vx[c], s.vy[k] - f.vy[c], s.vz[k] - f.vz[c]};
    add_outer(&f.stress_kinetic[9 * c], v, v[0], v[1], v[2], s.mass[k]);
  }

  // Contact virial (physics.md §8 with l = x_j - x_i, f = force on j =
  // -F_i, so l (x) f = (x_i - x_j) (x) F_i): positive for a repulsive
  // contact, i.e. sigma > 0 in compression. Pairs split 1/2 : 1/2 between
  // the particles' cells as LIGGGHTS' stress/atom does (§5.2); a wall
  // contact's whole virial goes to the particle's cell, with the contact
  // point as the partner position.
  for (const std::vector<ContactRecord>* list : records) {
    if (list == nullptr) continue;
    for (const ContactRecord& r : *list) {
      if (r.i >= n || (r.j != ContactRecord::kWall && r.j >= n)) {
        throw RuntimeError("cell grid '" + spec_.name + "': contact record (" + std::to_string(r.i) + ", " +
                           std::to_string(r.j) + ") is out of range of a store of " + std::to_string(n) +
                           " particles");
      }
      const std::ptrdiff_t ci = cell_scratch_[r.i];
      if (r.j == ContactRecord::kWall) {
        if (ci < 0) continue;
        const double l[3] = {s.x[r.i] - r.px, s.y[r.i] - r.py, s.z[r.i] - r.pz};
        add_outer(&f.stress[9 * ci], l, r.fx, r.fy, r.fz, 1.0);
        continue;
      }
      const std::ptrdiff_t cj = cell_scratch_[r.j];
      if (ci < 0 && cj < 0) continue;
      const double l[3] = {s.x[r.i] - r.px, s.y[r.i] - r.py, s.z[r.i] - r.pz};  // j's nearest image
      if (ci >= 0) add_outer(&f.stress[9 * ci], l, r.fx, r.fy, r.fz, 0.5);
      if (cj >= 0) add_outer(&f.stress[9 * cj], l, r.fx, r.fy, r.fz, 0.5);
    }
  }

  {  // every rank's stresses
    std::vector<double> sums(f.stress_kinetic), none;
    sums.insert(sums.end(), f.stress.begin(), f.stress.end());
    over_ranks(sums, none);
    if (sums.size() != 18 * n_cells_)
      throw RuntimeError("cell grid '" + spec_.name + "': the ranks' sums came back with another length");
    std::copy(sums.begin(), sums.begin() + static_cast<std::ptrdiff_t>(9 * n_cells_), f.stress_kinetic.begin());
    std::copy(sums.begin() + static_cast<std::ptrdiff_t>(9 * n_cells_), sums.end(), f.stress.begin());
  }

  // Divide by the accessible volume V_c w_c (physics.md §8). A cell the
  // sub-sampling found fully inside a wall has no defined density: 0.
  for (std::size_t c = 0; c < n_cells_; ++c) {
    const double veff = cell_volume_ * accessible_[c];
    double* st = &f.stress[9 * c];
    double* kin = &f.stress_kinetic[9 * c];
    if (veff > 0) {
      const double inv = 1.0 / veff;
      f.volume_fraction[c] *= inv;
      for (int e = 0; e < 9; ++e) {
        kin[e] *= inv;
        st[e] = st[e] * inv + kin[e];
      }
    } else {
      f.volume_fraction[c] = 0;
      for (int e = 0; e < 9; ++e) st[e] = kin[e] = 0;
    }
    f.pressure[c] = (st[0] + st[4] + st[8]) / 3.0;
  }

  // Running sums for mean_since_last_take(); the velocity slots hold momentum.
  for (std::size_t c = 0; c < n_cells_; ++c) {
    sum_.count[c] += f.count[c];
    sum_.count_fixed[c] += f.count_fixed[c];
    sum_.mass[c] += f.mass[c];
    sum_.mobile_mass[c] += f.mobile_mass[c];
    sum_.volume_fraction[c] += f.volume_fraction[c];
    sum_.vx[c] += f.mobile_mass[c] * f.vx[c];
    sum_.vy[c] += f.mobile_mass[c] * f.vy[c];
    sum_.vz[c] += f.mobile_mass[c] * f.vz[c];
    sum_.pressure[c] += f.pressure[c];
  }
  for (std::size_t e = 0; e < 9 * n_cells_; ++e) {
    sum_.stress[e] += f.stress[e];
    sum_.stress_kinetic[e] += f.stress_kinetic[e];
  }
  sum_.time = time;
  ++pending_;
}

CellFields CellGrid::mean_since_last_take() {
  CellFields out = std::move(sum_);
  sum_.reset(n_cells_);
  out.accessible = accessible_;
  out.samples = pending_;
  if (pending_ > 0) {
    const double inv = 1.0 / static_cast<double>(pending_);
    for (std::size_t c = 0; c < n_cells_; ++c) {
      // Favre mean over time as well: total momentum / total mobile mass.
      if (out.mobile_mass[c] > 0) {
        const double inv_m = 1.0 / out.mobile_mass[c];
        out.vx[c] *= inv_m;
        out.vy[c] *= inv_m;
        out.vz[c] *= inv_m;
      }
      out.count[c] *= inv;
      out.count_fixed[c] *= inv;
      out.mass[c] *= inv;
      out.mobile_mass[c] *= inv;
      out.volume_fraction[c] *= inv;
      out.pressure[c] *= inv;
    }
    for (std::size_t e = 0; e < 9 * n_cells_; ++e) {
      out.stress[e] *= inv;
      out.stress_kinetic[e] *= inv;
    }
  }
  pending_ = 0;
  return out;
}

LayerProfile CellGrid::profile(const CellFields& f, int axis) const {
  if (axis < 0 || axis > 2) {
    throw std::invalid_argument("cell grid '" + spec_.name + "': profile axis must be 0, 1 or 2, got " +
                                std::to_string(axis));
  }
  if (f.count.size() != n_cells_ || f.volume_fraction.size() != n_cells_ || f.pressure.size() != n_cells_ ||
      f.mobile_mass.size() != n_cells_ || f.vx.size() != n_cells_ || f.vy.size() != n_cells_ ||
      f.vz.size() != n_cells_ || f.accessible.size() != n_cells_) {
    throw std::invalid_argument("cell grid '" + spec_.name + "': profile of a field set of another size");
  }
  const std::size_t layers = static_cast<std::size_t>(spec_.cells[axis]);
  LayerProfile p;
  p.axis = axis;
  for (std::vector<double>* v :
       {&p.centre, &p.accessible_volume, &p.count, &p.volume_fraction, &p.pressure, &p.vx, &p.vy, &p.vz}) {
    v->assign(layers, 0.0);
  }
  std::vector<double> layer_mass(layers, 0.0);
  for (int iz = 0; iz < spec_.cells[2]; ++iz) {
    for (int iy = 0; iy < spec_.cells[1]; ++iy) {
      for (int ix = 0; ix < spec_.cells[0]; ++ix) {
        const int ic[3] = {ix, iy, iz};
        const std::size_t L = static_cast<std::size_t>(ic[axis]);
        const std::size_t c = index(ix, iy, iz);
        // Weighting by V_c w_c turns the mean of phi_c and sigma_c into
        // (sum of the numerators) / (layer's accessible volume): the layer's
        // own volume fraction and stress.
        const double wv = cell_volume_ * f.accessible[c];
        p.accessible_volume[L] += wv;
        p.count[L] += f.count[c];
        p.volume_fraction[L] += wv * f.volume_fraction[c];
        p.pressure[L] += wv * f.pressure[c];
        const double m = f.mobile_mass[c];
        layer_mass[L] += m;
        p.vx[L] += m * f.vx[c];
        p.vy[L] += m * f.vy[c];
        p.vz[L] += m * f.vz[c];
      }
    }
  }
  for (std::size_t L = 0; L < layers; ++L) {
    p.centre[L] = spec_.lo[axis] + (static_cast<double>(L) + 0.5) * h_[axis];
    if (p.accessible_volume[L] > 0) {
      p.volume_fraction[L] /= p.accessible_volume[L];
      p.pressure[L] /= p.accessible_volume[L];
    }
    if (layer_mass[L] > 0) {
      p.vx[L] /= layer_mass[L];
      p.vy[L] /= layer_mass[L];
      p.vz[L] /= layer_mass[L];
    }
  }
  return p;
}

void CellGrid::fields(CheckpointFields& f) {
  f("accessible", accessible_);
  if (f.loading() && accessible_.size() != n_cells_)
    f.reader().fail(f.prefix() + "accessible", "holds a grid of " + std::to_string(accessible_.size()) +
                                                   " cells; cell grid '" + spec_.name + "' has " +
                                                   std::to_string(n_cells_));
  for (const auto& set : {std::pair<const char*, CellFields*>{"latest/", &latest_}, {"sum/", &sum_}}) {
    const std::string at = set.first;
    CellFields* cells = set.second;
    cells->for_each_field([&](const char* name, std::vector<double>& v) {
      f(at + name, v);
      if (f.loading() && !v.empty() && v.size() != n_cells_ && v.size() != 9 * n_cells_)
        f.reader().fail(f.prefix() + at + name, "does not hold one value (or nine) per cell");
    });
    std::uint64_t samples = cells->samples;
    f(at + "time", cells->time);
    f(at + "samples", samples);
    cells->samples = static_cast<std::size_t>(samples);
  }
  std::uint64_t pending = pending_;
  f("pending", pending);
  pending_ = static_cast<std::size_t>(pending);
}

void CellGrid::save(ArchiveWriter& w, const std::string& p) const {
  save_fields(w, p, [&](CheckpointFields& f) { const_cast<CellGrid*>(this)->fields(f); });
}

void CellGrid::load(const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f); });
}

}  // namespace domel::platform
