// SPDX-License-Identifier: MIT
// Guards "defaults once" (issue 13, item 6): SchemaValidator::fill_defaults
// writes a schema's defaults into the instance (nested objects, arrays, $ref,
// allOf, the matching oneOf branch) and only where a key is absent; a default
// omitted from a scenario reaches the built Simulation as the schema states
// it; and the builders read no key with a second, in-code fallback.
#include "outputs/grid_files.hpp"
#include "outputs/state_files.hpp"
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "scenario/json_schema.hpp"
#include "scenario/scenario.hpp"
#include "support/fixture.hpp"

namespace {

using domel::platform::SchemaValidator;
using nlohmann::json;

TEST(FillDefaults, FillsAbsentKeysThroughObjectsArraysAndRefsAndReportsTheirPointers) {
  const json schema = json::parse(R"({
    "type": "object",
    "properties": {
      "run": { "$ref": "#/$defs/run", "default": {} },
      "items": { "type": "array", "items": { "$ref": "#/$defs/item" } },
      "given": { "type": "number", "default": 7 }
    },
    "$defs": {
      "run": { "type": "object", "properties": { "seed": { "type": "integer", "default": 1 },
                                                  "a/b": { "type": "string", "default": "x" } } },
      "item": { "type": "object", "properties": { "k": { "$ref": "#/$defs/k" } } },
      "k": { "type": "number", "default": 0.5 }
    }
  })");
  json doc = {{"items", {json::object(), {{"k", 2}}}}, {"given", 3}};
  const auto filled = SchemaValidator(schema).fill_defaults(doc, "/base");
  EXPECT_EQ(doc["run"], (json{{"seed", 1}, {"a/b", "x"}}));  // a filled object gets its own defaults
  EXPECT_EQ(doc["items"][0]["k"], 0.5);                       // default on the $ref target
  EXPECT_EQ(doc["items"][1]["k"], 2);                         // given values stay
  EXPECT_EQ(doc["given"], 3);
  ASSERT_EQ(filled.size(), 4u);
  EXPECT_EQ(filled[0], "/base/run");  // a parent before its members
  EXPECT_EQ(std::set<std::string>(filled.begin(), filled.end()),
            (std::set<std::string>{"/base/run", "/base/run/a~1b", "/base/run/seed", "/base/items/0/k"}));
}

TEST(FillDefaults, TakesTheOneOfBranchTheInstanceMatchesAndNoneWhenAmbiguous) {
  const json schema = json::parse(R"({
    "oneOf": [
      { "type": "object", "properties": { "model": { "const": "a" }, "p": { "default": 1 } }, "required": ["model"] },
      { "type": "object", "properties": { "model": { "const": "b" }, "q": { "default": 2 } }, "required": ["model"] }
    ]
  })");
  json a = {{"model", "a"}}, b = {{"model", "b"}}, neither = {{"model", "c"}};
  const SchemaValidator v(schema);
  v.fill_defaults(a);
  v.fill_defaults(b);
  v.fill_defaults(neither);
  EXPECT_EQ(a, (json{{"model", "a"}, {"p", 1}}));
  EXPECT_EQ(b, (json{{"model", "b"}, {"q", 2}}));
  EXPECT_EQ(neither, (json{{"model", "c"}}));
}

// A scenario that leaves out every key with a schema default.
json minimal_scenario() {
  json doc = domel::test::scenario(domel::test::hertz_mindlin(), 1e-5, 0.5, 0.5);
  doc.erase("gravity");
  doc.erase("output");
  doc["subdomains"][0].erase("contact");
  json region;
  region["box"] = {{"min", {0, 0, 0}}, {"max", {0.02, 0.02, 0.02}}};
  json insert = {{"model", "lattice"}, {"diameter", 0.004}, {"count", 8}};
  insert["region"] = region;
  doc["subdomains"][0]["insert"] = json::array({insert});
  doc["run"] = {{"steps", 2}};
  return doc;
}

TEST(FillDefaults, ASchemaDefaultReachesTheBuiltSimulation) {
  const json& defs = domel::platform::platform_scenario_schema()["$defs"];
  auto sim = domel::test::build(minimal_scenario());
  EXPECT_EQ(sim->seed, defs["run"]["properties"]["seed"]["default"].get<std::uint64_t>());
  EXPECT_EQ(sim->flow.deletion_interval, defs["run"]["properties"]["deletion_interval"]["default"].get<double>());
  const json gravity = domel::platform::platform_scenario_schema()["properties"]["gravity"]["default"];
  for (int a = 0; a < 3; ++a) EXPECT_EQ(sim->gravity[a], gravity[a].get<double>());
  const json& slots = defs["contact"]["properties"];
  EXPECT_EQ(sim->models_used["sd"]["normal"]["model"], slots["normal"]["default"]["model"]);
  EXPECT_EQ(sim->models_used["sd"]["tangential"]["model"], slots["tangential"]["default"]["model"]);
  EXPECT_FALSE(sim->models_used["sd"].contains("rolling"));  // default "none"
  // output.state's default (false): no state files' component
  EXPECT_FALSE(defs["output"]["properties"]["state"]["default"].get<bool>());
  EXPECT_EQ(sim->find<domel::platform::StateFiles>(), nullptr);
  EXPECT_EQ(sim->threads, 0);  // run.threads has no default: DOMEL_THREADS, else 1, at run time
  const auto& store = sim->subdomains[0]->store();
  ASSERT_EQ(store.size(), 8u);
  EXPECT_EQ(store.vx[0], 0.0);  // insert.velocity default
}

// A grid without write_interval was refused ("write_interval must be >= 0")
// although the reference gives its default, duration / 20 (issue 17, item 4):
// silo_ci's grids without the key validate and get it.
TEST(FillDefaults, ACellGridWithoutWriteIntervalGetsTheDocumentedDefault) {
  std::ifstream in(std::string(DOMEL_SOURCE_DIR) + "/scenarios/silo/silo_ci.json");
  json doc = json::parse(in);
  for (auto& g : doc["output"]["grids"]) g.erase("write_interval");
  auto sim = domel::test::build(doc);
  const auto* grids = sim->find<domel::platform::GridFiles>();
  ASSERT_NE(grids, nullptr);
  ASSERT_EQ(grids->setups().size(), 2u);
  for (const auto& g : grids->setups()) EXPECT_DOUBLE_EQ(g.spec.write_interval, sim->duration / 20.0);
}

// Every integer key of the composed schema (platform and built-in plugins)
// has a maximum: the builders and plugins read them into 32- or 64-bit
// integers, and a JSON number such as 1e26 is an integer by JSON Schema's
// rules, so without a maximum it would reach a conversion it overflows
// (docs/reliability.md).
TEST(FillDefaults, EveryIntegerKeyOfTheSchemaHasAMaximum) {
  const json schema = domel::platform::composed_scenario_schema(domel::test::builtin_registry());
  std::vector<std::string> missing;
  std::vector<std::pair<const json*, std::string>> todo = {{&schema, ""}};
  while (!todo.empty()) {
    const auto [node, path] = todo.back();
    todo.pop_back();
    if (node->is_object()) {
      const auto t = node->find("type");
      const bool integer = t != node->end() && (*t == "integer" || (t->is_array() && std::find(t->begin(), t->end(),
                                                                                               "integer") != t->end()));
      if (integer && !node->contains("maximum") && !node->contains("enum")) missing.push_back(path);
      for (const auto& [k, v] : node->items()) todo.push_back({&v, path + "/" + k});
    } else if (node->is_array()) {
      for (std::size_t k = 0; k < node->size(); ++k) todo.push_back({&(*node)[k], path + "/" + std::to_string(k)});
    }
  }
  EXPECT_TRUE(missing.empty()) << "integer keys without a maximum: " << ::testing::PrintToString(missing);
}

// 1e26 is an integer to JSON Schema; the seed's maximum refuses it instead
// of converting it to a 64-bit seed (undefined behaviour).
TEST(FillDefaults, AnIntegerBeyond64BitsIsRefusedNotConverted) {
  json doc = minimal_scenario();
  doc["run"]["seed"] = 1e26;
  EXPECT_THROW(domel::test::build(doc), domel::platform::ConfigError);
}

TEST(FillDefaults, AFilledWallDefaultOfAnotherWallTypeIsNotAnError) {
  // the wall schema is shared by every type: a plane gets "axis", "scale" and
  // "closed_top" filled, which the plane check must not call misplaced
  json doc = minimal_scenario();
  doc["walls"] = {{{"name", "floor"}, {"type", "plane"}, {"material", "m"}, {"point", {0, 0, 0}}, {"normal", {0, 0, 1}}}};
  EXPECT_NO_THROW(domel::test::build(doc));
  doc["walls"][0]["closed_top"] = false;  // written by the user: still refused
  EXPECT_THROW(domel::test::build(doc), domel::platform::ConfigError);
}

TEST(FillDefaults, TheBuildersReadNoKeyWithAnInCodeFallback) {
  // json::value(key, fallback) would be a second default next to the
  // schema's; an optional key without a schema default uses contains()
  for (const char* f : {"platform/scenario/builders.cpp", "platform/scenario/shapes.cpp", "platform/scenario/scenario.cpp"}) {
    std::ifstream in(std::string(DOMEL_SOURCE_DIR) + "/" + f);
    ASSERT_TRUE(in) << f;
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    std::smatch m;
    EXPECT_FALSE(std::regex_search(text, m, std::regex(R"(\.value\(|->value\()"))) << f << ": " << m.str();
  }
}

}  // namespace
