// SPDX-License-Identifier: MIT
// Plugin loading and the model registry. Libraries are opened at run time
// with Boost.DLL; each must export domel_plugin_entry_v1 returning a
// domel_library_v1. Every refusal throws PluginError naming the file and the
// reason: unloadable file, missing entry symbol (or an entry of another ABI
// major), ABI major mismatch, newer ABI minor, a library that registers
// nothing, a model lacking a required callback, an unknown kind, an invalid
// parameter schema, or a (kind, name) already provided by another library.
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

/// A model as registered: a zero-filled copy of the plugin's descriptor
/// (so fields appended in later ABI minors read as null/0) plus its origin.
struct RegisteredModel {
  domel_model_v1 desc{};
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

/// A live model instance (RAII over create/destroy).
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
  uint32_t history_slots() const { return model_->desc.history_slots; }

  /// Run the contact kernel on a batch; a failure status throws PluginError.
  void contact(domel_contact_batch_v1& batch) const;
  /// Run an insertion (with one capacity retry).
  void insert(const domel_insert_request_v1& request, std::vector<double>& x, std::vector<double>& y,
              std::vector<double>& z, std::vector<double>& r) const;

 private:
  const RegisteredModel* model_;
  void* handle_ = nullptr;
};

/// The host services handed to plugins (logging through spdlog).
const domel_host_v1* host_services();

}  // namespace domel::platform
