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
//     void compute(domel_contact_batch_v2& batch) const;   // contact kinds
//   };
//   DOMEL_PLUGIN_LIBRARY("my_library", "1.0.0", MyRolling /*, more models */)
//
// The callback of each family (abi.h):
//   contact kinds   void compute(domel_contact_batch_v2&) const;  batch.pair is
//                   always set: a batch of several material pairs is split
//                   into runs of one pair before compute() sees it
//   insertion       void insert(const domel_insert_request_v1&, domel::sdk::Inserted& out);
//   controller      void control(domel_control_step_v1&);
//   fluid_coupler   void exchange(domel_fluid_exchange_v1&);
//                   optional: void fields(domel_fluid_fields_v1&);
//                             void limits(domel_fluid_limits_v1&);
//
// Host services: `p.host()` in the constructor is the model's domel::sdk::Host
// (keep a copy); host.info("...") logs under the model's name and scenario
// location, host.error("...") reports an error with that context.
//
// Nothing here crosses the ABI: exceptions thrown by a model are caught in
// the generated C callbacks and turned into a status plus message; JSON is
// handed over as text and parsed on the plugin's side with nlohmann_json.
#pragma once

#include <domel/sdk/abi.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace domel::sdk {

/// Thrown by a model constructor to refuse its parameters.
class ParameterError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The host services of one model instance (abi.h, domel_host_v2). Cheap to
/// copy; valid while the instance lives. Messages are prefixed by the host
/// with the model's kind and name, its library and its scenario location.
class Host {
 public:
  Host() = default;
  explicit Host(const domel_host_v2* h) : h_(h) {}
  void debug(const std::string& m) const { log(0, m); }
  void info(const std::string& m) const { log(1, m); }
  void warn(const std::string& m) const { log(2, m); }
  /// Report an error with its context; the host logs it and keeps it as the
  /// instance's last error (used when a callback fails without a message).
  void error(const std::string& m, domel_status code = DOMEL_ERR_RUNTIME) const {
    if (h_ != nullptr && h_->struct_size >= offsetof(domel_host_v2, error) + sizeof(h_->error) && h_->error)
      h_->error(h_->context, code, m.c_str());
  }
  void log(int level, const std::string& m) const {
    if (h_ != nullptr && h_->log) h_->log(h_->context, level, m.c_str());
  }
  const domel_host_v2* raw() const { return h_; }

 private:
  const domel_host_v2* h_ = nullptr;
};

/// Read-only view of a model's parameters. The host has already validated
/// them against the model's schema, so the accessors only guard against a
/// schema and a constructor that disagree.
class Params {
 public:
  explicit Params(const nlohmann::json& j, Host host = Host()) : j_(j), host_(host) {}
  /// The instance's host services (logging and errors under the model's name).
  Host host() const { return host_; }
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
  Host host_;
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

/// A contact model declares `static constexpr bool kReadsMasses = false;`
/// when it never reads the batch's mass_i/mass_j (abi.h,
/// DOMEL_CONTACT_IGNORES_MASSES); without the declaration it gets them.
template <class M, class = void>
struct reads_masses : std::true_type {};
template <class M>
struct reads_masses<M, std::void_t<decltype(M::kReadsMasses)>> : std::bool_constant<M::kReadsMasses> {};

/// A fluid coupler may provide `void fields(domel_fluid_fields_v1&)` (its
/// grid fields for output) and `void limits(domel_fluid_limits_v1&)` (its
/// stable coupling interval); either is optional (abi.h, ABI 2.2).
template <class M, class = void>
struct has_fields : std::false_type {};
template <class M>
struct has_fields<M, std::void_t<decltype(std::declval<M&>().fields(std::declval<domel_fluid_fields_v1&>()))>>
    : std::true_type {};
template <class M, class = void>
struct has_limits : std::false_type {};
template <class M>
struct has_limits<M, std::void_t<decltype(std::declval<M&>().limits(std::declval<domel_fluid_limits_v1&>()))>>
    : std::true_type {};

constexpr bool is_contact_kind(domel_kind k) {
  return k == DOMEL_KIND_NORMAL || k == DOMEL_KIND_DAMPING || k == DOMEL_KIND_TANGENTIAL ||
         k == DOMEL_KIND_ROLLING || k == DOMEL_KIND_TWISTING;
}

/// Calls f(sub) for each run of contacts of one material pair, sub being a
/// view of the batch's contacts [c0, c0 + m) with sub.pair set (abi.h,
/// domel_contact_batch_v2::pair). A uniform batch (pair set) is passed as
/// is: one test per batch, nothing per contact.
template <class F>
inline void for_each_pair_run(domel_contact_batch_v2& b, F&& f) {
  if (b.pair != nullptr || b.n == 0) {
    f(b);
    return;
  }
  uint32_t c0 = 0;
  while (c0 < b.n) {
    const domel_pair_v2* p = b.pair_of[c0];
    uint32_t c1 = c0 + 1;
    while (c1 < b.n && b.pair_of[c1] == p) ++c1;
    domel_contact_batch_v2 sub = b;
    sub.n = c1 - c0;
    sub.pair = p;
    sub.pair_of = b.pair_of + c0;
    const double** in[] = {&sub.overlap,  &sub.nx,       &sub.ny,     &sub.nz,     &sub.r_eff, &sub.m_eff,
                           &sub.radius_i, &sub.radius_j, &sub.mass_i, &sub.mass_j, &sub.vn,    &sub.vtx,
                           &sub.vty,      &sub.vtz,      &sub.wx,     &sub.wy,     &sub.wz};
    for (auto* q : in)
      if (*q) *q += c0;
    double** out[] = {&sub.fn_elastic, &sub.kn, &sub.kn_tangent, &sub.contact_radius, &sub.fn_damping,
                      &sub.eta_n, &sub.fn, &sub.ftx, &sub.fty, &sub.ftz, &sub.tqx, &sub.tqy, &sub.tqz,
                      &sub.rolling_stiffness, &sub.rolling_damping};
    for (auto* q : out)
      if (*q) *q += c0;
    if (sub.history) sub.history += static_cast<size_t>(c0) * b.history_stride;
    f(sub);
    c0 = c1;
  }
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
  static domel_status create(const char* params_json, const domel_host_v2* host,
                             void** out, char* err, std::size_t cap) {
    *out = nullptr;
    try {
      const nlohmann::json j = nlohmann::json::parse(params_json ? params_json : "{}");
      *out = new Instance<M>(Params(j, Host(host)));
      return DOMEL_OK;
    } catch (const std::exception& e) {
      write_message(err, cap, e.what());
    } catch (...) {
      write_message(err, cap, "unknown exception in create");
    }
    return DOMEL_ERR_PARAMETER;
  }
  static void destroy(void* p) { delete static_cast<Instance<M>*>(p); }

  /// fn()'s status, or DOMEL_ERR_RUNTIME with the exception's message
  /// ("unknown exception in <what>" for one that is not a std::exception).
  template <class F>
  static domel_status guarded(char* err, std::size_t cap, const char* what, F&& fn) {
    try {
      return fn();
    } catch (const std::exception& e) {
      write_message(err, cap, e.what());
    } catch (...) {
      write_message(err, cap, (std::string("unknown exception in ") + what).c_str());
    }
    return DOMEL_ERR_RUNTIME;
  }

  static domel_status contact(void* self, domel_contact_batch_v2* batch, char* err,
                              std::size_t cap) {
    if constexpr (is_contact_kind(M::kKind)) {
      return guarded(err, cap, "contact kernel", [&] {
        // through a const reference: kernels may run concurrently on one
        // instance (abi.h), so compute() must not modify the model
        const M& model = static_cast<Instance<M>*>(self)->model;
        for_each_pair_run(*batch, [&](domel_contact_batch_v2& run) { model.compute(run); });
        return DOMEL_OK;
      });
    } else {
      (void)self; (void)batch;
      write_message(err, cap, "not a contact model");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status insert(void* self, const domel_insert_request_v1* req,
                             domel_insert_output_v1* out, char* err, std::size_t cap) {
    if constexpr (M::kKind == DOMEL_KIND_INSERTION) {
      return guarded(err, cap, "insertion", [&] {
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
      });
    } else {
      (void)self; (void)req; (void)out;
      write_message(err, cap, "not an insertion model");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status control(void* self, domel_control_step_v1* step, char* err, std::size_t cap) {
    if constexpr (M::kKind == DOMEL_KIND_CONTROLLER) {
      return guarded(err, cap, "controller", [&] {
        static_cast<Instance<M>*>(self)->model.control(*step);
        return DOMEL_OK;
      });
    } else {
      (void)self; (void)step;
      write_message(err, cap, "not a controller");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status exchange(void* self, domel_fluid_exchange_v1* ex, char* err, std::size_t cap) {
    if constexpr (M::kKind == DOMEL_KIND_FLUID_COUPLER) {
      return guarded(err, cap, "fluid coupler", [&] {
        static_cast<Instance<M>*>(self)->model.exchange(*ex);
        return DOMEL_OK;
      });
    } else {
      (void)self; (void)ex;
      write_message(err, cap, "not a fluid coupler");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status fields(void* self, domel_fluid_fields_v1* out, char* err, std::size_t cap) {
    if constexpr (has_fields<M>::value) {
      return guarded(err, cap, "fluid fields", [&] {
        static_cast<Instance<M>*>(self)->model.fields(*out);
        return DOMEL_OK;
      });
    } else {
      (void)self; (void)out;
      write_message(err, cap, "no fields");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status limits(void* self, domel_fluid_limits_v1* out, char* err, std::size_t cap) {
    if constexpr (has_limits<M>::value) {
      return guarded(err, cap, "fluid limits", [&] {
        static_cast<Instance<M>*>(self)->model.limits(*out);
        return DOMEL_OK;
      });
    } else {
      (void)self; (void)out;
      write_message(err, cap, "no limits");
      return DOMEL_ERR_RUNTIME;
    }
  }

  /// The family table of M's kind.
  static const void* family() {
    if constexpr (is_contact_kind(M::kKind)) {
      static const domel_contact_family_v2 t = {sizeof(domel_contact_family_v2), history_slots<M>::value,
                                                &Export::contact,
                                                reads_masses<M>::value ? 0u : DOMEL_CONTACT_IGNORES_MASSES};
      return &t;
    } else if constexpr (M::kKind == DOMEL_KIND_INSERTION) {
      static const domel_insertion_family_v2 t = {sizeof(domel_insertion_family_v2), 0u, &Export::insert};
      return &t;
    } else if constexpr (M::kKind == DOMEL_KIND_CONTROLLER) {
      static const domel_controller_family_v1 t = {sizeof(domel_controller_family_v1), 0u, &Export::control};
      return &t;
    } else {
      static_assert(M::kKind == DOMEL_KIND_FLUID_COUPLER, "a model's kKind must be a domel_kind");
      static const domel_fluid_coupler_family_v1 t = {
          sizeof(domel_fluid_coupler_family_v1), 0u, &Export::exchange,
          has_fields<M>::value ? &Export::fields : nullptr, has_limits<M>::value ? &Export::limits : nullptr};
      return &t;
    }
  }

  static const domel_model_v2* descriptor() {
    static const domel_model_v2 d = {
        sizeof(domel_model_v2),
        static_cast<uint32_t>(M::kKind),
        M::kName,
        M::kVersion,
        M::kSummary,
        M::kSchema,
        &Export::create,
        &Export::destroy,
        family(),
    };
    return &d;
  }
};

template <class... Ms>
const domel_library_v2* library(const char* name, const char* version) {
  static const domel_model_v2* const models[] = {Export<Ms>::descriptor()...};
  static const domel_library_v2 lib = {sizeof(domel_library_v2),
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
  extern "C" DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) {         \
    return ::domel::sdk::detail::library<__VA_ARGS__>(LIBRARY_NAME, LIBRARY_VERSION);   \
  }
