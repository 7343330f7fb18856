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
//                   optional (ABI 2.5): void setup(const domel_control_setup_v1&);
//   fluid_coupler   void exchange(domel_fluid_exchange_v1&);
//                   optional: void fields(domel_fluid_fields_v1&);
//                             void limits(domel_fluid_limits_v1&);
//   controller and fluid_coupler, for checkpoints (ABI 2.3), both or neither:
//                   void save_state(domel::sdk::StateWriter&) const;
//                   void load_state(domel::sdk::StateReader&);
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

#include <algorithm>
#include <cstddef>
#include <cstdint>
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

/// Thrown by a model's long loop when Host::stop_requested() says the run is
/// to stop: the callback fails with the message (how far it got), and the
/// host ends the run as interrupted.
class StopRequested : public std::runtime_error {
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
  /// True once the run was asked to stop and the step in progress has not
  /// ended within a second (ABI 2.6; false from an older host): a long loop
  /// asks every so often and throws StopRequested.
  bool stop_requested() const {
    return h_ != nullptr &&
           h_->struct_size >= offsetof(domel_host_v2, stop_requested) + sizeof(h_->stop_requested) &&
           h_->stop_requested != nullptr && h_->stop_requested(h_->context) != 0;
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

/// A model's state for a checkpoint (abi.h, domel_state_sink_v1): values
/// and arrays of trivially copyable types, in the order the model chooses.
/// Host and plugin run on one machine, so the bytes are native.
class StateWriter {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "StateWriter::put takes trivially copyable values");
    const auto* p = reinterpret_cast<const unsigned char*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  /// An array: its length, then its elements.
  template <class T>
  void put(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>, "StateWriter::put takes arrays of trivially copyable values");
    put<std::uint64_t>(values.size());
    const auto* p = reinterpret_cast<const unsigned char*>(values.data());
    bytes_.insert(bytes_.end(), p, p + values.size() * sizeof(T));
  }
  const std::vector<unsigned char>& bytes() const { return bytes_; }

 private:
  std::vector<unsigned char> bytes_;
};

/// Reads what a StateWriter wrote, in the same order; a read beyond the end,
/// or bytes left over at the end, throws std::runtime_error (the host then
/// refuses the checkpoint naming the model).
class StateReader {
 public:
  StateReader(const void* data, std::size_t n) : p_(static_cast<const unsigned char*>(data)), n_(n) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>, "StateReader::get reads trivially copyable values");
    T value;
    take(&value, sizeof(T));
    return value;
  }
  /// An array written by StateWriter::put(vector); `expected` (if not
  /// SIZE_MAX) is the length the model's parameters imply.
  template <class T>
  std::vector<T> get_vector(std::size_t expected = static_cast<std::size_t>(-1)) {
    const auto n = get<std::uint64_t>();
    if (expected != static_cast<std::size_t>(-1) && n != expected)
      throw std::runtime_error("the saved state holds an array of " + std::to_string(n) + " values where " +
                               std::to_string(expected) + " were expected (another grid or parameter set?)");
    if (n > (n_ - at_) / (sizeof(T) ? sizeof(T) : 1))
      throw std::runtime_error("the saved state is truncated (an array of " + std::to_string(n) + " values)");
    std::vector<T> out(static_cast<std::size_t>(n));
    take(out.data(), out.size() * sizeof(T));
    return out;
  }
  /// Throws if bytes are left: the state was written by another layout.
  void finish() const {
    if (at_ != n_)
      throw std::runtime_error("the saved state has " + std::to_string(n_ - at_) + " bytes more than this model reads");
  }

 private:
  void take(void* out, std::size_t k) {
    if (k > n_ - at_) throw std::runtime_error("the saved state is truncated");
    if (k) std::memcpy(out, p_ + at_, k);
    at_ += k;
  }
  const unsigned char* p_;
  std::size_t n_;
  std::size_t at_ = 0;
};

/// Particles produced by an insertion model (radii already include alpha).
/// A model that draws its sizes from a mixture (SizeDistribution::draw)
/// pushes each particle with its component; the host reads them (ABI 2.4)
/// only when every particle has one.
struct Inserted {
  std::vector<double> x, y, z, r;
  std::vector<std::uint32_t> component;  ///< per particle when pushed with one, else empty
  /// The most particles the host accepts (the request's max_count; 0: no
  /// limit): push() beyond it, or expect() of more, throws.
  std::size_t limit = 0;
  void push(double px, double py, double pz, double pr) {
    if (limit != 0 && r.size() >= limit) too_many("more than " + std::to_string(limit));
    x.push_back(px); y.push_back(py); z.push_back(pz); r.push_back(pr);
  }
  /// The same, for a particle of component `c` of a mixture.
  void push(double px, double py, double pz, double pr, std::uint32_t c) {
    push(px, py, pz, pr);
    component.resize(r.size() - 1, kNoComponent);
    component.push_back(c);
  }
  static constexpr std::uint32_t kNoComponent = 0xFFFFFFFFu;
  /// Call before allocating for `n` particles: throws when n exceeds the limit.
  void expect(double n) const {
    if (limit != 0 && n > static_cast<double>(limit)) too_many("about " + std::to_string(static_cast<unsigned long long>(std::min(n, 1e19))));
  }
  std::size_t size() const { return r.size(); }

 private:
  [[noreturn]] void too_many(const std::string& count) const {
    throw std::runtime_error("the insertion would place " + count + " particles, more than the " +
                             std::to_string(limit) + " the run accepts (run.max_particles): check the units of "
                             "the region and of the diameters, or raise run.max_particles");
  }
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

/// A controller or fluid coupler may keep state for checkpoints (ABI 2.3):
/// `void save_state(StateWriter&) const` and `void load_state(StateReader&)`.
template <class M, class = void>
struct has_state : std::false_type {};
template <class M>
struct has_state<M, std::void_t<decltype(std::declval<const M&>().save_state(std::declval<StateWriter&>())),
                                decltype(std::declval<M&>().load_state(std::declval<StateReader&>()))>>
    : std::true_type {};

/// A controller may provide `void setup(const domel_control_setup_v1&)`
/// (ABI 2.5): its coupling's derived values (time steps, steps per control
/// interval, the grid, the inflow cells), once before the run; it throws
/// ParameterError to refuse them.
template <class M, class = void>
struct has_setup : std::false_type {};
template <class M>
struct has_setup<M, std::void_t<decltype(std::declval<M&>().setup(std::declval<const domel_control_setup_v1&>()))>>
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
          if (req->struct_size >= offsetof(domel_insert_request_v1, max_count) + sizeof(req->max_count))
            inst->last.limit = req->max_count;
          inst->model.insert(*req, inst->last);
        }
        const std::size_t n = inst->last.size();
        out->count = n;
        if (n > out->capacity) return DOMEL_ERR_CAPACITY;
        for (std::size_t k = 0; k < n; ++k) {
          out->x[k] = inst->last.x[k]; out->y[k] = inst->last.y[k];
          out->z[k] = inst->last.z[k]; out->r[k] = inst->last.r[k];
        }
        // ABI 2.4: the mixture components, when the host asks and every particle has one
        if (out->struct_size >= offsetof(domel_insert_output_v1, component) + sizeof(out->component) &&
            out->component != nullptr && inst->last.component.size() == n)
          for (std::size_t k = 0; k < n; ++k) out->component[k] = inst->last.component[k];
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

  static domel_status control_setup(void* self, const domel_control_setup_v1* setup, char* err, std::size_t cap) {
    if constexpr (has_setup<M>::value) {
      try {
        static_cast<Instance<M>*>(self)->model.setup(*setup);
        return DOMEL_OK;
      } catch (const ParameterError& e) {
        write_message(err, cap, e.what());
        return DOMEL_ERR_PARAMETER;
      } catch (const std::exception& e) {
        write_message(err, cap, e.what());
      } catch (...) {
        write_message(err, cap, "unknown exception in controller setup");
      }
      return DOMEL_ERR_RUNTIME;
    } else {
      (void)self; (void)setup;
      write_message(err, cap, "no setup");
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

  static domel_status save_state(void* self, const domel_state_sink_v1* sink, char* err, std::size_t cap) {
    if constexpr (has_state<M>::value) {
      return guarded(err, cap, "save_state", [&] {
        StateWriter w;
        static_cast<const Instance<M>*>(self)->model.save_state(w);
        if (sink == nullptr || sink->write == nullptr) throw std::runtime_error("no state sink");
        return sink->write(sink->host, w.bytes().data(), w.bytes().size());
      });
    } else {
      (void)self; (void)sink;
      write_message(err, cap, "no state");
      return DOMEL_ERR_RUNTIME;
    }
  }

  static domel_status load_state(void* self, const void* data, std::size_t n, char* err, std::size_t cap) {
    if constexpr (has_state<M>::value) {
      return guarded(err, cap, "load_state", [&] {
        StateReader r(data, n);
        static_cast<Instance<M>*>(self)->model.load_state(r);
        r.finish();
        return DOMEL_OK;
      });
    } else {
      (void)self; (void)data; (void)n;
      write_message(err, cap, "no state");
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
      static const domel_controller_family_v1 t = {sizeof(domel_controller_family_v1), 0u, &Export::control,
                                                   has_state<M>::value ? &Export::save_state : nullptr,
                                                   has_state<M>::value ? &Export::load_state : nullptr,
                                                   has_setup<M>::value ? &Export::control_setup : nullptr};
      return &t;
    } else {
      static_assert(M::kKind == DOMEL_KIND_FLUID_COUPLER, "a model's kKind must be a domel_kind");
      static const domel_fluid_coupler_family_v1 t = {
          sizeof(domel_fluid_coupler_family_v1), 0u, &Export::exchange,
          has_fields<M>::value ? &Export::fields : nullptr, has_limits<M>::value ? &Export::limits : nullptr,
          has_state<M>::value ? &Export::save_state : nullptr, has_state<M>::value ? &Export::load_state : nullptr};
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
