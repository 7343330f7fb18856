// SPDX-License-Identifier: MIT
// Formatting of diagnostics and the "did you mean" helper (edit distance, as
// preCICE's computeMatches does; the full sorted list otherwise, as OpenFOAM).
#include "core/error.hpp"

#include <algorithm>

namespace domel::platform {

std::string Diagnostic::format() const {
  std::string s;
  if (!file.empty()) s += file + ": ";
  s += "at " + (pointer.empty() ? std::string("/") : pointer) + ": " + message;
  if (!hint.empty()) s += " (" + hint + ")";
  return s;
}

static std::string join_messages(const std::vector<Diagnostic>& d) {
  std::string s;
  for (const auto& x : d) {
    if (!s.empty()) s += "\n";
    s += x.format();
  }
  return s;
}

ConfigError::ConfigError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(join_messages(diagnostics)), diagnostics_(std::move(diagnostics)) {}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  // Optimal string alignment distance: insertions, deletions, substitutions
  // and swaps of two adjacent characters ("rnu" -> "run") each cost 1.
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i)
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

std::string suggest(const std::string& found, const std::vector<std::string>& candidates) {
  if (candidates.empty()) return {};
  std::vector<std::string> sorted = candidates;
  std::sort(sorted.begin(), sorted.end());
  std::string best;
  std::size_t best_d = std::string::npos;
  for (const auto& c : sorted) {
    const std::size_t d = edit_distance(found, c);
    if (d < best_d) { best_d = d; best = c; }
  }
  // Close enough to be a typo: at most a third of the longer word, at least 1.
  const std::size_t limit = std::max<std::size_t>(1, std::max(found.size(), best.size()) / 3);
  if (best_d <= limit) return "did you mean '" + best + "'?";
  std::string list = "valid: ";
  for (std::size_t k = 0; k < sorted.size(); ++k) list += (k ? ", " : "") + sorted[k];
  return list;
}

}  // namespace domel::platform
