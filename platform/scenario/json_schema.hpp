// SPDX-License-Identifier: MIT
// A small JSON Schema validator for the subset of keywords domel's own schemas
// use (scenario file, plugin parameter blocks). It checks the schema once when
// constructed, refusing any keyword it does not implement so that nobody relies
// on a constraint that is silently skipped, and then reports every problem of
// an instance as a Diagnostic whose message says what was expected and what
// was found, at the JSON pointer of the offending value.
#pragma once

#include "core/error.hpp"

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace domel::platform {

/// Validates JSON instances against a JSON Schema (draft-07 / 2020-12 subset).
///
/// Understood: type, properties, required, additionalProperties, enum, const,
/// minimum, maximum, exclusiveMinimum, exclusiveMaximum (numeric form),
/// minItems, maxItems, items (single-schema form), minLength, maxLength (in
/// Unicode code points), oneOf, anyOf, allOf, not, $ref (local "#..." only;
/// siblings of $ref are applied as in 2020-12), $defs, definitions and boolean
/// schemas. Ignored: $schema, $id (root only), title, description, default,
/// examples, $comment and every keyword starting with "x-" ("x-unit" is shown
/// in bound messages unless it is "1", dimensionless; a unit on a schema is
/// inherited through its $ref/allOf/anyOf/oneOf/not); "default" is used by
/// fill_defaults(), never by validate(). A cycle of $ref, allOf,
/// anyOf, oneOf or not that never descends into the instance is refused as
/// malformed.
///
/// Copies share the (immutable) checked schema; validate() is const and may be
/// called from several threads at once.
class SchemaValidator {
 public:
  /// Throws std::invalid_argument for a malformed schema or an unsupported
  /// keyword; the message names the keyword and its schema pointer.
  explicit SchemaValidator(nlohmann::json schema);

  /// Appends one Diagnostic per problem (file left empty; pointer =
  /// base_pointer + path inside the instance, RFC 6901 escaped).
  void validate(const nlohmann::json& instance, std::vector<Diagnostic>& out,
                const std::string& base_pointer = "") const;

  /// True when validate() would report nothing (stops at the first problem).
  bool is_valid(const nlohmann::json& instance) const;

  /// Writes the schema's "default" of every property the instance leaves
  /// out into the instance, recursing into objects (properties,
  /// additionalProperties), arrays (items) and through $ref and allOf; a
  /// oneOf or anyOf contributes the one branch the instance matches (none when
  /// it matches no branch or, for oneOf, several). A filled value is filled
  /// in turn (a default object gets its own members' defaults). Meant for an
  /// instance that validate() accepted: what it does to an invalid one is
  /// unspecified but harmless. Returns the JSON pointers it filled
  /// (base_pointer + path, RFC 6901 escaped), a filled object before its members.
  std::vector<std::string> fill_defaults(nlohmann::json& instance, const std::string& base_pointer = "") const;

  /// The schema as given to the constructor.
  const nlohmann::json& schema() const;

 private:
  struct State;
  std::shared_ptr<const State> state_;
};

/// The set of keywords validate() understands (used by tests and docs): the
/// validation keywords, $ref/$defs/definitions and the annotation keywords that
/// are accepted and ignored. Keywords starting with "x-" are accepted too but
/// cannot be listed. Sorted.
const std::vector<std::string>& supported_schema_keywords();

}  // namespace domel::platform
