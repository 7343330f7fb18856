// SPDX-License-Identifier: MIT
// Typed errors of the platform. A ConfigError carries where (file, JSON
// pointer), what was expected, what was found and a hint; the CLI formats it.
// Library code throws these and never calls exit() or abort().
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace domel::platform {

/// One problem found in a scenario (or plugin parameter block).
struct Diagnostic {
  std::string file;      ///< scenario file, may be empty for in-memory input
  std::string pointer;   ///< JSON pointer, e.g. "/subdomains/0/contact/normal/model"
  std::string message;   ///< what was expected and what was found
  std::string hint;      ///< "did you mean 'hertz'?" or the list of valid names; may be empty

  /// "file: at /a/b: message (hint)"
  std::string format() const;
};

/// Thrown when a scenario cannot be accepted; holds every problem found.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

/// Thrown when a plugin library is refused or a plugin call fails.
class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thrown when the simulation cannot go on (e.g. a particle left every wall).
class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Levenshtein distance, for "did you mean".
std::size_t edit_distance(const std::string& a, const std::string& b);

/// "did you mean 'x'?" when one candidate is close, otherwise
/// "valid names: a, b, c"; empty when there are no candidates.
std::string suggest(const std::string& found, const std::vector<std::string>& candidates);

}  // namespace domel::platform
