// SPDX-License-Identifier: MIT
// Formatting of diagnostics and the "did you mean" helper (edit distance, as
// preCICE's computeMatches does; the full sorted list otherwise, as OpenFOAM).
#include "core/error.hpp"

#include <algorithm>
#include <numeric>

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
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  std::iota(prev.begin(), prev.end(), 0);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
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
