// SPDX-License-Identifier: MIT
// Guards the wording and completeness of scenario diagnostics: every bad
// scenario in tests/config/cases/*.json is loaded with load_scenario (all
// validation passes plus the build stage) and must be refused with exactly
// the diagnostics listed in its <name>.expected.txt, each in the scenario's
// file. One test per case; the folder is read when the test program starts,
// so adding a case means adding two files (then rebuilding, so that ctest
// lists the new test).
//
// <name>.expected.txt holds one expected diagnostic per line:
//   <json pointer> | <substring of the message> | <substring of the hint>
// The pointer must match exactly (empty for the document root), the other two
// fields are substrings (an empty field matches anything). Blank lines and
// lines starting with '#' are ignored. The order of lines does not matter, but
// every line must match a different diagnostic and the number of diagnostics
// must equal the number of lines.
#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
namespace dp = domel::platform;

const fs::path kCaseDir = fs::path(DOMEL_SOURCE_DIR) / "tests" / "config" / "cases";

struct Expected {
  int line = 0;
  std::string pointer;
  std::string message;
  std::string hint;
  std::string text;  ///< the line as written, for failure messages
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

/// Case names (file stems of *.json), sorted.
std::vector<std::string> case_names() {
  std::vector<std::string> names;
  if (!fs::is_directory(kCaseDir)) return names;
  for (const auto& entry : fs::directory_iterator(kCaseDir))
    if (entry.is_regular_file() && entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// Parses an .expected.txt file; a malformed line is reported through `errors`.
std::vector<Expected> read_expected(const fs::path& file, std::vector<std::string>& errors) {
  std::vector<Expected> out;
  std::ifstream in(file);
  if (!in) {
    errors.push_back("cannot open " + file.string());
    return out;
  }
  std::string raw;
  for (int n = 1; std::getline(in, raw); ++n) {
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    // Fields are separated by '|'; the first two separators split the line
    // (a hint may itself contain '|', a pointer or message may not).
    const auto a = raw.find('|');
    const auto b = a == std::string::npos ? std::string::npos : raw.find('|', a + 1);
    if (b == std::string::npos) {
      errors.push_back(file.filename().string() + ":" + std::to_string(n) +
                       ": expected '<pointer> | <message> | <hint>', found '" + line + "'");
      continue;
    }
    out.push_back({n, trim(raw.substr(0, a)), trim(raw.substr(a + 1, b - a - 1)), trim(raw.substr(b + 1)), line});
  }
  return out;
}

bool matches(const Expected& e, const dp::Diagnostic& d) {
  return d.pointer == e.pointer && d.message.find(e.message) != std::string::npos &&
         d.hint.find(e.hint) != std::string::npos;
}

/// Maximum bipartite matching of expected lines to diagnostics (each
/// diagnostic used once). Returns, per expected line, the diagnostic index or -1.
std::vector<int> match_all(const std::vector<Expected>& expected, const std::vector<dp::Diagnostic>& diags) {
  std::vector<int> owner(diags.size(), -1);  // diagnostic -> expected line
  std::function<bool(std::size_t, std::vector<bool>&)> augment = [&](std::size_t e, std::vector<bool>& seen) {
    for (std::size_t d = 0; d < diags.size(); ++d) {
      if (seen[d] || !matches(expected[e], diags[d])) continue;
      seen[d] = true;
      if (owner[d] < 0 || augment(static_cast<std::size_t>(owner[d]), seen)) {
        owner[d] = static_cast<int>(e);
        return true;
      }
    }
    return false;
  };
  for (std::size_t e = 0; e < expected.size(); ++e) {
    std::vector<bool> seen(diags.size(), false);
    augment(e, seen);
  }
  std::vector<int> result(expected.size(), -1);
  for (std::size_t d = 0; d < diags.size(); ++d)
    if (owner[d] >= 0) result[static_cast<std::size_t>(owner[d])] = static_cast<int>(d);
  return result;
}

std::string describe(const std::vector<dp::Diagnostic>& diags) {
  std::ostringstream os;
  os << "actual diagnostics (" << diags.size() << "):\n";
  for (const auto& d : diags) os << "  " << d.format() << "\n";
  os << "as .expected.txt lines:\n";
  for (const auto& d : diags) os << "  " << d.pointer << " | " << d.message << " | " << d.hint << "\n";
  return os.str();
}

class ConfigCorpus : public ::testing::TestWithParam<std::string> {};

TEST_P(ConfigCorpus, RefusedWithExpectedDiagnostics) {
  const fs::path scenario = kCaseDir / (GetParam() + ".json");
  const fs::path expected_file = kCaseDir / (GetParam() + ".expected.txt");
  std::vector<std::string> errors;
  const auto expected = read_expected(expected_file, errors);
  for (const auto& e : errors) ADD_FAILURE() << e;
  ASSERT_TRUE(errors.empty());
  ASSERT_FALSE(expected.empty()) << expected_file << " lists no diagnostic; a bad case must expect at least one";

  dp::PluginRegistry registry;
  registry.load_directory(DOMEL_BINARY_DIR "/plugins");
  ASSERT_FALSE(registry.libraries().empty()) << "no plugins found in " DOMEL_BINARY_DIR "/plugins";

  std::vector<dp::Diagnostic> diags;
  try {
    dp::load_scenario(scenario, registry);
    FAIL() << scenario << " was accepted; expected a ConfigError with " << expected.size() << " diagnostic(s)";
  } catch (const dp::ConfigError& e) {
    diags = e.diagnostics();
  }
  const std::string actual = describe(diags);

  EXPECT_EQ(diags.size(), expected.size()) << "number of diagnostics of " << scenario.filename() << "\n" << actual;
  const auto found = match_all(expected, diags);
  for (std::size_t k = 0; k < expected.size(); ++k)
    EXPECT_GE(found[k], 0) << expected_file.filename().string() << ":" << expected[k].line
                           << ": no (distinct) diagnostic matches '" << expected[k].text << "'\n"
                           << actual;
  for (const auto& d : diags)
    EXPECT_EQ(d.file, scenario.string()) << "file field of the diagnostic '" << d.format() << "'";
}

std::string case_test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(Cases, ConfigCorpus, ::testing::ValuesIn(case_names()), case_test_name);

// Every case has both files, and the corpus is not empty (a wrong folder
// would otherwise make the parameterised suite silently run nothing).
TEST(ConfigCorpusFiles, EveryCaseHasBothFiles) {
  const auto names = case_names();
  EXPECT_GE(names.size(), 20u) << "cases expected in " << kCaseDir;
  for (const auto& n : names)
    EXPECT_TRUE(fs::is_regular_file(kCaseDir / (n + ".expected.txt"))) << n << ".json has no " << n << ".expected.txt";
  for (const auto& entry : fs::directory_iterator(kCaseDir)) {
    const std::string f = entry.path().filename().string();
    const std::string suffix = ".expected.txt";
    if (f.size() <= suffix.size() || f.compare(f.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
    const std::string stem = f.substr(0, f.size() - suffix.size());
    EXPECT_TRUE(fs::is_regular_file(kCaseDir / (stem + ".json"))) << f << " has no " << stem << ".json";
  }
}

}  // namespace
