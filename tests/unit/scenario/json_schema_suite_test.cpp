// SPDX-License-Identifier: MIT
// Runs SchemaValidator against the official JSON-Schema-Test-Suite (Debian
// package json-schema-test-suite, draft-07 files) for every keyword it
// supports, so that its verdicts agree with the specification and not only
// with our own reading of it. Each file is one test case; it prints how many
// cases ran and how many groups were skipped, and insists on a minimum number
// of cases so that it cannot pass by skipping everything.
#include <gtest/gtest.h>

#include <cstddef>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scenario/json_schema.hpp"

#ifndef DOMEL_JSON_SCHEMA_TEST_SUITE
#define DOMEL_JSON_SCHEMA_TEST_SUITE "/usr/share/json-schema-test-suite"
#endif

namespace {

using domel::platform::Diagnostic;
using domel::platform::SchemaValidator;
using nlohmann::json;

struct SuiteFile {
  const char* name;                ///< file in tests/draft7, without ".json"
  std::size_t min_cases;           ///< at least this many cases must run
  std::size_t max_skipped_groups;  ///< at most this many groups may be skipped
};

// Minimums are what the suite 2.0.0 (Debian 2.0.0-1.1) gives; "(of N)" is the
// file's total. Every group runs except these (printed when the test runs):
//  properties, additionalProperties: 1 and 2 groups use "patternProperties";
//  items: 2 groups use the array form of "items" (one schema per position);
//  ref: "relative pointer ref to array" (array-form items), "escaped pointer
//       ref" (its ref targets sit under root keys that are not keywords, which
//       the constructor refuses; our own tests cover ~0, ~1 and %-escapes),
//       "ref overrides any sibling keywords" (draft-07 semantics, see below),
//       the remote ref and the "$id"-based "Recursive references" group.
const SuiteFile kFiles[] = {
    {"type", 59, 0},                 // (of 59)
    {"properties", 10, 1},           // (of 18)
    {"required", 7, 0},              // (of 7)
    {"additionalProperties", 6, 2},  // (of 14)
    {"enum", 9, 0},                  // (of 9)
    {"const", 12, 0},                // (of 12)
    {"minimum", 4, 0},               // (of 4)
    {"maximum", 4, 0},               // (of 4)
    {"exclusiveMinimum", 4, 0},      // (of 4)
    {"exclusiveMaximum", 4, 0},      // (of 4)
    {"minItems", 4, 0},              // (of 4)
    {"maxItems", 4, 0},              // (of 4)
    {"items", 8, 2},                 // (of 17)
    {"minLength", 5, 0},             // (of 5)
    {"maxLength", 5, 0},             // (of 5)
    {"oneOf", 15, 0},                // (of 15)
    {"anyOf", 14, 0},                // (of 14)
    {"allOf", 14, 0},                // (of 14)
    {"not", 12, 0},                  // (of 12)
    {"ref", 12, 5},                  // (of 27)
    {"boolean_schema", 18, 0},       // (of 18)
};

// Lets GoogleTest name the parameter instead of dumping its bytes.
void PrintTo(const SuiteFile& file, std::ostream* os) { *os << file.name; }

bool is_ignored_sibling(const std::string& k) {
  return k == "$ref" || k == "$defs" || k == "definitions" || k == "$schema" || k == "$id" ||
         k == "title" || k == "description" || k == "default" || k == "examples" ||
         k == "$comment" || k.rfind("x-", 0) == 0;
}

// True when some schema object holds "$ref" next to a keyword that validates.
// Draft-07 ignores every sibling of "$ref"; SchemaValidator applies them (as
// 2020-12 does), so such a group would test a rule we deliberately differ on.
// Walks only schema positions (not enum/const values).
bool has_ref_with_validating_sibling(const json& s) {
  if (!s.is_object()) return false;
  if (s.contains("$ref")) {
    for (auto it = s.begin(); it != s.end(); ++it) {
      if (!is_ignored_sibling(it.key())) return true;
    }
  }
  for (const char* k : {"properties", "$defs", "definitions"}) {
    if (auto m = s.find(k); m != s.end() && m->is_object()) {
      for (const auto& sub : *m) {
        if (has_ref_with_validating_sibling(sub)) return true;
      }
    }
  }
  for (const char* k : {"additionalProperties", "items", "not"}) {
    if (auto m = s.find(k); m != s.end()) {
      if (m->is_array()) {
        for (const auto& sub : *m) {
          if (has_ref_with_validating_sibling(sub)) return true;
        }
      } else if (has_ref_with_validating_sibling(*m)) {
        return true;
      }
    }
  }
  for (const char* k : {"allOf", "anyOf", "oneOf"}) {
    if (auto m = s.find(k); m != s.end() && m->is_array()) {
      for (const auto& sub : *m) {
        if (has_ref_with_validating_sibling(sub)) return true;
      }
    }
  }
  return false;
}

class JsonSchemaSuite : public ::testing::TestWithParam<SuiteFile> {};

// Guards agreement with the official draft-07 suite for one keyword's file.
// Skipping rule: a group is skipped when its schema cannot be used as written,
// i.e. SchemaValidator's constructor throws std::invalid_argument (a keyword
// outside the supported set anywhere in the schema, the array form of
// "items", a remote or "$id"-relative $ref, "$id" below the root), or when it
// puts a validating keyword next to "$ref" (draft-07 ignores those siblings,
// we apply them). Every case of every other group must give the expected
// verdict, both from is_valid() and from validate().
TEST_P(JsonSchemaSuite, Draft7File) {
  const SuiteFile& file = GetParam();
  const std::string path =
      std::string(DOMEL_JSON_SCHEMA_TEST_SUITE) + "/tests/draft7/" + file.name + ".json";
  std::ifstream in(path);
  ASSERT_TRUE(in) << "cannot open " << path << " (install the json-schema-test-suite package)";
  const json groups = json::parse(in);

  std::size_t cases_run = 0;
  std::vector<std::string> skipped;
  for (const auto& group : groups) {
    const std::string description = group.at("description").get<std::string>();
    const json& schema = group.at("schema");
    if (has_ref_with_validating_sibling(schema)) {
      skipped.push_back(description + ": draft-07 ignores siblings of $ref");
      continue;
    }
    try {
      const SchemaValidator validator(schema);
      for (const auto& test : group.at("tests")) {
        const bool expected = test.at("valid").get<bool>();
        const json& data = test.at("data");
        const std::string where = std::string(file.name) + " / " + description + " / " +
                                  test.at("description").get<std::string>();
        EXPECT_EQ(validator.is_valid(data), expected) << where;
        std::vector<Diagnostic> diagnostics;
        validator.validate(data, diagnostics);
        EXPECT_EQ(diagnostics.empty(), expected) << where;
        for (const auto& d : diagnostics) EXPECT_FALSE(d.message.empty()) << where;
        ++cases_run;
      }
    } catch (const std::invalid_argument& e) {
      skipped.push_back(description + ": " + e.what());
    }
  }

  std::cout << file.name << ": " << cases_run << " cases run, " << skipped.size()
            << " groups skipped\n";
  for (const auto& s : skipped) std::cout << "  skipped " << s << "\n";
  EXPECT_GE(cases_run, file.min_cases) << file.name;
  EXPECT_LE(skipped.size(), file.max_skipped_groups) << file.name;
}

INSTANTIATE_TEST_SUITE_P(Draft7, JsonSchemaSuite, ::testing::ValuesIn(kFiles),
                         [](const ::testing::TestParamInfo<SuiteFile>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
