// SPDX-License-Identifier: MIT
// Guards the generated scenario reference (docs/scenario-reference.md,
// `domel docs`): every property of the composed schema, platform and
// built-in plugins, appears in a table row, so no key a scenario may use is
// undocumented (issue 17, item 7: pours, deletion regions, grids and
// mass-flow planes were once missing).
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scenario/reference.hpp"
#include "scenario/scenario.hpp"
#include "support/fixture.hpp"

namespace {

using nlohmann::json;

TEST(ScenarioReference, EveryPropertyOfTheSchemaHasARow) {
  const auto& registry = domel::test::builtin_registry();
  const json schema = domel::platform::composed_scenario_schema(registry);
  const std::string md = domel::platform::scenario_reference_markdown(registry);
  std::set<std::string> names;
  std::vector<const json*> todo = {&schema};
  while (!todo.empty()) {
    const json* node = todo.back();
    todo.pop_back();
    if (node->is_object()) {
      if (const auto p = node->find("properties"); p != node->end() && p->is_object())
        for (const auto& [k, v] : p->items()) names.insert(k);
      for (const auto& [k, v] : node->items()) todo.push_back(&v);
    } else if (node->is_array()) {
      for (const auto& v : *node) todo.push_back(&v);
    }
  }
  ASSERT_GT(names.size(), 100u);
  for (const char* key : {"pour", "deletion_regions", "grids", "mass_flow", "checkpoint_interval",
                          "max_initial_overlap"})
    EXPECT_TRUE(names.count(key)) << key << " is not in the schema any more";
  std::vector<std::string> missing;
  for (const auto& n : names)
    if (md.find("| `" + n + "` |") == std::string::npos) missing.push_back(n);
  EXPECT_TRUE(missing.empty()) << "keys without a row in the reference: " << ::testing::PrintToString(missing);
}

}  // namespace
