// SPDX-License-Identifier: MIT
// Plugin loading and the model registry. Libraries are opened at run time
// with Boost.DLL; each must export domel_plugin_entry_v2 returning a
// domel_library_v2. Every refusal throws PluginError naming the file and the
// reason: unloadable file, missing entry symbol, an ABI 1 plugin or one of a
// future major (both versions named), newer ABI minor, a library that
// registers nothing, a model lacking a required member or family callback
// (named), an unknown kind, an invalid parameter schema, or a (kind, name)
// already provided by another library.
// Libraries stay loaded for the registry's lifetime, so model instances
// never outlive their code.
#pragma once

#include "core/error.hpp"

#include <domel/sdk/abi.h>

#include <boost/dll/shared_library.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

/// "normal", "damping", ... for a kind; "unknown" otherwise.
const char* kind_name(uint32_t kind);
/// Kind from its scenario/CLI name; 0 if unknown.
uint32_t kind_from_name(const std::string& name);

struct LibraryInfo {
  std::filesystem::path path;
  std::string name;
  std::string version;
  uint32_t abi_major = 0;
  uint32_t abi_minor = 0;
};

/// A model as registered: zero-filled copies of the plugin's descriptor and
/// of its family table (so fields appended in later ABI minors read as
/// null/0) plus its origin. Only the table of the model's family is filled.
struct RegisteredModel {
  domel_model_v2 desc{};
  domel_contact_family_v2 contact{};
  domel_insertion_family_v2 insertion{};
  domel_controller_family_v1 controller{};
  domel_fluid_coupler_family_v1 fluid_coupler{};
  std::string library_name;
  std::string name;
  std::string version;
  std::string summary;
  nlohmann::json schema;
  std::size_t library = 0;  ///< index into PluginRegistry::libraries()
};

class PluginRegistry {
 public:
  PluginRegistry() = default;
  PluginRegistry(const PluginRegistry&) = delete;
  PluginRegistry& operator=(const PluginRegistry&) = delete;

  /// Load one library (idempotent for the same canonical path).
  void load(const std::filesystem::path& path);
  /// Load every shared library (*.so, *.dylib, *.dll) directly in `dir`.
  /// A missing directory is skipped. A library that is refused does not stop
  /// the scan: its message is kept in refused() for the caller to report.
  /// Returns the number of libraries loaded.
  std::size_t load_directory(const std::filesystem::path& dir);
  const std::vector<std::string>& refused() const { return refused_; }

  const RegisteredModel* find(uint32_t kind, const std::string& name) const;
  std::vector<std::string> names(uint32_t kind) const;
  const std::vector<RegisteredModel>& models() const { return models_; }
  const std::vector<LibraryInfo>& libraries() const { return libraries_; }

 private:
  std::vector<LibraryInfo> libraries_;
  std::vector<boost::dll::shared_library> handles_;
  std::vector<RegisteredModel> models_;
  std::vector<std::string> refused_;
};

/// Folders searched for plugins, in order: the built-in folder found from the
/// executable's own location (build tree: <build>/bin/../plugins; install:
/// <prefix>/bin/../lib/domel/plugins), then each entry of $DOMEL_PLUGIN_PATH
/// (':'-separated). No compiled-in absolute path: an installed domel never
/// scans the tree it was built in.
std::vector<std::filesystem::path> default_plugin_directories();

/// True for the five contact-stage kinds (the contact family).
bool is_contact_kind(uint32_t kind);

/// A live model instance (RAII over create/destroy) with its own host
/// services (domel_host_v2): the plugin's log lines and reported errors are
/// prefixed with the model's kind, name, library and `where`.
class ModelInstance {
 public:
  /// Calls the plugin's create; a refusal becomes PluginError with the
  /// plugin's message, prefixed by `where` (e.g. the scenario location).
  ModelInstance(const RegisteredModel& model, const nlohmann::json& params, const std::string& where);
  ~ModelInstance();
  ModelInstance(const ModelInstance&) = delete;
  ModelInstance& operator=(const ModelInstance&) = delete;

  const RegisteredModel& model() const { return *model_; }
  void* handle() const { return handle_; }
  uint32_t history_slots() const { return model_->contact.history_slots; }
  /// Whether the contact stage reads the batch's mass_i/mass_j (it did not
  /// declare DOMEL_CONTACT_IGNORES_MASSES; a 2.0 table always reads them).
  bool reads_masses() const { return (model_->contact.flags & DOMEL_CONTACT_IGNORES_MASSES) == 0; }
  /// "rolling model 'epsd' (library 'third_party_rolling') at <where>": the prefix of its messages.
  const std::string& context() const;
  /// The last error the plugin reported through the host's error service ("" if none).
  std::string last_error() const;

  /// Run the contact kernel on a batch; a failure status throws PluginError.
  void contact(domel_contact_batch_v2& batch) const;
  /// Run an insertion (with one capacity retry). With `component`, also
  /// each particle's mixture component (ABI 2.4); a model that does not say
  /// for every particle is refused (PluginError).
  void insert(const domel_insert_request_v1& request, std::vector<double>& x, std::vector<double>& y,
              std::vector<double>& z, std::vector<double>& r, std::vector<uint32_t>* component = nullptr) const;
  /// Hand a controller its coupling's derived values (ABI 2.5's optional
  /// setup; false: the model takes none). A refusal throws PluginError with
  /// the model's message.
  bool control_setup(const domel_control_setup_v1& setup) const;
  /// Run a controller on one control interval.
  void control(domel_control_step_v1& step) const;
  /// Run a fluid coupler's exchange of one coupling interval.
  void exchange(domel_fluid_exchange_v1& exchange) const;
  /// A fluid coupler's fields (false: it provides none; ABI 2.2's optional callback).
  bool fluid_fields(domel_fluid_fields_v1& out) const;
  /// A fluid coupler's stability limit (false: it reports none).
  bool fluid_limits(domel_fluid_limits_v1& out) const;
  /// Whether a controller or fluid coupler can save and load its state
  /// (ABI 2.3's optional save_state and load_state, both present).
  bool has_state() const;
  /// Its state for a checkpoint; throws PluginError when it fails or has no
  /// save_state.
  std::vector<unsigned char> save_state() const;
  /// Restore a state save_state() gave (on a fresh instance); a refusal
  /// throws PluginError with the plugin's message.
  void load_state(const std::vector<unsigned char>& bytes) const;

  struct HostContext;  ///< the instance's side of domel_host_v2 (plugin_registry.cpp)

 private:
  [[noreturn]] void fail(const char* what, const char* err) const;
  const RegisteredModel* model_;
  std::unique_ptr<HostContext> host_;
  void* handle_ = nullptr;
};

}  // namespace domel::platform
