// SPDX-License-Identifier: MIT
// probes.csv (probes.hpp).
#include "outputs/probes.hpp"

#include "core/archive.hpp"
#include "subdomain/subdomain.hpp"

namespace domel::platform {

namespace {

/// The per-subdomain columns of probes.csv, "<subdomain>.<name>", in this
/// order: one table gives both the header and the values of a row.
struct ProbeColumn {
  const char* name;
  const char* unit;  ///< SI, "1" for counts and ratios
  double (*value)(const SubdomainStats&);
};
const ProbeColumn kProbeColumns[] = {
    {"particles", "1", [](const SubdomainStats& s) { return static_cast<double>(s.particles); }},
    {"ke_translational", "J", [](const SubdomainStats& s) { return s.kinetic_translational; }},
    {"ke_rotational", "J", [](const SubdomainStats& s) { return s.kinetic_rotational; }},
    {"mean_angular_speed", "rad/s", [](const SubdomainStats& s) { return s.mean_angular_speed; }},
    {"median_angular_speed", "rad/s", [](const SubdomainStats& s) { return s.median_angular_speed; }},
    {"trimmed_mean_angular_speed", "rad/s", [](const SubdomainStats& s) { return s.trimmed_mean_angular_speed; }},
    {"max_overlap_ratio", "1", [](const SubdomainStats& s) { return s.max_overlap_ratio; }},
    {"contacts", "1", [](const SubdomainStats& s) { return static_cast<double>(s.contacts); }},
    {"wall_contacts", "1", [](const SubdomainStats& s) { return static_cast<double>(s.wall_contacts); }},
};

}  // namespace

std::string probe_column_unit(const std::string& column) {
  if (column == "time") return "s";
  const auto dot = column.rfind('.');
  const std::string name = dot == std::string::npos ? column : column.substr(dot + 1);
  for (const auto& c : kProbeColumns)
    if (name == c.name) return c.unit;
  // the probe sources' columns (region mass, repose, deletion, plane, wall loads, servos)
  if (name == "repose_angle_deg") return "deg";
  if (name == "mass_kg" || name == "removed_kg") return "kg";
  if (name == "rate_kg_s") return "kg/s";
  if (name == "force_x" || name == "force_y" || name == "force_z") return "N";  // output.wall_loads
  if (name == "torque") return "N m";
  if (name == "com_x" || name == "com_y" || name == "com_z") return "m";  // output.region_mass
  if (name == "servo_force") return "N";  // walls[].motion[].servo
  if (name == "servo_travel") return "m";
  return "";
}

void ProbesOutput::setup(RunContext& ctx) {
  rows_ = Cadence::in_time(interval_, 0.0, ctx.macro);
  if (!enabled() || !ctx.writer) return;  // every rank makes the rows: their statistics are collective
  std::vector<std::string> columns = {"time"};
  for (const auto& sd : ctx.subdomains)
    for (const auto& c : kProbeColumns) columns.push_back(sd->name() + "." + c.name);
  for (const ProbeSource* s : sources_) s->probe_columns(columns);
  file_ = std::make_unique<io::CsvSeries>(ctx.out / "probes.csv", columns);
}

void ProbesOutput::output(RunContext& ctx, const MacroStep& step) {
  if (!rows_.take(step.index)) return;
  const double t = step.t;
  std::vector<double> row = {t};
  for (std::size_t k = 0; k < ctx.subdomains.size(); ++k) {
    const SubdomainStats st = ctx.stats(k, t);
    for (const auto& c : kProbeColumns) row.push_back(c.value(st));
  }
  for (ProbeSource* s : sources_) s->probe_values(ctx, t, row);
  if (file_) file_->append(row);
}

void ProbesOutput::finish(RunContext&, nlohmann::json& summary) {
  if (file_) file_->flush();
  summary["outputs"]["probes"] = enabled() ? "probes.csv" : "";
}

void ProbesOutput::fields(CheckpointFields& f, std::uint64_t first) {
  std::uint64_t row = rows_.index(), bytes = 0;
  double period = rows_.period();
  if (file_ && !f.loading()) {
    file_->flush();
    bytes = file_->size();
  }
  f("row", row);
  f("period", period);
  f("bytes", bytes);
  if (!f.loading()) return;
  rows_.restore(row, period, first);
  if (file_ && bytes > 0) file_->resume(bytes);
}

void ProbesOutput::save(ArchiveWriter& w, const std::string& p) {
  save_fields(w, p, [&](CheckpointFields& f) { fields(f, 0); });
}

void ProbesOutput::load(RunContext& ctx, const ArchiveReader& r, const std::string& p) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f, ctx.first); });
}

}  // namespace domel::platform
