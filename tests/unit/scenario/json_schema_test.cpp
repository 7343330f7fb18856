// SPDX-License-Identifier: MIT
// Unit tests of SchemaValidator (platform/scenario/json_schema): the exact
// wording of every message users read, the JSON pointers (RFC 6901 escaping,
// base pointer), did-you-mean hints, collecting every problem at once, the
// choice of branch reported for oneOf/anyOf, local $ref resolution, ignored
// annotation keywords, and refusing unsupported keywords or malformed schemas
// when the validator is constructed. Agreement with the specification itself
// is checked by json_schema_suite_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "scenario/json_schema.hpp"

namespace {

using domel::platform::Diagnostic;
using domel::platform::SchemaValidator;
using domel::platform::suggest;
using domel::platform::supported_schema_keywords;
using nlohmann::json;

std::vector<Diagnostic> check(const json& schema, const json& instance,
                              const std::string& base = "") {
  std::vector<Diagnostic> out;
  const SchemaValidator validator(schema);
  validator.validate(instance, out, base);
  EXPECT_EQ(validator.is_valid(instance), out.empty()) << "is_valid() disagrees with validate()";
  return out;
}

// Message of the constructor's std::invalid_argument, or "" when it accepts the schema.
std::string construction_error(const json& schema) {
  try {
    const SchemaValidator validator(schema);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

const json kMaterial = json::parse(R"({
  "type": "object",
  "properties": {
    "density": { "type": "number", "exclusiveMinimum": 0, "x-unit": "kg/m^3", "description": "particle density" },
    "youngs_modulus": { "type": "number", "exclusiveMinimum": 0, "x-unit": "Pa" },
    "poisson_ratio": { "type": "number", "minimum": -1, "exclusiveMaximum": 0.5 }
  },
  "required": ["density", "youngs_modulus"],
  "additionalProperties": false
})");

}  // namespace

// Guards the wording and pointer of a missing required property, with its description appended.
TEST(JsonSchema, MissingRequiredNamesPropertyAndDescription) {
  const auto d = check(kMaterial, json{{"youngs_modulus", 1e9}}, "/materials/steel");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/materials/steel");
  EXPECT_EQ(d[0].message, "missing required property 'density' \u2014 particle density");
  EXPECT_EQ(d[0].hint, "");
  EXPECT_EQ(d[0].file, "");
}

// Guards that a property without description gets the bare message, and that $ref is followed for
// it.
TEST(JsonSchema, MissingRequiredWithoutOrBehindRefDescription) {
  const auto bare = check(kMaterial, json{{"density", 1}});
  ASSERT_EQ(bare.size(), 1u);
  EXPECT_EQ(bare[0].message, "missing required property 'youngs_modulus'");
  const json schema = json::parse(R"({
    "$defs": { "run": { "type": "object", "description": "run control" } },
    "properties": { "run": { "$ref": "#/$defs/run" } },
    "required": ["run"]
  })");
  const auto behind = check(schema, json::object());
  ASSERT_EQ(behind.size(), 1u);
  EXPECT_EQ(behind[0].message, "missing required property 'run' \u2014 run control");
}

// Guards additionalProperties:false: pointer of the unknown key, message and did-you-mean hint.
TEST(JsonSchema, UnknownPropertyWithDidYouMean) {
  const auto d =
      check(kMaterial, json{{"density", 1}, {"youngs_modulus", 1}, {"densty", 2}}, "/materials/a");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/materials/a/densty");
  EXPECT_EQ(d[0].message, "unknown property 'densty'");
  EXPECT_EQ(d[0].hint, "did you mean 'density'?");
  const auto far = check(kMaterial, json{{"density", 1}, {"youngs_modulus", 1}, {"colour", 2}});
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].hint, suggest("colour", {"density", "youngs_modulus", "poisson_ratio"}));
  EXPECT_EQ(far[0].hint, "valid: density, poisson_ratio, youngs_modulus");
}

// Guards additionalProperties given as a schema: extra values are validated at their own pointer.
TEST(JsonSchema, AdditionalPropertiesSchema) {
  const json schema = {{"type", "object"}, {"additionalProperties", {{"type", "string"}}}};
  const auto d = check(schema, json{{"a", "ok"}, {"b", 3}});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/b");
  EXPECT_EQ(d[0].message, "expected a string, found 3");
}

// Guards the type message: expected type, found value shown compactly with strings quoted.
TEST(JsonSchema, TypeMismatchShowsFoundValue) {
  EXPECT_EQ(check({{"type", "number"}}, "abc").at(0).message,
            "expected a number, found a string (\"abc\")");
  EXPECT_EQ(check({{"type", "string"}}, true).at(0).message, "expected a string, found true");
  EXPECT_EQ(check({{"type", "string"}}, nullptr).at(0).message, "expected a string, found null");
  EXPECT_EQ(check({{"type", "object"}}, json::array({1, 2})).at(0).message,
            "expected an object, found an array ([1,2])");
  EXPECT_EQ(check({{"type", "array"}}, json{{"a", 1}}).at(0).message,
            "expected an array, found an object ({\"a\":1})");
  EXPECT_EQ(check({{"type", {"string", "number", "null"}}}, false).at(0).message,
            "expected a string, a number or null, found false");
}

// Guards "integer": a zero fractional part counts (1.0), 2.5 is reported as such.
TEST(JsonSchema, IntegerType) {
  EXPECT_TRUE(check({{"type", "integer"}}, 1.0).empty());
  EXPECT_TRUE(check({{"type", "integer"}}, -7).empty());
  const auto d = check({{"type", "integer"}}, 2.5);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].message, "expected an integer, found 2.5");
  EXPECT_EQ(check({{"type", "number"}}, 2.5).size(), 0u);
}

// Guards that long found values are truncated (about 40 characters) in messages.
TEST(JsonSchema, LongValuesAreTruncated) {
  const std::string long_text(200, 'a');
  const auto d = check({{"type", "number"}}, long_text);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_LT(d[0].message.size(), 90u);
  EXPECT_NE(d[0].message.find("aaa...\")"), std::string::npos) << d[0].message;
  json big = json::array();
  for (int i = 0; i < 100; ++i) big.push_back(i);
  const auto a = check({{"type", "object"}}, big);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_LT(a[0].message.size(), 90u);
  EXPECT_NE(a[0].message.find("...)"), std::string::npos) << a[0].message;
}

// Guards the four bound messages and their comparison operators.
TEST(JsonSchema, NumericBoundMessages) {
  EXPECT_EQ(check({{"exclusiveMinimum", 0}}, -3).at(0).message, "expected a number > 0, found -3");
  EXPECT_EQ(check({{"minimum", 0}}, -0.5).at(0).message, "expected a number >= 0, found -0.5");
  EXPECT_EQ(check({{"maximum", 1}}, 2).at(0).message, "expected a number <= 1, found 2");
  EXPECT_EQ(check({{"exclusiveMaximum", 90}}, 90).at(0).message,
            "expected a number < 90, found 90");
  EXPECT_TRUE(check({{"minimum", 0}}, 0).empty());
  EXPECT_TRUE(check({{"maximum", 1}}, 1.0).empty());
  EXPECT_EQ(check({{"exclusiveMinimum", 0}}, 0).size(), 1u);
  // An integer schema says so; bounds ignore non-numbers.
  EXPECT_EQ(check({{"type", "integer"}, {"minimum", 1}}, 0).at(0).message,
            "expected an integer >= 1, found 0");
  EXPECT_TRUE(check({{"minimum", 1}}, "text").empty());
}

// Guards that x-unit is shown in bound messages, also when it sits on the schema holding the $ref.
TEST(JsonSchema, BoundMessagesShowUnit) {
  const auto d = check(kMaterial, json{{"density", 1}, {"youngs_modulus", -3}});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/youngs_modulus");
  EXPECT_EQ(d[0].message, "expected a number > 0 [Pa], found -3");
  const json schema = json::parse(R"({
    "$defs": { "positive": { "type": "number", "exclusiveMinimum": 0 } },
    "properties": { "radius": { "$ref": "#/$defs/positive", "x-unit": "m" } }
  })");
  EXPECT_EQ(check(schema, json{{"radius", 0}}).at(0).message, "expected a number > 0 [m], found 0");
  // "1" (dimensionless) is not shown.
  EXPECT_EQ(check({{"maximum", 1}, {"x-unit", "1"}}, 1.5).at(0).message,
            "expected a number <= 1, found 1.5");
}

// Guards enum: the allowed values listed, the found one quoted, did-you-mean for strings.
TEST(JsonSchema, EnumMessageAndHint) {
  const json schema = {{"enum", {"plane", "box", "cylinder"}}};
  const auto typo = check(schema, "cylindr");
  ASSERT_EQ(typo.size(), 1u);
  EXPECT_EQ(typo[0].message, "expected one of 'plane', 'box', 'cylinder', found 'cylindr'");
  EXPECT_EQ(typo[0].hint, "did you mean 'cylinder'?");
  // no close match: no hint, the message already lists every valid value
  const auto other = check(schema, "sphere");
  EXPECT_EQ(other.at(0).hint, "");
  const auto number = check(schema, 3);
  EXPECT_EQ(number.at(0).message, "expected one of 'plane', 'box', 'cylinder', found 3");
  EXPECT_EQ(number.at(0).hint, "");
  EXPECT_TRUE(check(schema, "box").empty());
  EXPECT_TRUE(check({{"enum", {1, 2}}}, 2.0).empty());
}

// Guards const: expected and found values quoted.
TEST(JsonSchema, ConstMessage) {
  const auto d = check({{"const", "hertz"}}, "hurtz");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].message, "expected 'hertz', found 'hurtz'");
  EXPECT_EQ(check({{"const", 3}}, 4).at(0).message, "expected 3, found 4");
  EXPECT_TRUE(check({{"const", "hertz"}}, "hertz").empty());
}

// Guards array-size messages: at least / at most / exactly (3-vectors), with singular and plural.
TEST(JsonSchema, ItemCountMessages) {
  const json vec3 = {
      {"type", "array"}, {"items", {{"type", "number"}}}, {"minItems", 3}, {"maxItems", 3}};
  EXPECT_EQ(check(vec3, json::array({1, 2})).at(0).message,
            "expected an array of exactly 3 items, found 2");
  EXPECT_EQ(check(vec3, json::array({1, 2, 3, 4})).at(0).message,
            "expected an array of exactly 3 items, found 4");
  EXPECT_EQ(check({{"minItems", 3}}, json::array({1, 2})).at(0).message,
            "expected an array of at least 3 items, found 2 items");
  EXPECT_EQ(check({{"maxItems", 2}}, json::array({1, 2, 3})).at(0).message,
            "expected an array of at most 2 items, found 3 items");
  EXPECT_EQ(check({{"minItems", 1}}, json::array()).at(0).message,
            "expected an array of at least 1 item, found 0 items");
  EXPECT_TRUE(check(vec3, json::array({1, 2, 3})).empty());
}

// Guards string-length messages and that lengths count Unicode code points, not bytes.
TEST(JsonSchema, StringLengthCountsCodePoints) {
  EXPECT_EQ(check({{"minLength", 1}}, "").at(0).message,
            "expected a string of at least 1 character, found 0 characters (\"\")");
  EXPECT_EQ(check({{"maxLength", 2}}, "abc").at(0).message,
            "expected a string of at most 2 characters, found 3 characters (\"abc\")");
  EXPECT_EQ(check({{"minLength", 2}, {"maxLength", 2}}, "a").at(0).message,
            "expected a string of exactly 2 characters, found 1 (\"a\")");
  EXPECT_TRUE(check({{"maxLength", 2}}, "\u00e9\u00e9").empty());      // 4 bytes, 2 code points
  EXPECT_TRUE(check({{"maxLength", 1}}, "\xF0\x9F\x92\xA9").empty());  // one 4-byte code point
  EXPECT_EQ(check({{"minLength", 2}}, "\xF0\x9F\x92\xA9").size(), 1u);
}

// Guards oneOf reporting the branch whose type matches the instance (time_step: number or "auto").
TEST(JsonSchema, OneOfReportsBranchOfMatchingType) {
  const json schema = json::parse(R"({
    "properties": { "time_step": { "oneOf": [
      { "type": "number", "exclusiveMinimum": 0, "x-unit": "s" }, { "const": "auto" } ] } }
  })");
  const auto text = check(schema, json{{"time_step", "auto2"}});
  ASSERT_EQ(text.size(), 1u);
  EXPECT_EQ(text[0].pointer, "/time_step");
  EXPECT_EQ(text[0].message, "expected 'auto', found 'auto2'");
  const auto number = check(schema, json{{"time_step", -1}});
  ASSERT_EQ(number.size(), 1u);
  EXPECT_EQ(number[0].message, "expected a number > 0 [s], found -1");
  EXPECT_TRUE(check(schema, json{{"time_step", "auto"}}).empty());
  EXPECT_TRUE(check(schema, json{{"time_step", 1e-5}}).empty());
}

// Guards the generic oneOf message (no branch stands out) and its per-form summary hint.
TEST(JsonSchema, OneOfWithoutClearBranch) {
  const json schema = json::parse(R"({
    "type": "object",
    "properties": { "duration": { "type": "number" }, "steps": { "type": "integer" } },
    "oneOf": [ { "required": ["duration"] }, { "required": ["steps"] } ]
  })");
  const auto none = check(schema, json::object(), "/run");
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0].pointer, "/run");
  // branches that only require a key: "give one of these keys", in those words
  EXPECT_EQ(none[0].message, "missing required property: expected one of 'duration' or 'steps', found none");
  EXPECT_EQ(none[0].hint, "give one of them");
  // other forms that none matches: the generic message naming each form's problem
  const json forms = json::parse(R"({
    "type": "object",
    "oneOf": [ { "required": ["duration"], "properties": { "duration": { "type": "number" } } },
               { "required": ["steps"] } ]
  })");
  const auto other = check(forms, json::object(), "/run");
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0].message, "does not match any of the allowed forms");
  EXPECT_EQ(other[0].hint, "form 1: missing required property 'duration'; form 2: missing required property 'steps'");
}

// Guards oneOf matched by several branches.
TEST(JsonSchema, OneOfMatchingSeveralForms) {
  // "exactly one of these keys" (branches that only require a key) is said in those words
  const json schema = {{"oneOf", {{{"required", {"box"}}}, {{"required", {"cylinder"}}}}}};
  const auto d = check(schema, json{{"box", 1}, {"cylinder", 2}}, "/region");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/region");
  EXPECT_EQ(d[0].message, "expected exactly one of 'box' or 'cylinder', found 'box' and 'cylinder'");
  EXPECT_EQ(d[0].hint, "remove all but one of them");
  EXPECT_TRUE(check(schema, json{{"box", 1}}).empty());
  // other overlapping forms: the generic message naming the forms
  const json general = {{"oneOf", {{{"type", "number"}}, {{"minimum", 0}}}}};
  const auto g = check(general, 3);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].message, "matches more than one of the allowed forms");
  EXPECT_EQ(g[0].hint, "matching forms: 1, 2");
}

// Guards anyOf reporting the only branch with the fewest errors, and anyOf accepting any match.
TEST(JsonSchema, AnyOfReportsBranchWithFewestErrors) {
  const json schema = json::parse(R"({ "anyOf": [
    { "type": "object", "required": ["a", "b"] }, { "type": "object", "required": ["c"] } ] })");
  const auto d = check(schema, json::object());
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].message, "missing required property 'c'");
  EXPECT_TRUE(check(schema, json{{"a", 1}, {"b", 1}}).empty());
  EXPECT_TRUE(check(schema, json{{"c", 1}}).empty());
}

// Guards allOf applying every branch and not reporting the same problem twice.
TEST(JsonSchema, AllOfCollectsAndDeduplicates) {
  const json schema = {{"allOf", {{{"minimum", 0}}, {{"minimum", 0}}, {{"type", "integer"}}}}};
  const auto d = check(schema, -1.5);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].message, "expected a number >= 0, found -1.5");
  EXPECT_EQ(d[1].message, "expected an integer, found -1.5");
}

// Guards the messages of "not" and of a false schema.
TEST(JsonSchema, NotAndFalseSchema) {
  EXPECT_EQ(check({{"not", {{"type", "string"}}}}, "x").at(0).message,
            "expected a value that does not match the excluded form, found a string (\"x\")");
  EXPECT_TRUE(check({{"not", {{"type", "string"}}}}, 1).empty());
  const auto d = check({{"properties", {{"legacy", false}}}}, json{{"legacy", 1}});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/legacy");
  EXPECT_EQ(d[0].message, "no value is allowed here, found 1");
  EXPECT_TRUE(check(true, json{{"anything", 1}}).empty());
}

// Guards RFC 6901 escaping of keys ("/" -> "~1", "~" -> "~0"), array indices and the base pointer.
TEST(JsonSchema, PointerEscaping) {
  const json schema = {{"properties",
                        {{"a/b", {{"type", "string"}}},
                         {"m~n", {{"type", "string"}}},
                         {"list", {{"items", {{"type", "string"}}}}}}},
                       {"additionalProperties", false}};
  const auto d =
      check(schema, json{{"a/b", 1}, {"m~n", 2}, {"list", {"x", 3}}, {"x/~y", 0}}, "/subdomains/0");
  ASSERT_EQ(d.size(), 4u);
  std::vector<std::string> pointers;
  for (const auto& x : d) pointers.push_back(x.pointer);
  EXPECT_EQ(pointers, (std::vector<std::string>{"/subdomains/0/a~1b", "/subdomains/0/list/1",
                                                "/subdomains/0/m~0n", "/subdomains/0/x~1~0y"}));
}

// Guards that every problem is collected in one pass, not only the first.
TEST(JsonSchema, CollectsAllErrors) {
  const auto d =
      check(kMaterial, json{{"densty", 1}, {"youngs_modulus", -3}, {"poisson_ratio", "x"}});
  ASSERT_EQ(d.size(), 4u);
  auto has = [&](const std::string& pointer, const std::string& message) {
    for (const auto& x : d) {
      if (x.pointer == pointer && x.message == message) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("", "missing required property 'density' \u2014 particle density"));
  EXPECT_TRUE(has("/densty", "unknown property 'densty'"));
  EXPECT_TRUE(has("/youngs_modulus", "expected a number > 0 [Pa], found -3"));
  EXPECT_TRUE(has("/poisson_ratio", "expected a number, found a string (\"x\")"));
}

// Guards that a value of the wrong type gets one message, not its children's or siblings' errors.
TEST(JsonSchema, WrongTypeSuppressesChildErrors) {
  const json schema = {{"properties", {{"material", kMaterial}}}, {"required", {"material"}}};
  const auto d = check(schema, json{{"material", json::array({1})}});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].pointer, "/material");
  EXPECT_EQ(d[0].message, "expected an object, found an array ([1])");
  // Also with oneOf next to the type: no "matches more than one" noise.
  const json region = {{"type", "object"},
                       {"oneOf", {{{"required", {"box"}}}, {{"required", {"cylinder"}}}}}};
  EXPECT_EQ(check(region, 5).size(), 1u);
}

// Guards $ref into $defs and definitions, with ~0, ~1 and %-escapes, and recursion through "#".
TEST(JsonSchema, LocalRefs) {
  const json schema = json::parse(R"({
    "$defs": { "vec3": { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3 },
               "a/b": { "type": "integer" }, "c~d": { "type": "string" }, "e%f": { "type": "boolean" } },
    "definitions": { "name": { "type": "string", "minLength": 1 } },
    "properties": {
      "gravity": { "$ref": "#/$defs/vec3" },
      "n": { "$ref": "#/$defs/a~1b" }, "s": { "$ref": "#/$defs/c~0d" }, "b": { "$ref": "#/$defs/e%25f" },
      "name": { "$ref": "#/definitions/name" },
      "child": { "$ref": "#" }
    }
  })");
  EXPECT_TRUE(
      check(schema,
            json{{"gravity", {0, 0, -9.81}}, {"n", 1}, {"s", "x"}, {"b", true}, {"name", "a"}})
          .empty());
  const auto d =
      check(schema, json{{"gravity", {0, 0, "z"}}, {"n", 1.5}, {"s", 1}, {"b", 0}, {"name", ""}});
  ASSERT_EQ(d.size(), 5u);
  EXPECT_EQ(d[0].pointer, "/b");
  EXPECT_EQ(d[1].pointer, "/gravity/2");
  EXPECT_EQ(d[1].message, "expected a number, found a string (\"z\")");
  EXPECT_EQ(d[2].message, "expected an integer, found 1.5");
  EXPECT_EQ(check(schema, json{{"gravity", {0, 0}}}).at(0).message,
            "expected an array of exactly 3 items, found 2");
  const auto nested = check(schema, json{{"child", {{"child", {{"n", "x"}}}}}});
  ASSERT_EQ(nested.size(), 1u);
  EXPECT_EQ(nested[0].pointer, "/child/child/n");
}

// Guards that annotations, root $id and every "x-" keyword are accepted and change nothing.
TEST(JsonSchema, IgnoresAnnotationsAndExtensions) {
  const json schema = json::parse(R"({
    "$schema": "https://json-schema.org/draft/2020-12/schema", "$id": "https://example.org/s.json",
    "title": "t", "description": "d", "default": 1, "examples": [1], "$comment": "c",
    "type": "number", "x-unit": "Pa", "x-anything": { "patternProperties": {} }
  })");
  EXPECT_TRUE(check(schema, 5).empty());
  EXPECT_EQ(check(schema, "5").size(), 1u);
  EXPECT_EQ(check({{"type", "string"}, {"x-unit", "m"}}, "abc").size(), 0u);
}

// Guards that an unsupported keyword is refused by the constructor, naming it and its schema
// pointer.
TEST(JsonSchema, RejectsUnsupportedKeyword) {
  const json schema = {{"properties", {{"a", {{"patternProperties", {{"^x", json::object()}}}}}}}};
  EXPECT_THROW(SchemaValidator{schema}, std::invalid_argument);
  const std::string msg = construction_error(schema);
  EXPECT_NE(msg.find("'patternProperties'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("#/properties/a"), std::string::npos) << msg;
  const std::string typo = construction_error({{"minimun", 0}});
  EXPECT_NE(typo.find("did you mean 'minimum'?"), std::string::npos) << typo;
  // Unsupported also deep inside $defs that nothing refers to.
  EXPECT_NE(construction_error({{"$defs", {{"x", {{"if", true}}}}}})
                .find("'if' in the schema at #/$defs/x"),
            std::string::npos);
}

// Guards that malformed schemas and unsupported forms are refused at construction.
TEST(JsonSchema, RejectsMalformedSchemas) {
  const std::vector<json> bad = {
      42,                                    // not a schema
      {{"type", "float"}},                   // unknown type
      {{"type", json::array()}},             // empty type list
      {{"minimum", "3"}},                    // bound not a number
      {{"exclusiveMinimum", true}},          // draft-4 boolean form
      {{"minItems", -1}},                    // negative count
      {{"minLength", 1.5}},                  // fractional count
      {{"required", "a"}},                   // not an array
      {{"anyOf", json::array()}},            // empty
      {{"items", {json::object()}}},         // array form of items
      {{"properties", {{"a", 3}}}},          // property schema not a schema
      {{"$ref", "other.json#/a"}},           // remote ref
      {{"$ref", "#/$defs/missing"}},         // unresolvable ref
      {{"$ref", "#anchor"}},                 // plain-name fragment
      {{"$defs", {{"a", {{"$id", "x"}}}}}},  // $id below the root
      {{"$ref", "#"}},                       // endless self reference
      {{"allOf", {{{"$ref", "#"}}}}},        // endless through allOf
      json::parse(
          R"({"$defs": {"a": {"$ref": "#/$defs/b"}, "b": {"not": {"$ref": "#/$defs/a"}}}})"),
  };
  for (const auto& schema : bad) {
    EXPECT_THROW(SchemaValidator{schema}, std::invalid_argument) << schema.dump();
  }
  EXPECT_NE(construction_error({{"type", "float"}}).find("'float'"), std::string::npos);
  EXPECT_NE(construction_error({{"$ref", "other.json#/a"}}).find("only local references"),
            std::string::npos);
  // Recursion that descends into the instance is fine.
  EXPECT_EQ(construction_error({{"properties", {{"next", {{"$ref", "#"}}}}}}), "");
}

// Guards the published keyword list and that every listed keyword is accepted by the constructor.
TEST(JsonSchema, SupportedKeywordList) {
  const auto& k = supported_schema_keywords();
  EXPECT_TRUE(std::is_sorted(k.begin(), k.end()));
  for (const char* name : {"type",
                           "properties",
                           "required",
                           "additionalProperties",
                           "enum",
                           "const",
                           "minimum",
                           "maximum",
                           "exclusiveMinimum",
                           "exclusiveMaximum",
                           "minItems",
                           "maxItems",
                           "items",
                           "minLength",
                           "maxLength",
                           "oneOf",
                           "anyOf",
                           "allOf",
                           "not",
                           "$ref",
                           "$defs"}) {
    EXPECT_NE(std::find(k.begin(), k.end(), name), k.end()) << name;
  }
  EXPECT_EQ(std::find(k.begin(), k.end(), "patternProperties"), k.end());
  const json schema = json::parse(R"({
    "$schema": "s", "$id": "i", "title": "t", "description": "d", "default": 0, "examples": [], "$comment": "c",
    "type": "object", "properties": {}, "required": [], "additionalProperties": true, "enum": [{}], "const": {},
    "minimum": 0, "maximum": 1, "exclusiveMinimum": 0, "exclusiveMaximum": 1, "minItems": 0, "maxItems": 1,
    "items": true, "minLength": 0, "maxLength": 1, "oneOf": [true], "anyOf": [true], "allOf": [true],
    "not": false, "$ref": "#/$defs/a", "$defs": { "a": true }, "definitions": { "b": true }
  })");
  std::vector<std::string> used;
  for (auto it = schema.begin(); it != schema.end(); ++it) used.push_back(it.key());
  std::sort(used.begin(), used.end());
  EXPECT_EQ(used, k);
  EXPECT_EQ(construction_error(schema), "");
  EXPECT_TRUE(SchemaValidator(schema).is_valid(json::object()));
}

// Guards that schema() returns the given schema and that copies stay usable after the original is
// gone.
TEST(JsonSchema, CopiesShareTheCheckedSchema) {
  const json schema = {{"$defs", {{"p", {{"minimum", 0}}}}}, {"$ref", "#/$defs/p"}};
  std::vector<SchemaValidator> copies;
  {
    const SchemaValidator original(schema);
    EXPECT_EQ(original.schema(), schema);
    copies.push_back(original);
  }
  EXPECT_TRUE(copies[0].is_valid(1));
  EXPECT_FALSE(copies[0].is_valid(-1));
}

// Guards that domel's own scenario schema stays within the supported subset.
TEST(JsonSchema, AcceptsScenarioSchema) {
#ifdef DOMEL_SOURCE_DIR
  const std::string source_dir = DOMEL_SOURCE_DIR;
#else
  // Built outside CMake: find the tree from this file's own path.
  const std::string here = __FILE__;
  const std::size_t at = here.rfind("/tests/unit/scenario/");
  if (at == std::string::npos) GTEST_SKIP() << "source tree unknown (DOMEL_SOURCE_DIR not defined)";
  const std::string source_dir = here.substr(0, at);
#endif
  std::ifstream in(source_dir + "/platform/scenario/scenario.schema.json");
  ASSERT_TRUE(in) << source_dir;
  const json schema = json::parse(in);
  EXPECT_EQ(construction_error(schema), "");
}
