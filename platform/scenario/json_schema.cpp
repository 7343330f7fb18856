// SPDX-License-Identifier: MIT
// Implementation of SchemaValidator. The constructor walks the schema once:
// it checks every keyword's form, refuses keywords outside the supported
// subset, resolves each local $ref to the node it names and refuses $ref
// cycles that would never descend into the instance. validate() then
// interprets the schema directly, collecting every problem with a message
// meant for people ("expected a number > 0 [Pa], found -3"); is_valid() runs
// the same walk without messages and stops at the first problem;
// fill_defaults() walks it once more to write "default"s into an instance.
// Over 600 lines because the three walks share the resolved schema, its $ref
// table and the branch matching in one private State; split, they would need
// that State in a header of its own.
#include "scenario/json_schema.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace domel::platform {

using nlohmann::json;

namespace {

const std::vector<std::string>& type_names() {
  static const std::vector<std::string> names = {"array",  "boolean", "integer", "null",
                                                 "number", "object",  "string"};
  return names;
}

// Accepted and ignored by validation (their values are never looked at,
// except "description", quoted in "missing required property" messages, and
// "default", which fill_defaults() writes into an instance).
bool is_annotation(const std::string& k) {
  return k == "$schema" || k == "title" || k == "description" || k == "default" ||
         k == "examples" || k == "$comment";
}

bool is_extension(const std::string& k) { return k.size() >= 2 && k[0] == 'x' && k[1] == '-'; }

// RFC 6901: "~" -> "~0", "/" -> "~1".
std::string escape_token(const std::string& key) {
  std::string s;
  s.reserve(key.size());
  for (char c : key) {
    if (c == '~')
      s += "~0";
    else if (c == '/')
      s += "~1";
    else
      s += c;
  }
  return s;
}

std::string schema_location(const std::string& ptr) { return "#" + ptr; }

// Shortens to about `max` bytes without cutting a UTF-8 sequence.
std::string truncate(const std::string& s, std::size_t max = 40) {
  if (s.size() <= max) return s;
  std::size_t cut = max;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  return s.substr(0, cut) + "...";
}

std::string compact(const json& v) {
  return truncate(v.dump(-1, ' ', false, json::error_handler_t::replace));
}

// A string in JSON double quotes, shortened.
std::string quoted(const std::string& s) {
  return json(truncate(s)).dump(-1, ' ', false, json::error_handler_t::replace);
}

// How a found value is shown: numbers, booleans and null as they are,
// strings quoted with their type named, containers named and abbreviated.
std::string found_phrase(const json& v) {
  if (v.is_string()) {
    return "a string (" + quoted(v.get_ref<const std::string&>()) + ")";
  }
  if (v.is_object()) return "an object (" + compact(v) + ")";
  if (v.is_array()) return "an array (" + compact(v) + ")";
  return compact(v);
}

// How a schema value (enum member, const) is shown: strings in single quotes.
std::string literal(const json& v) {
  if (v.is_string()) return "'" + truncate(v.get_ref<const std::string&>()) + "'";
  return compact(v);
}

// Like literal() for strings, like found_phrase() otherwise.
std::string found_literal(const json& v) { return v.is_string() ? literal(v) : found_phrase(v); }

std::string type_phrase(const std::string& name) {
  if (name == "null") return "null";
  if (name == "integer" || name == "array" || name == "object") return "an " + name;
  return "a " + name;
}

// "a string", "a string or a number", "a string, a number or null".
std::string expected_types(const json& type) {
  if (type.is_string()) return type_phrase(type.get<std::string>());
  std::string s;
  for (std::size_t i = 0; i < type.size(); ++i) {
    if (i > 0) s += (i + 1 == type.size()) ? " or " : ", ";
    s += type_phrase(type[i].get<std::string>());
  }
  return s;
}

bool is_integer_value(const json& v) {
  if (v.is_number_integer()) return true;
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  return std::isfinite(d) && std::floor(d) == d;
}

bool type_matches(const std::string& name, const json& v) {
  if (name == "null") return v.is_null();
  if (name == "boolean") return v.is_boolean();
  if (name == "object") return v.is_object();
  if (name == "array") return v.is_array();
  if (name == "string") return v.is_string();
  if (name == "number") return v.is_number();
  if (name == "integer") return is_integer_value(v);
  return false;
}

bool type_keyword_matches(const json& type, const json& v) {
  if (type.is_string()) return type_matches(type.get_ref<const std::string&>(), v);
  for (const auto& t : type) {
    if (type_matches(t.get_ref<const std::string&>(), v)) return true;
  }
  return false;
}

// The JSON type of a value, with every number called "number".
std::string json_type_name(const json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "boolean";
  if (v.is_object()) return "object";
  if (v.is_array()) return "array";
  if (v.is_string()) return "string";
  return "number";
}

// Negative, zero or positive as a <, ==, > b; exact when both are integers.
int compare_numbers(const json& a, const json& b) {
  if (a.is_number_integer() && b.is_number_integer()) {
    const bool au = a.is_number_unsigned(), bu = b.is_number_unsigned();
    if (au && bu) {
      const auto x = a.get<std::uint64_t>(), y = b.get<std::uint64_t>();
      return x < y ? -1 : (x > y ? 1 : 0);
    }
    if (!au && !bu) {
      const auto x = a.get<std::int64_t>(), y = b.get<std::int64_t>();
      return x < y ? -1 : (x > y ? 1 : 0);
    }
    if (au) {  // a unsigned, b signed
      const auto y = b.get<std::int64_t>();
      if (y < 0) return 1;
      const auto x = a.get<std::uint64_t>(), yu = static_cast<std::uint64_t>(y);
      return x < yu ? -1 : (x > yu ? 1 : 0);
    }
    return -compare_numbers(b, a);
  }
  const double x = a.get<double>(), y = b.get<double>();
  return x < y ? -1 : (x > y ? 1 : 0);
}

// Unicode code points of a UTF-8 string (continuation bytes not counted).
std::size_t code_points(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) {
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++n;
  }
  return n;
}

bool is_non_negative_integer(const json& v) {
  if (v.is_number_unsigned()) return true;
  if (v.is_number_integer()) return v.get<std::int64_t>() >= 0;
  return is_integer_value(v) && v.get<double>() >= 0;
}

std::size_t as_size(const json& v) {
  if (v.is_number_integer()) return static_cast<std::size_t>(v.get<std::uint64_t>());
  const double d = v.get<double>();
  return d >= 1.8e19 ? static_cast<std::size_t>(-1) : static_cast<std::size_t>(d);
}

std::string plural(std::size_t n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

bool fail(std::vector<Diagnostic>* out, const std::string& ptr, std::string message,
          std::string hint = {}) {
  if (out) out->push_back(Diagnostic{std::string(), ptr, std::move(message), std::move(hint)});
  return false;
}

[[noreturn]] void refuse(const std::string& what) {
  throw std::invalid_argument("JSON schema: " + what);
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

struct SchemaValidator::State {
  json root_;
  /// Every $ref string of the schema -> the node it names (inside root_).
  std::unordered_map<std::string, const json*> refs_;
  /// Schema nodes met while checking -> their pointer (construction only).
  using Seen = std::unordered_map<const json*, std::string>;

  // ---- construction -------------------------------------------------------

  void check_schema(const json& s, const std::string& ptr, Seen& seen) {
    if (seen.count(&s) != 0) return;
    if (!s.is_boolean() && !s.is_object()) {
      refuse("the schema at " + schema_location(ptr) + " must be an object or a boolean, found " +
             found_phrase(s));
    }
    seen.emplace(&s, ptr);
    if (s.is_boolean()) return;
    for (auto it = s.begin(); it != s.end(); ++it) {
      const std::string& k = it.key();
      const json& val = it.value();
      const std::string kptr = ptr + "/" + escape_token(k);
      const std::string where = "'" + k + "' at " + schema_location(ptr);
      if (is_extension(k) || is_annotation(k)) continue;
      if (k == "$id") {
        // Only harmless at the root, where it does not change how "#..." resolves.
        if (&s != &root_) {
          refuse("'$id' is only supported at the schema root, found one at " +
                 schema_location(ptr));
        }
        if (!val.is_string()) refuse(where + " must be a string, found " + found_phrase(val));
      } else if (k == "type") {
        check_type(val, where);
      } else if (k == "properties" || k == "$defs" || k == "definitions") {
        if (!val.is_object()) refuse(where + " must be an object, found " + found_phrase(val));
        for (auto p = val.begin(); p != val.end(); ++p) {
          check_schema(p.value(), kptr + "/" + escape_token(p.key()), seen);
        }
      } else if (k == "required") {
        if (!val.is_array())
          refuse(where + " must be an array of strings, found " + found_phrase(val));
        for (const auto& name : val) {
          if (!name.is_string()) {
            refuse(where + " must be an array of strings, found " + found_phrase(name) + " in it");
          }
        }
      } else if (k == "additionalProperties" || k == "not") {
        check_schema(val, kptr, seen);
      } else if (k == "items") {
        if (val.is_array()) {
          refuse("the array form of 'items' (one schema per position) at " + schema_location(ptr) +
                 " is not supported; give one schema for every item");
        }
        check_schema(val, kptr, seen);
      } else if (k == "enum") {
        if (!val.is_array()) refuse(where + " must be an array, found " + found_phrase(val));
      } else if (k == "const") {
        // any value
      } else if (k == "minimum" || k == "maximum" || k == "exclusiveMinimum" ||
                 k == "exclusiveMaximum") {
        if (!val.is_number()) {
          refuse(where + " must be a number, found " + found_phrase(val) +
                 (val.is_boolean() ? " (the boolean form of draft 4 is not supported)" : ""));
        }
      } else if (k == "minItems" || k == "maxItems" || k == "minLength" || k == "maxLength") {
        if (!is_non_negative_integer(val)) {
          refuse(where + " must be a non-negative integer, found " + found_phrase(val));
        }
      } else if (k == "allOf" || k == "anyOf" || k == "oneOf") {
        if (!val.is_array() || val.empty()) {
          refuse(where + " must be a non-empty array of schemas, found " + found_phrase(val));
        }
        for (std::size_t i = 0; i < val.size(); ++i) {
          check_schema(val[i], kptr + "/" + std::to_string(i), seen);
        }
      } else if (k == "$ref") {
        if (!val.is_string()) refuse(where + " must be a string, found " + found_phrase(val));
        const std::string& ref = val.get_ref<const std::string&>();
        std::string target_ptr;
        const json* target = resolve(ref, ptr, target_ptr);
        refs_.emplace(ref, target);
        check_schema(*target, target_ptr, seen);
      } else {
        std::string msg =
            "unsupported keyword '" + k + "' in the schema at " + schema_location(ptr);
        const std::string hint = suggest(k, supported_schema_keywords());
        if (hint.rfind("did you mean", 0) == 0) msg += " (" + hint + ")";
        refuse(msg);
      }
    }
  }

  static void check_type(const json& val, const std::string& where) {
    auto check_name = [&](const json& n) {
      if (!n.is_string()) refuse(where + " must name types as strings, found " + found_phrase(n));
      const auto& name = n.get_ref<const std::string&>();
      const auto& names = type_names();
      if (std::find(names.begin(), names.end(), name) == names.end()) {
        refuse(where + " names the unknown type '" + name + "' (" + suggest(name, names) + ")");
      }
    };
    if (val.is_array()) {
      if (val.empty()) refuse(where + " must not be an empty array");
      for (const auto& n : val) check_name(n);
    } else {
      check_name(val);
    }
  }

  // Resolves a local reference "#", "#/a/b~1c" (URI fragment, %-escapes
  // allowed) to a node of root_; target_ptr receives its JSON pointer.
  const json* resolve(const std::string& ref, const std::string& ptr,
                      std::string& target_ptr) const {
    const std::string where = "'$ref' \"" + ref + "\" at " + schema_location(ptr);
    if (ref.empty() || ref[0] != '#') {
      refuse(where + ": only local references (\"#\", \"#/$defs/name\", ...) are supported");
    }
    std::string frag;
    for (std::size_t i = 1; i < ref.size(); ++i) {
      if (ref[i] != '%') {
        frag += ref[i];
        continue;
      }
      const int hi = i + 2 < ref.size() ? hex_digit(ref[i + 1]) : -1;
      const int lo = i + 2 < ref.size() ? hex_digit(ref[i + 2]) : -1;
      if (hi < 0 || lo < 0) refuse(where + ": malformed %-escape");
      frag += static_cast<char>(hi * 16 + lo);
      i += 2;
    }
    target_ptr = frag;
    const json* node = &root_;
    if (frag.empty()) return node;
    if (frag[0] != '/') refuse(where + ": plain-name fragments (anchors) are not supported");
    std::size_t pos = 1;
    while (true) {
      const std::size_t slash = frag.find('/', pos);
      const std::string raw =
          frag.substr(pos, slash == std::string::npos ? std::string::npos : slash - pos);
      std::string token;
      for (std::size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] != '~') {
          token += raw[i];
        } else if (i + 1 < raw.size() && (raw[i + 1] == '0' || raw[i + 1] == '1')) {
          token += raw[i + 1] == '0' ? '~' : '/';
          ++i;
        } else {
          refuse(where + ": malformed '~' escape in the JSON pointer");
        }
      }
      if (node->is_object()) {
        auto it = node->find(token);
        if (it == node->end()) refuse(where + " does not resolve: no member '" + token + "'");
        node = &*it;
      } else if (node->is_array()) {
        const bool digits = !token.empty() && std::all_of(token.begin(), token.end(), [](char c) {
          return c >= '0' && c <= '9';
        });
        if (!digits || (token.size() > 1 && token[0] == '0') || token.size() > 9 ||
            std::stoul(token) >= node->size()) {
          refuse(where + " does not resolve: no element '" + token + "'");
        }
        node = &(*node)[std::stoul(token)];
      } else {
        refuse(where + " does not resolve: '" + token + "' goes into a non-container");
      }
      if (slash == std::string::npos) break;
      pos = slash + 1;
    }
    return node;
  }

  // Schemas applied to the same instance value: $ref, allOf, anyOf, oneOf, not.
  std::vector<const json*> in_place_children(const json& s) const {
    std::vector<const json*> c;
    if (!s.is_object()) return c;
    if (auto r = s.find("$ref"); r != s.end()) c.push_back(refs_.at(r->get<std::string>()));
    for (const char* k : {"allOf", "anyOf", "oneOf"}) {
      if (auto a = s.find(k); a != s.end()) {
        for (const auto& b : *a) c.push_back(&b);
      }
    }
    if (auto n = s.find("not"); n != s.end()) c.push_back(&*n);
    return c;
  }

  // A cycle through in-place applicators would recurse for ever at validation.
  void check_cycles(const Seen& seen) const {
    std::unordered_map<const json*, int> state;  // 1 on the stack, 2 done
    for (const auto& [node, ptr] : seen) visit(node, state, seen);
  }

  void visit(const json* node, std::unordered_map<const json*, int>& state,
             const Seen& seen) const {
    int& st = state[node];
    if (st == 2) return;
    if (st == 1) {
      refuse("the schema at " + schema_location(seen.at(node)) +
             " refers back to itself through $ref/allOf/anyOf/oneOf/not without descending into "
             "the instance (endless recursion)");
    }
    st = 1;
    for (const json* c : in_place_children(*node)) visit(c, state, seen);
    state[node] = 2;
  }

  // ---- validation ---------------------------------------------------------

  // Validates v against s. With out == nullptr stops at the first problem,
  // otherwise appends every problem. Returns whether v is valid.
  bool eval(const json& s, const json& v, const std::string& ptr, const std::string& inherited_unit,
            std::vector<Diagnostic>* out) const {
    if (s.is_boolean()) {
      if (s.get<bool>()) return true;
      return fail(out, ptr, "no value is allowed here, found " + found_phrase(v));
    }
    // Wrong type: report only that, not what the other keywords think of it.
    if (auto t = s.find("type"); t != s.end() && !type_keyword_matches(*t, v)) {
      return fail(out, ptr, "expected " + expected_types(*t) + ", found " + found_phrase(v));
    }
    const std::string* unit = &inherited_unit;
    if (auto u = s.find("x-unit"); u != s.end() && u->is_string())
      unit = &u->get_ref<const std::string&>();

    bool ok = true;
    // Records a result; true when the caller should stop (first problem, no messages wanted).
    auto stop = [&](bool result) {
      if (!result) ok = false;
      return !result && out == nullptr;
    };

    if (auto e = s.find("enum"); e != s.end()) {
      if (std::find(e->begin(), e->end(), v) == e->end()) {
        std::string list;
        std::vector<std::string> names;
        for (std::size_t i = 0; i < e->size(); ++i) {
          list += (i ? ", " : "") + literal((*e)[i]);
          if ((*e)[i].is_string()) names.push_back((*e)[i].get<std::string>());
        }
        const std::string expected = e->size() == 1 ? list
                                     : e->empty()   ? "no value (empty enum)"
                                                    : "one of " + list;
        // Only a "did you mean": the message already lists every valid value.
        std::string hint = v.is_string() ? suggest(v.get<std::string>(), names) : std::string();
        if (hint.rfind("did you mean", 0) != 0) hint.clear();
        if (stop(fail(out, ptr, "expected " + expected + ", found " + found_literal(v), hint)))
          return false;
      }
    }
    if (auto c = s.find("const"); c != s.end() && *c != v) {
      if (stop(fail(out, ptr, "expected " + literal(*c) + ", found " + found_literal(v))))
        return false;
    }

    if (v.is_number()) {
      const auto t = s.find("type");
      const bool integer =
          t != s.end() && ((t->is_string() && *t == "integer") ||
                           (t->is_array() && t->size() == 1 && (*t)[0] == "integer"));
      struct Bound {
        const char* keyword;
        const char* op;
        bool (*holds)(int);
      };
      static const Bound bounds[] = {
          {"minimum", ">=", [](int c) { return c >= 0; }},
          {"exclusiveMinimum", ">", [](int c) { return c > 0; }},
          {"maximum", "<=", [](int c) { return c <= 0; }},
          {"exclusiveMaximum", "<", [](int c) { return c < 0; }},
      };
      for (const auto& b : bounds) {
        auto it = s.find(b.keyword);
        if (it == s.end() || b.holds(compare_numbers(v, *it))) continue;
        std::string msg = std::string("expected ") + (integer ? "an integer " : "a number ") +
                          b.op + " " + compact(*it);
        // "1" marks a dimensionless quantity: "[1]" would only confuse.
        if (!unit->empty() && *unit != "1") msg += " [" + *unit + "]";
        if (stop(fail(out, ptr, msg + ", found " + compact(v)))) return false;
      }
    }

    if (v.is_string()) {
      const std::size_t n = code_points(v.get_ref<const std::string&>());
      const auto lo = s.find("minLength"), hi = s.find("maxLength");
      const bool exact = lo != s.end() && hi != s.end() && as_size(*lo) == as_size(*hi);
      const std::string shown = quoted(v.get_ref<const std::string&>());
      auto length_error = [&](const char* relation, std::size_t limit) {
        if (exact) {
          return "expected a string of exactly " + plural(limit, "character") + ", found " +
                 std::to_string(n) + " (" + shown + ")";
        }
        return std::string("expected a string of ") + relation + " " + plural(limit, "character") +
               ", found " + plural(n, "character") + " (" + shown + ")";
      };
      if (lo != s.end() && n < as_size(*lo)) {
        if (stop(fail(out, ptr, length_error("at least", as_size(*lo))))) return false;
      }
      if (hi != s.end() && n > as_size(*hi)) {
        if (stop(fail(out, ptr, length_error("at most", as_size(*hi))))) return false;
      }
    }

    if (v.is_array()) {
      const std::size_t n = v.size();
      const auto lo = s.find("minItems"), hi = s.find("maxItems");
      const bool exact = lo != s.end() && hi != s.end() && as_size(*lo) == as_size(*hi);
      auto count_error = [&](const char* relation, std::size_t limit) {
        if (exact) {
          return "expected an array of exactly " + plural(limit, "item") + ", found " +
                 std::to_string(n);
        }
        return std::string("expected an array of ") + relation + " " + plural(limit, "item") +
               ", found " + plural(n, "item");
      };
      if (lo != s.end() && n < as_size(*lo)) {
        if (stop(fail(out, ptr, count_error("at least", as_size(*lo))))) return false;
      }
      if (hi != s.end() && n > as_size(*hi)) {
        if (stop(fail(out, ptr, count_error("at most", as_size(*hi))))) return false;
      }
      if (auto items = s.find("items"); items != s.end()) {
        for (std::size_t i = 0; i < n; ++i) {
          if (stop(eval(*items, v[i], ptr + "/" + std::to_string(i), std::string(), out)))
            return false;
        }
      }
    }

    if (v.is_object()) {
      const auto props = s.find("properties");
      if (auto req = s.find("required"); req != s.end()) {
        for (const auto& name : *req) {
          const auto& key = name.get_ref<const std::string&>();
          if (v.contains(key)) continue;
          std::string msg = "missing required property '" + key + "'";
          if (props != s.end()) {
            if (auto p = props->find(key); p != props->end()) {
              const std::string d = description_of(*p);
              if (!d.empty()) msg += " \u2014 " + d;
            }
          }
          if (stop(fail(out, ptr, msg))) return false;
        }
      }
      const auto extra = s.find("additionalProperties");
      for (auto it = v.begin(); it != v.end(); ++it) {
        const std::string child = ptr + "/" + escape_token(it.key());
        if (props != s.end()) {
          if (auto p = props->find(it.key()); p != props->end()) {
            if (stop(eval(*p, it.value(), child, std::string(), out))) return false;
            continue;
          }
        }
        if (extra == s.end()) continue;
        if (extra->is_boolean() && !extra->get<bool>()) {
          std::vector<std::string> names;
          if (props != s.end()) {
            for (auto p = props->begin(); p != props->end(); ++p) names.push_back(p.key());
          }
          if (stop(fail(out, child, "unknown property '" + it.key() + "'",
                        suggest(it.key(), names)))) {
            return false;
          }
        } else if (stop(eval(*extra, it.value(), child, std::string(), out))) {
          return false;
        }
      }
    }

    if (auto r = s.find("$ref"); r != s.end()) {
      if (stop(eval(*refs_.at(r->get_ref<const std::string&>()), v, ptr, *unit, out))) return false;
    }
    if (auto all = s.find("allOf"); all != s.end()) {
      for (const auto& b : *all) {
        if (stop(eval(b, v, ptr, *unit, out))) return false;
      }
    }
    if (auto any = s.find("anyOf"); any != s.end()) {
      if (stop(eval_alternatives(*any, false, v, ptr, *unit, out))) return false;
    }
    if (auto one = s.find("oneOf"); one != s.end()) {
      if (stop(eval_alternatives(*one, true, v, ptr, *unit, out))) return false;
    }
    if (auto n = s.find("not"); n != s.end() && eval(*n, v, ptr, *unit, nullptr)) {
      if (stop(fail(out, ptr,
                    "expected a value that does not match the excluded form, found " +
                        found_phrase(v)))) {
        return false;
      }
    }
    return ok;
  }

  // anyOf (exactly_one false) or oneOf (exactly_one true).
  bool eval_alternatives(const json& branches, bool exactly_one, const json& v,
                         const std::string& ptr, const std::string& unit,
                         std::vector<Diagnostic>* out) const {
    const std::size_t n = branches.size();
    if (out == nullptr) {
      std::size_t matches = 0;
      for (const auto& b : branches) {
        if (eval(b, v, ptr, unit, nullptr) && (++matches > 1 || !exactly_one)) break;
      }
      return exactly_one ? matches == 1 : matches > 0;
    }
    std::vector<std::vector<Diagnostic>> errors(n);
    std::vector<std::size_t> matching;
    for (std::size_t i = 0; i < n; ++i) {
      if (eval(branches[i], v, ptr, unit, &errors[i])) {
        matching.push_back(i);
        if (!exactly_one) return true;
      }
    }
    if (matching.size() == 1) return true;
    // Branches that only require keys ("oneOf": [{"required": ["a"]}, {"required": ["b"]}])
    // express "give exactly one of a, b": say that in those words.
    std::vector<std::string> keys;
    bool only_required = exactly_one;
    for (const auto& b : branches) {
      if (!b.is_object() || b.size() != 1 || !b.contains("required") || b["required"].size() != 1 ||
          !b["required"][0].is_string()) {
        only_required = false;
        break;
      }
      keys.push_back("'" + b["required"][0].get<std::string>() + "'");
    }
    std::string list;
    for (std::size_t i = 0; i < keys.size(); ++i) list += (i == 0 ? "" : i + 1 == keys.size() ? " or " : ", ") + keys[i];
    if (only_required && matching.empty() && v.is_object())
      return fail(out, ptr, "missing required property: expected one of " + list + ", found none",
                  "give one of them");
    if (matching.size() > 1) {
      if (only_required) {
        std::string given;
        for (std::size_t i = 0; i < matching.size(); ++i)
          given += (i == 0 ? "" : i + 1 == matching.size() ? " and " : ", ") + keys[matching[i]];
        return fail(out, ptr, "expected exactly one of " + list + ", found " + given,
                    "remove all but one of them");
      }
      std::string which;
      for (std::size_t i = 0; i < matching.size(); ++i)
        which += (i ? ", " : "") + std::to_string(matching[i] + 1);
      return fail(out, ptr, "matches more than one of the allowed forms",
                  "matching forms: " + which);
    }
    report_no_match(branches, v, ptr, errors, *out);
    return false;
  }

  // No branch matched: report the errors of the branch the user most likely
  // meant (the only one declaring the instance's type, else the only one with
  // the fewest errors), or a summary when none stands out.
  void report_no_match(const json& branches, const json& v, const std::string& ptr,
                       const std::vector<std::vector<Diagnostic>>& errors,
                       std::vector<Diagnostic>& out) const {
    const std::size_t n = branches.size();
    std::vector<std::size_t> declared_match, compatible, all;
    for (std::size_t i = 0; i < n; ++i) {
      all.push_back(i);
      const auto types = declared_types(branches[i], 0);
      if (types.empty()) {
        compatible.push_back(i);
      } else if (std::any_of(types.begin(), types.end(),
                             [&](const std::string& t) { return type_matches(t, v); })) {
        declared_match.push_back(i);
        compatible.push_back(i);
      }
    }
    auto take = [&](std::size_t i) { out.insert(out.end(), errors[i].begin(), errors[i].end()); };
    if (declared_match.size() == 1) return take(declared_match[0]);
    const auto& pool = !declared_match.empty() ? declared_match
                       : !compatible.empty()   ? compatible
                                               : all;
    std::size_t best = pool[0], ties = 0;
    for (std::size_t i : pool) {
      if (errors[i].size() < errors[best].size()) {
        best = i;
        ties = 1;
      } else if (errors[i].size() == errors[best].size()) {
        ++ties;
      }
    }
    if (ties == 1) return take(best);
    std::string hint;
    const std::size_t shown = std::min<std::size_t>(n, 4);
    for (std::size_t i = 0; i < shown; ++i) {
      if (errors[i].empty()) continue;
      const Diagnostic& d = errors[i].front();
      if (!hint.empty()) hint += "; ";
      hint += "form " + std::to_string(i + 1) + ": ";
      if (d.pointer != ptr) {
        hint += "at " + (d.pointer.rfind(ptr, 0) == 0 ? d.pointer.substr(ptr.size()) : d.pointer) +
                ": ";
      }
      hint += d.message;
    }
    if (n > shown) hint += "; ...";
    out.push_back(Diagnostic{std::string(), ptr, "does not match any of the allowed forms", hint});
  }

  // The JSON types a branch admits, from "type" or from its const / enum
  // values, following $ref; empty when it does not say.
  std::vector<std::string> declared_types(const json& s, int depth) const {
    std::vector<std::string> types;
    if (!s.is_object() || depth > 32) return types;
    if (auto t = s.find("type"); t != s.end()) {
      if (t->is_string())
        types.push_back(t->get<std::string>());
      else
        for (const auto& x : *t) types.push_back(x.get<std::string>());
    } else if (auto c = s.find("const"); c != s.end()) {
      types.push_back(json_type_name(*c));
    } else if (auto e = s.find("enum"); e != s.end()) {
      for (const auto& x : *e) types.push_back(json_type_name(x));
    } else if (auto r = s.find("$ref"); r != s.end()) {
      return declared_types(*refs_.at(r->get_ref<const std::string&>()), depth + 1);
    }
    return types;
  }

  // ---- defaults -----------------------------------------------------------

  // The "default" of a property schema, on it or on the node its $ref names.
  const json* default_of(const json& s) const {
    const json* node = &s;
    for (int depth = 0; depth < 32 && node->is_object(); ++depth) {
      if (auto d = node->find("default"); d != node->end()) return &*d;
      auto r = node->find("$ref");
      if (r == node->end()) break;
      node = refs_.at(r->get_ref<const std::string&>());
    }
    return nullptr;
  }

  void fill(const json& s, json& v, const std::string& ptr, std::vector<std::string>& filled) const {
    if (!s.is_object()) return;
    if (v.is_object()) {
      const auto props = s.find("properties");
      if (props != s.end()) {
        for (auto p = props->begin(); p != props->end(); ++p) {
          if (v.contains(p.key())) continue;
          if (const json* d = default_of(p.value())) {
            v[p.key()] = *d;
            filled.push_back(ptr + "/" + escape_token(p.key()));
          }
        }
      }
      const auto extra = s.find("additionalProperties");
      for (auto it = v.begin(); it != v.end(); ++it) {
        const std::string child = ptr + "/" + escape_token(it.key());
        if (props != s.end()) {
          if (auto p = props->find(it.key()); p != props->end()) {
            fill(*p, it.value(), child, filled);
            continue;
          }
        }
        if (extra != s.end()) fill(*extra, it.value(), child, filled);
      }
    }
    if (v.is_array()) {
      if (auto items = s.find("items"); items != s.end())
        for (std::size_t i = 0; i < v.size(); ++i) fill(*items, v[i], ptr + "/" + std::to_string(i), filled);
    }
    if (auto r = s.find("$ref"); r != s.end()) fill(*refs_.at(r->get_ref<const std::string&>()), v, ptr, filled);
    if (auto all = s.find("allOf"); all != s.end())
      for (const auto& b : *all) fill(b, v, ptr, filled);
    for (const char* k : {"oneOf", "anyOf"}) {
      auto alt = s.find(k);
      if (alt == s.end()) continue;
      const json* match = nullptr;
      std::size_t matches = 0;
      for (const auto& b : *alt)
        if (eval(b, v, ptr, std::string(), nullptr) && ++matches == 1) match = &b;
      if (matches == 1 || (matches > 1 && k[0] == 'a')) fill(*match, v, ptr, filled);
    }
  }

  // The "description" of a property schema, following $ref; may be empty.
  std::string description_of(const json& s) const {
    const json* node = &s;
    for (int depth = 0; depth < 32 && node->is_object(); ++depth) {
      if (auto d = node->find("description"); d != node->end() && d->is_string())
        return d->get<std::string>();
      auto r = node->find("$ref");
      if (r == node->end()) break;
      node = refs_.at(r->get_ref<const std::string&>());
    }
    return {};
  }
};

SchemaValidator::SchemaValidator(nlohmann::json schema) {
  auto state = std::make_shared<State>();
  state->root_ = std::move(schema);
  State::Seen seen;
  state->check_schema(state->root_, "", seen);
  state->check_cycles(seen);
  state_ = std::move(state);
}

void SchemaValidator::validate(const nlohmann::json& instance, std::vector<Diagnostic>& out,
                               const std::string& base_pointer) const {
  std::vector<Diagnostic> found;
  state_->eval(state_->root_, instance, base_pointer, std::string(), &found);
  // The same problem can be reached twice (e.g. a type repeated behind a
  // $ref, or allOf branches sharing a constraint): report it once.
  std::set<std::pair<std::string, std::string>> reported;
  for (auto& d : found) {
    if (reported.emplace(d.pointer, d.message).second) out.push_back(std::move(d));
  }
}

bool SchemaValidator::is_valid(const nlohmann::json& instance) const {
  return state_->eval(state_->root_, instance, std::string(), std::string(), nullptr);
}

std::vector<std::string> SchemaValidator::fill_defaults(nlohmann::json& instance,
                                                       const std::string& base_pointer) const {
  std::vector<std::string> filled;
  state_->fill(state_->root_, instance, base_pointer, filled);
  return filled;
}

const nlohmann::json& SchemaValidator::schema() const { return state_->root_; }

const std::vector<std::string>& supported_schema_keywords() {
  static const std::vector<std::string> keywords = [] {
    std::vector<std::string> k = {"type",
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
                                  "$defs",
                                  "definitions",
                                  "$schema",
                                  "$id",
                                  "title",
                                  "description",
                                  "default",
                                  "examples",
                                  "$comment"};
    std::sort(k.begin(), k.end());
    return k;
  }();
  return keywords;
}

}  // namespace domel::platform
