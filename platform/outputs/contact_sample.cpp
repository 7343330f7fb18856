// SPDX-License-Identifier: MIT
// Wall loads and contact rows from the recorded contact forces.
#include "outputs/contact_sample.hpp"

#include "core/archive.hpp"
#include "loop/ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <cmath>
#include <cstring>

namespace domel::platform {

namespace {
constexpr std::size_t kSums = 4;  // force x, y, z, torque
/// |F_t| at mu |F_n| within round-off of the Coulomb cap's rescaling.
constexpr double kSlidingTolerance = 1e-9;
}  // namespace

void ContactSample::configure(std::vector<WallLoadProbe> probes, bool rows) {
  probes_ = std::move(probes);
  rows_wanted_ = rows;
  sums_.assign(kSums * probes_.size(), 0.0);
}

std::vector<std::string> ContactSample::columns() const {
  std::vector<std::string> c;
  for (const auto& p : probes_) {
    for (const char* s : {".force_x", ".force_y", ".force_z"}) c.push_back(p.name + s);
    if (p.has_axis) c.push_back(p.name + ".torque");
  }
  return c;
}

void ContactSample::begin(double t) {
  time_ = t;
  std::fill(sums_.begin(), sums_.end(), 0.0);
  rows_.clear();
}

void ContactSample::take(std::size_t k, const Subdomain& sd, const std::vector<WallPrimitive>& walls) {
  take(k, sd, sd.store(), sd.contact_records(), walls);
}

void ContactSample::take(std::size_t k, const Subdomain& sd, const ParticleStore& s,
                         const std::vector<const std::vector<ContactRecord>*>& records,
                         const std::vector<WallPrimitive>& walls) {
  for (const auto* list : records)
    for (const ContactRecord& c : *list) {
      const bool wall = c.j == ContactRecord::kWall;
      const double xi[3] = {s.x[c.i], s.y[c.i], s.z[c.i]};
      const double xj[3] = {c.px, c.py, c.pz};  // the contact point on a wall; the partner (its nearest image)
      const double f[3] = {c.fx, c.fy, c.fz};
      if (wall) {
        const std::size_t scenario_wall = walls[c.wall].wall;
        for (std::size_t q = 0; q < probes_.size(); ++q) {
          const WallLoadProbe& p = probes_[q];
          if (p.wall != scenario_wall || (p.subdomain != kAllSubdomains && p.subdomain != k)) continue;
          double* sum = &sums_[kSums * q];
          for (int a = 0; a < 3; ++a) sum[a] -= f[a];  // the wall feels the opposite of the particle
          if (p.has_axis) {
            const double r[3] = {xj[0] - p.point[0], xj[1] - p.point[1], xj[2] - p.point[2]};
            const double m[3] = {-(r[1] * f[2] - r[2] * f[1]), -(r[2] * f[0] - r[0] * f[2]),
                                 -(r[0] * f[1] - r[1] * f[0])};
            sum[3] += m[0] * p.axis[0] + m[1] * p.axis[1] + m[2] * p.axis[2];
          }
        }
      }
      if (!rows_wanted_) continue;
      io::ContactRow row{};
      double d[3] = {xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]};
      const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double n[3] = {dist > 0 ? d[0] / dist : 0, dist > 0 ? d[1] / dist : 0, dist > 0 ? d[2] / dist : 0};
      const double fn = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
      for (int a = 0; a < 3; ++a) {
        row.a[a] = xi[a];
        row.b[a] = xj[a];
        row.force[a] = f[a];
        row.tangential[a] = f[a] - fn * n[a];
      }
      row.normal_force = fn;
      row.overlap = (wall ? s.radius[c.i] : s.radius[c.i] + s.radius[c.j]) - dist;
      row.id_i = s.id[c.i];
      row.id_j = wall ? io::ContactRow::kWallId : s.id[c.j];
      row.subdomain = static_cast<std::int32_t>(k);
      row.wall = wall ? static_cast<std::int32_t>(walls[c.wall].wall) : -1;
      const double mu = wall ? sd.wall_pair(c.wall, s.material[c.i]).friction
                             : sd.pair(s.material[c.i], s.material[c.j]).friction;
      const double ft = std::sqrt(row.tangential[0] * row.tangential[0] + row.tangential[1] * row.tangential[1] +
                                  row.tangential[2] * row.tangential[2]);
      row.sliding = ft > 0 && ft >= mu * std::fabs(fn) * (1.0 - kSlidingTolerance) ? 1 : 0;
      rows_.push_back(row);
    }
}

void ContactSample::append_values(double t, double tolerance, std::vector<double>& row) const {
  const bool here = std::fabs(t - time_) <= tolerance;
  for (std::size_t q = 0; q < probes_.size(); ++q) {
    const std::size_t n = probes_[q].has_axis ? 4 : 3;
    for (std::size_t a = 0; a < n; ++a) row.push_back(here ? sums_[kSums * q + a] : std::nan(""));
  }
}

const std::vector<io::ContactRow>* ContactSample::rows_at(double t, double tolerance) const {
  return rows_wanted_ && std::fabs(t - time_) <= tolerance ? &rows_ : nullptr;
}

void ContactSample::fields(CheckpointFields& f) {
  f("time", time_);
  std::vector<double> sums = sums_;
  f("sums", sums);
  if (f.loading() && sums.size() != sums_.size())
    f.reader().fail(f.prefix() + "sums", "holds " + std::to_string(sums.size()) +
                                             " values, this scenario's wall loads need " + std::to_string(sums_.size()));
  sums_ = std::move(sums);
  std::string bytes(reinterpret_cast<const char*>(rows_.data()), rows_.size() * sizeof(io::ContactRow));
  f("rows", bytes);
  if (!f.loading()) return;
  if (bytes.size() % sizeof(io::ContactRow) != 0)
    f.reader().fail(f.prefix() + "rows", "is not a whole number of contact rows");
  rows_.resize(bytes.size() / sizeof(io::ContactRow));
  if (!bytes.empty()) std::memcpy(rows_.data(), bytes.data(), bytes.size());
}

void ContactSample::save(ArchiveWriter& w, const std::string& prefix) {
  save_fields(w, prefix, [&](CheckpointFields& f) { fields(f); });
}

void ContactSample::load(const ArchiveReader& r, const std::string& prefix) {
  load_fields(r, prefix, [&](CheckpointFields& f) { fields(f); });
}

void ContactSample::init(RunContext& ctx) {
  if (!ctx.restart && enabled())
    for (auto& sd : ctx.subdomains) sd->set_record_contacts(true);  // the outputs at t = 0 (wall loads, contacts)
}

void ContactSample::setup(RunContext& ctx) {
  if (ctx.restart || !enabled()) return;
  begin(0.0);
  for (std::size_t k = 0; k < ctx.subdomains.size(); ++k) {
    take(ctx, k);
    ctx.subdomains[k]->set_record_contacts(false);
  }
}

void ContactSample::before_steps(RunContext& ctx, const MacroStep& step) {
  // the contacts of the macro step's last steps, when an output at its end reads them
  sampling_ = false;
  for (const Cadence* c : wanted_at_) sampling_ = sampling_ || c->due(step.index + 1);
  if (sampling_) begin(static_cast<double>(step.index + 1) * ctx.macro);
}

void ContactSample::after_step(RunContext& ctx, std::size_t k, bool last) {
  if (sampling_ && last) take(ctx, k);
}

void ContactSample::take(RunContext& ctx, std::size_t k) {
  Subdomain& sd = *ctx.subdomains[k];
  const GatheredParticles all = ctx.ranks.gather(sd, true);
  std::vector<ContactRecord> gathered;
  take(k, sd, *all, ctx.ranks.contact_records(sd, *all, gathered), ctx.walls);
}

void ContactSample::probe_columns(std::vector<std::string>& names) const {
  for (const auto& c : columns()) names.push_back(c);
}

void ContactSample::probe_values(RunContext& ctx, double t, std::vector<double>& row) {
  append_values(t, kTimeTolerance * ctx.macro, row);
}

}  // namespace domel::platform
