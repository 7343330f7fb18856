// SPDX-License-Identifier: MIT
// The A/B comparison driver (see compare.hpp).
#include "apps/compare.hpp"

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/output_folder.hpp"
#include "scenario/scenario.hpp"
#include "loop/macro_step.hpp"
#include "outputs/probes.hpp"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace domel::platform {

extern const char* const kPlotCompareScript;

namespace {

using nlohmann::json;

json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

std::string fmt(double v) {
  if (!std::isfinite(v)) return "–";
  char b[32];
  if (v == std::floor(v) && std::fabs(v) < 1e15)
    std::snprintf(b, sizeof b, "%.0f", v);  // counts: particles, contacts
  else
    std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

/// The last row of a CSV as column -> value.
std::vector<std::pair<std::string, double>> last_row(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<std::pair<std::string, double>> out;
  std::stringstream hs(header), ls(last);
  std::string h, v;
  while (std::getline(hs, h, ',') && std::getline(ls, v, ',')) {
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    out.emplace_back(h, end != v.c_str() ? x : std::nan(""));
  }
  return out;
}

/// Single-quotes an argument for /bin/sh.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string slug(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

std::filesystem::path write_report(const std::filesystem::path& out, const std::string& title, const std::string& intro,
                                   const std::string& what, const std::vector<std::string>& labels,
                                   const std::vector<std::string>& rows, const std::vector<std::filesystem::path>& dirs,
                                   const std::vector<json>& summaries) {
  // Plots (python3 + matplotlib); the report is written without them otherwise.
  std::vector<std::string> pngs;
  {
    const auto script = out / "plot_compare.py";
    io::write_file_atomically(script, kPlotCompareScript);
    // Debian's interpreter first: python3-matplotlib installs into it, while a
    // python3 earlier on PATH (pyenv, venv) may lack matplotlib.
    const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    std::string cmd = python + " " + shell_quote(script.string()) + " " + shell_quote(out.string());
    for (std::size_t k = 0; k < dirs.size(); ++k)
      cmd += " " + shell_quote(labels[k]) + " " + shell_quote(dirs[k].string());
    cmd += " 2>&1";
    if (FILE* p = popen(cmd.c_str(), "r")) {
      char line[512];
      std::string all;
      while (std::fgets(line, sizeof line, p)) all += line;
      const int rc = pclose(p);
      if (rc == 0) {
        std::stringstream ss(all);
        std::string l;
        while (std::getline(ss, l))
          if (l.size() > 4 && l.substr(l.size() - 4) == ".png") pngs.push_back(l);
      } else {
        spdlog::warn("compare: plots not made (python3 with matplotlib needed): {}", all);
      }
    }
  }

  std::ostringstream md;
  md << "# " << title << "\n\n" << intro << "\n\n";
  md << "| variant | " << what << " |\n|---|---|\n";
  for (std::size_t k = 0; k < labels.size(); ++k) md << "| " << labels[k] << " | " << rows[k] << " |\n";
  md << "\n## Final values\n\n";
  // one row per observable column (from the last probe row), one column per variant
  std::vector<std::vector<std::pair<std::string, double>>> finals;
  for (const auto& d : dirs) finals.push_back(last_row(d / "probes.csv"));
  md << "| quantity |";
  for (const auto& l : labels) md << " " << l << " |";
  md << "\n|---|";
  for (std::size_t k = 0; k < dirs.size(); ++k) md << "---|";
  md << "\n";
  if (!finals.empty())
    for (std::size_t c = 0; c < finals[0].size(); ++c) {
      const std::string unit = probe_column_unit(finals[0][c].first);
      md << "| " << finals[0][c].first << (unit.empty() || unit == "1" ? "" : " [" + unit + "]") << " |";
      for (const auto& f : finals) md << " " << (c < f.size() ? fmt(f[c].second) : "–") << " |";
      md << "\n";
    }
  md << "| wall time [s] |";
  for (const auto& s : summaries) md << " " << fmt(s.value("wall_time_s", 0.0)) << " |";
  md << "\n| particle-steps/s |";
  for (const auto& s : summaries) md << " " << fmt(s.value("particle_steps_per_s", 0.0)) << " |";
  md << "\n\n";
  if (!pngs.empty()) {
    md << "## Time series\n\n";
    for (const auto& p : pngs) md << "![" << p << "](" << p << ")\n\n";
  }
  md << "Each variant's own output (ParaView files, probes.csv, summary.json) is in the folder named after it.\n";
  const auto report = out / "report.md";
  io::write_file_atomically(report, md.str());
  return report;
}

}  // namespace

CompareVariant parse_variant(const std::string& text, const std::string& label) {
  CompareVariant v;
  v.label = label;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ';')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || item[0] != '/')
      throw ConfigError({{"", "", "--vary expects POINTER=VALUE with a JSON pointer such as /subdomains/0/time_step, found '" + item + "'", ""}});
    v.assignments.emplace_back(item.substr(0, eq), item.substr(eq + 1));
  }
  if (v.assignments.empty()) throw ConfigError({{"", "", "--vary needs at least one POINTER=VALUE", ""}});
  if (v.label.empty()) {
    for (const auto& [p, val] : v.assignments) v.label += (v.label.empty() ? "" : ", ") + p + "=" + val;
  }
  return v;
}

std::filesystem::path run_compare(const CompareOptions& options, PluginRegistry& registry) {
  std::ifstream in(options.scenario);
  if (!in) throw ConfigError({{options.scenario.string(), "", "cannot open the scenario file", ""}});
  json base;
  try {
    base = json::parse(in);
  } catch (const json::parse_error& e) {
    throw ConfigError({{options.scenario.string(), "", std::string("not valid JSON: ") + e.what(), ""}});
  }

  // Build and validate every variant before running any, so a typo in the
  // last --vary does not cost the first variant's run.
  std::vector<std::unique_ptr<Simulation>> sims;
  std::vector<json> docs;
  for (std::size_t k = 0; k < options.variants.size(); ++k) {
    const auto& var = options.variants[k];
    json doc = base;
    std::vector<Diagnostic> diags;
    for (const auto& [pointer, text] : var.assignments) {
      json value;
      try {
        value = json::parse(text);
      } catch (const json::parse_error&) {
        value = text;  // a bare word: a string
      }
      try {
        const json::json_pointer ptr(pointer);
        if (!doc.contains(ptr.parent_pointer()))
          diags.push_back({options.scenario.string(), pointer,
                           "--vary of variant '" + var.label + "' points into a location the scenario does not have",
                           "its parent " + ptr.parent_pointer().to_string() + " must exist"});
        else
          doc[ptr] = value;
      } catch (const json::exception& e) {
        diags.push_back({options.scenario.string(), pointer, std::string("not a JSON pointer: ") + e.what(), ""});
      }
    }
    if (!diags.empty()) throw ConfigError(diags);
    try {
      sims.push_back(load_scenario(doc, options.scenario, registry));
    } catch (ConfigError& e) {
      auto d = e.diagnostics();
      for (auto& x : d) x.message = "variant '" + var.label + "': " + x.message;
      throw ConfigError(d);
    }
    docs.push_back(doc);
  }

  const std::filesystem::path out = options.output_directory;
  std::string capped;  // the variants --max-steps stops before their end, for the log and the report
  if (options.max_steps > 0)
    for (std::size_t k = 0; k < sims.size(); ++k) {
      const double macro = sims[k]->macro_step();
      const auto total = static_cast<std::uint64_t>(std::ceil(sims[k]->duration / macro - kTimeTolerance));
      if (options.max_steps >= total) continue;
      spdlog::warn("compare: variant '{}' stops after {} of its {} macro steps (--max-steps), at t = {:.6g} s of "
                   "{:.6g} s: its final values are not the scenario's end", options.variants[k].label,
                   options.max_steps, total, options.max_steps * macro, sims[k]->duration);
      capped += (capped.empty() ? "" : "; ") + options.variants[k].label + ": " + std::to_string(options.max_steps) +
                " of " + std::to_string(total) + " macro steps";
    }
  // a comparison run again replaces its variants' earlier runs (their
  // manifests say which files; io/output_folder.hpp), checked before any runs
  for (const auto& v : options.variants) io::prepare_output_folder(out / slug(v.label), io::OutputPolicy::overwrite);
  std::filesystem::create_directories(out);
  std::vector<std::filesystem::path> dirs;
  std::vector<json> summaries;
  for (std::size_t k = 0; k < sims.size(); ++k) {
    RunOptions ro;
    ro.output_directory = out / slug(options.variants[k].label);
    ro.threads = options.threads;
    ro.max_steps = options.max_steps;
    ro.progress = options.progress;
    spdlog::info("compare: variant {} of {}: {}", k + 1, sims.size(), options.variants[k].label);
    const RunResult r = sims[k]->run(ro, registry);
    dirs.push_back(ro.output_directory);
    summaries.push_back(r.summary);
  }

  std::vector<std::string> labels, rows;
  for (const auto& v : options.variants) {
    std::string o;
    for (const auto& [p, val] : v.assignments) o += (o.empty() ? "" : "<br>") + ("`" + p + "` = `" + val + "`");
    labels.push_back(v.label);
    rows.push_back(o);
  }
  const std::string intro = "Scenario `" + options.scenario.string() + "`, " + std::to_string(sims.size()) +
                            " variants, identical seeds and insertion; written by `domel compare` (domel " +
                            DOMEL_VERSION + ")." +
                            (capped.empty() ? "" : " **Stopped early by --max-steps** (" + capped + ").");
  return write_report(out, "A/B comparison: " + options.scenario.filename().string(), intro, "overrides", labels, rows,
                      dirs, summaries);
}

std::filesystem::path report_runs(const std::filesystem::path& out, const std::vector<std::filesystem::path>& runs,
                                  std::vector<std::string> labels) {
  std::vector<Diagnostic> diags;
  std::vector<json> summaries;
  std::vector<std::string> rows;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const auto sj = runs[k] / "summary.json", pc = runs[k] / "probes.csv";
    if (!std::filesystem::exists(sj) || !std::filesystem::exists(pc)) {
      diags.push_back({runs[k].string(), "",
                       "--runs " + runs[k].string() +
                           ": expected the output folder of a finished run, with summary.json and probes.csv; found " +
                           std::string(std::filesystem::exists(runs[k]) ? "a folder without them" : "no such folder"),
                       "a run that failed or was stopped writes no summary.json"});
      continue;
    }
    json s;
    try {
      s = read_json(sj);
    } catch (const json::exception& e) {
      diags.push_back({sj.string(), "", sj.string() + " is not valid JSON: " + e.what(), ""});
      continue;
    }
    const json sc = s.value("scenario", json::object());
    rows.push_back("`" + sc.value("file", std::string("?")) + "`, folder `" + runs[k].string() + "`");
    summaries.push_back(s);
  }
  if (!diags.empty()) throw ConfigError(diags);
  if (labels.empty())
    for (const auto& r : runs) labels.push_back(r.filename().empty() ? r.parent_path().filename().string() : r.filename().string());
  std::filesystem::create_directories(out);
  const std::string intro = std::to_string(runs.size()) + " finished runs, compared by `domel compare --runs` (domel " +
                            std::string(DOMEL_VERSION) + "); each row names its scenario file and output folder.";
  return write_report(out, "Comparison of " + std::to_string(runs.size()) + " runs", intro, "run", labels, rows, runs,
                      summaries);
}

}  // namespace domel::platform
