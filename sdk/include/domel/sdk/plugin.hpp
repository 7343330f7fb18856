// SPDX-License-Identifier: MIT
//
// domel SDK — header-only C++ layer over abi.h. A plugin author writes an
// ordinary class per model and exports a whole library with one macro:
//
//   class MyRolling {
//    public:
//     static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
//     static constexpr const char* kName = "my_rolling";
//     static constexpr const char* kVersion = "1.0.0";
//     static constexpr const char* kSummary = "one line for `domel plugins`";
//     static constexpr unsigned kHistorySlots = 3;        // optional, default 0
//     static constexpr const char* kSchema = R"json({ ...JSON Schema... })json";
//     explicit MyRolling(const domel::sdk::Params& p);      // throw to refuse
//     void compute(domel_contact_batch_v1& batch) const;   // contact kinds
//   };
//   DOMEL_PLUGIN_LIBRARY("my_library", "1.0.0", MyRolling /*, more models */)
//
// Insertion models implement `void insert(const domel_insert_request_v1&,
// domel::sdk::Inserted& out)` instead of compute().
//
// Nothing here crosses the ABI: exceptions thrown by a model are caught in
// the generated C callbacks and turned into a status plus message; JSON is
// handed over as text and parsed on the plugin's side with nlohmann_json.
#pragma once

#include <domel/sdk/abi.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace domel::sdk {

/// Thrown by a model constructor to refuse its parameters.
class ParameterError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Read-only view of a model's parameters. The host has already validated
/// them against the model's schema, so the accessors only guard against a
/// schema and a constructor that disagree.
class Params {
 public:
  explicit Params(const nlohmann::json& j) : j_(j) {}
  bool has(const char* key) const { return j_.contains(key); }
  double number(const char* key) const {
    auto it = j_.find(key);
    if (it == j_.end() || !it->is_number())
      throw ParameterError(std::string(it == j_.end() ? "missing required number '" : "expected a number for '") +
                           key + "'");
    return it->get<double>();
  }
  double number_or(const char* key, double fallback) const {
    auto it = j_.find(key);
    return (it == j_.end() || !it->is_number()) ? fallback : it->get<double>();
  }
  bool boolean_or(const char* key, bool fallback) const {
    auto it = j_.find(key);
    return (it == j_.end() || !it->is_boolean()) ? fallback : it->get<bool>();
  }
  std::string string_or(const char* key, const std::string& fallback) const {
    auto it = j_.find(key);
    return (it == j_.end() || !it->is_string()) ? fallback : it->get<std::string>();
  }
  const nlohmann::json& json() const { return j_; }

 private:
  const nlohmann::json& j_;
};

/// Particles produced by an insertion model (radii already include alpha).
struct Inserted {
  std::vector<double> x, y, z, r;
  void push(double px, double py, double pz, double pr) {
    x.push_back(px); y.push_back(py); z.push_back(pz); r.push_back(pr);
  }
  std::size_t size() const { return r.size(); }
};

namespace detail {

inline void write_message(char* buffer, std::size_t capacity, const char* text) {
  if (buffer == nullptr || capacity == 0) return;
  std::strncpy(buffer, text, capacity - 1);
  buffer[capacity - 1] = '\0';
}

template <class M, class = void>
struct history_slots : std::integral_constant<unsigned, 0> {};
template <class M>
struct history_slots<M, std::void_t<decltype(M::kHistorySlots)>>
    : std::integral_constant<unsigned, M::kHistorySlots> {};

constexpr bool is_contact_kind(domel_kind k) {
  return k == DOMEL_KIND_NORMAL || k == DOMEL_KIND_DAMPING || k == DOMEL_KIND_TANGENTIAL ||
         k == DOMEL_KIND_ROLLING || k == DOMEL_KIND_TWISTING;
}

/// Instance wrapper: the model plus scratch the C callbacks need.
template <class M>
struct Instance {
  M model;
  Inserted last;  // insertion: kept between a capacity retry and the next call
  explicit Instance(const Params& p) : model(p) {}
};

template <class M>
struct Export {
  static domel_status create(const char* params_json, const domel_host_v1* /*host*/,
                             void** out, char* err, std::size_t cap) {
    *out = nullptr;
    try {
      const nlohmann::json j = nlohmann::json::parse(params_json ? params_json : "{}");
      *out = new Instance<M>(Params(j));
      return DOMEL_OK;
    } catch (const std::exception& e) {
      write_message(err, cap, e.what());
    } catch (...) {
      write_message(err, cap, "unknown exception in create");
    }
    return DOMEL_ERR_PARAMETER;
  }
  static void destroy(void* p) { delete static_cast<Instance<M>*>(p); }

  static domel_status contact(void* self, domel_contact_batch_v1* batch, char* err,
                              std::size_t cap) {
    if constexpr (is_contact_kind(M::kKind)) {
      try {
        // through a const reference: kernels may run concurrently on one
        // instance (abi.h), so compute() must not modify the model
        static_cast<const M&>(static_cast<Instance<M>*>(self)->model).compute(*batch);
        return DOMEL_OK;
      } catch (const std::exception& e) {
        write_message(err, cap, e.what());
      } catch (...) {
        write_message(err, cap, "unknown exception in contact kernel");
      }
      return DOMEL_ERR_RUNTIME;
    } else {
      (void)self; (void)batch;
      write_message(err, cap, "not a contact model");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status insert(void* self, const domel_insert_request_v1* req,
                             domel_insert_output_v1* out, char* err, std::size_t cap) {
    if constexpr (M::kKind == DOMEL_KIND_INSERTION) {
      try {
        auto* inst = static_cast<Instance<M>*>(self);
        if (inst->last.size() == 0 || out->count != inst->last.size()) {
          inst->last = Inserted{};
          inst->model.insert(*req, inst->last);
        }
        const std::size_t n = inst->last.size();
        out->count = n;
        if (n > out->capacity) return DOMEL_ERR_CAPACITY;
        for (std::size_t k = 0; k < n; ++k) {
          out->x[k] = inst->last.x[k]; out->y[k] = inst->last.y[k];
          out->z[k] = inst->last.z[k]; out->r[k] = inst->last.r[k];
        }
        inst->last = Inserted{};
        return DOMEL_OK;
      } catch (const std::exception& e) {
        write_message(err, cap, e.what());
      } catch (...) {
        write_message(err, cap, "unknown exception in insertion");
      }
      return DOMEL_ERR_RUNTIME;
    } else {
      (void)self; (void)req; (void)out;
      write_message(err, cap, "not an insertion model");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static const domel_model_v1* descriptor() {
    static const domel_model_v1 d = {
        sizeof(domel_model_v1),
        static_cast<uint32_t>(M::kKind),
        M::kName,
        M::kVersion,
        M::kSummary,
        M::kSchema,
        history_slots<M>::value,
        0u,
        &Export::create,
        &Export::destroy,
        is_contact_kind(M::kKind) ? &Export::contact : nullptr,
        M::kKind == DOMEL_KIND_INSERTION ? &Export::insert : nullptr,
    };
    return &d;
  }
};

template <class... Ms>
const domel_library_v1* library(const char* name, const char* version) {
  static const domel_model_v1* const models[] = {Export<Ms>::descriptor()...};
  static const domel_library_v1 lib = {sizeof(domel_library_v1),
                                       DOMEL_ABI_MAJOR,
                                       DOMEL_ABI_MINOR,
                                       name,
                                       version,
                                       static_cast<uint32_t>(sizeof...(Ms)),
                                       models};
  return &lib;
}

}  // namespace detail
}  // namespace domel::sdk

/// Export a plugin library: its name, its version and the model classes.
#define DOMEL_PLUGIN_LIBRARY(LIBRARY_NAME, LIBRARY_VERSION, ...)                       \
  extern "C" DOMEL_EXPORT const domel_library_v1* domel_plugin_entry_v1(void) {         \
    return ::domel::sdk::detail::library<__VA_ARGS__>(LIBRARY_NAME, LIBRARY_VERSION);   \
  }
