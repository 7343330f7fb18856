// SPDX-License-Identifier: MIT
// Plugin loading with Boost.DLL, descriptor checks and the model registry.
// Checks follow the GDExtension/OBS pattern: struct sizes first, then the
// ABI version, then each required member by name.
#include "loader/plugin_registry.hpp"

#include <boost/dll/runtime_symbol_info.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace domel::platform {

namespace {

struct KindName { uint32_t kind; const char* name; };
constexpr KindName kKindNames[] = {
    {DOMEL_KIND_NORMAL, "normal"},       {DOMEL_KIND_DAMPING, "damping"},
    {DOMEL_KIND_TANGENTIAL, "tangential"}, {DOMEL_KIND_ROLLING, "rolling"},
    {DOMEL_KIND_TWISTING, "twisting"},   {DOMEL_KIND_INSERTION, "insertion"},
    {DOMEL_KIND_FLUID, "fluid"},         {DOMEL_KIND_CONTROLLER, "controller"}};

bool is_contact_kind(uint32_t k) {
  return k == DOMEL_KIND_NORMAL || k == DOMEL_KIND_DAMPING || k == DOMEL_KIND_TANGENTIAL ||
         k == DOMEL_KIND_ROLLING || k == DOMEL_KIND_TWISTING;
}

[[noreturn]] void refuse(const std::filesystem::path& file, const std::string& why) {
  throw PluginError("plugin '" + file.string() + "' refused: " + why);
}

void host_log(void*, int level, const char* message) {
  const char* m = message ? message : "";
  switch (level) {
    case 0: spdlog::debug("[plugin] {}", m); break;
    case 1: spdlog::info("[plugin] {}", m); break;
    case 2: spdlog::warn("[plugin] {}", m); break;
    default: spdlog::error("[plugin] {}", m); break;
  }
}

const domel_host_v1 kHost = {sizeof(domel_host_v1), DOMEL_ABI_MINOR, nullptr, &host_log};

}  // namespace

const char* kind_name(uint32_t kind) {
  for (const auto& k : kKindNames)
    if (k.kind == kind) return k.name;
  return "unknown";
}

uint32_t kind_from_name(const std::string& name) {
  for (const auto& k : kKindNames)
    if (name == k.name) return k.kind;
  return 0;
}

const domel_host_v1* host_services() { return &kHost; }

void PluginRegistry::load(const std::filesystem::path& path) {
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(path, ec);
  const auto file = ec ? path : canonical;
  for (const auto& lib : libraries_)
    if (lib.path == file) return;
  if (!std::filesystem::exists(file)) refuse(file, "file not found");

  boost::dll::shared_library handle;
  try {
    handle.load(boost::dll::fs::path(file.string()),
                boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
  } catch (const std::exception& e) {
    refuse(file, std::string("cannot be loaded as a shared library: ") + e.what());
  }
  if (!handle.has(DOMEL_ENTRY_SYMBOL)) {
    for (int major = 2; major <= 9; ++major) {
      const std::string other = "domel_plugin_entry_v" + std::to_string(major);
      if (handle.has(other))
        refuse(file, "it exports '" + other + "', i.e. it was built against domel SDK ABI " +
                         std::to_string(major) + ".x; this domel loads ABI " +
                         std::to_string(DOMEL_ABI_MAJOR) + ".x plugins");
    }
    refuse(file, std::string("not a domel plugin: it does not export '") + DOMEL_ENTRY_SYMBOL + "'");
  }
  const domel_library_v1* lib = nullptr;
  try {
    lib = handle.get<const domel_library_v1*()>(DOMEL_ENTRY_SYMBOL)();
  } catch (const std::exception& e) {
    refuse(file, std::string("its entry function failed: ") + e.what());
  }
  if (lib == nullptr) refuse(file, "its entry function returned no library description");
  if (lib->struct_size < offsetof(domel_library_v1, models) + sizeof(lib->models))
    refuse(file, "its library description is truncated (struct_size " + std::to_string(lib->struct_size) + ")");

  const std::string lib_name = lib->name ? lib->name : "";
  const std::string lib_version = lib->version ? lib->version : "";
  const std::string who = "library '" + lib_name + "' " + lib_version;
  if (lib->abi_major != DOMEL_ABI_MAJOR)
    refuse(file, who + " was built against domel SDK ABI " + std::to_string(lib->abi_major) + "." +
                     std::to_string(lib->abi_minor) + "; this domel needs ABI major " +
                     std::to_string(DOMEL_ABI_MAJOR) + " (it speaks " + std::to_string(DOMEL_ABI_MAJOR) +
                     "." + std::to_string(DOMEL_ABI_MINOR) + ")");
  if (lib->abi_minor > DOMEL_ABI_MINOR)
    refuse(file, who + " was built against the newer domel SDK ABI " + std::to_string(lib->abi_major) + "." +
                     std::to_string(lib->abi_minor) + "; this domel supports up to " +
                     std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR) +
                     ": upgrade domel or rebuild the plugin against this SDK");
  if (lib_name.empty()) refuse(file, "its library description has no name");
  // The same library reached through two folders (build tree and install
  // prefix, or a folder listed twice): keep the first, say so in the debug log.
  for (const auto& other : libraries_)
    if (other.name == lib_name && other.version == lib_version) {
      spdlog::debug("plugin '{}': library '{}' {} already loaded from '{}'; skipped", file.string(), lib_name,
                    lib_version, other.path.string());
      return;
    }
  if (lib->model_count == 0 || lib->models == nullptr)
    refuse(file, who + " registers no models");

  // Check every model before registering any, so a refused library leaves no trace.
  std::vector<RegisteredModel> incoming;
  for (uint32_t k = 0; k < lib->model_count; ++k) {
    const domel_model_v1* d = lib->models[k];
    const std::string slot = "model #" + std::to_string(k);
    if (d == nullptr) refuse(file, who + ": " + slot + " is null");
    if (d->struct_size < offsetof(domel_model_v1, insert))
      refuse(file, who + ": " + slot + " descriptor is truncated (struct_size " +
                       std::to_string(d->struct_size) + ")");
    RegisteredModel m;
    std::memcpy(&m.desc, d, std::min<std::size_t>(d->struct_size, sizeof(domel_model_v1)));
    m.desc.struct_size = sizeof(domel_model_v1);
    if (m.desc.name == nullptr || *m.desc.name == '\0')
      refuse(file, who + ": " + slot + " lacks required member 'name'");
    m.name = m.desc.name;
    const std::string what = std::string(kind_name(m.desc.kind)) + " model '" + m.name + "'";
    if (std::string(kind_name(m.desc.kind)) == "unknown")
      refuse(file, who + ": model '" + m.name + "' has unknown kind " + std::to_string(m.desc.kind));
    auto require = [&](const void* p, const char* member) {
      if (p == nullptr) refuse(file, who + ": " + what + " lacks required member '" + member + "'");
    };
    require(m.desc.version, "version");
    require(m.desc.params_schema_json, "params_schema_json");
    require(reinterpret_cast<const void*>(m.desc.create), "create");
    require(reinterpret_cast<const void*>(m.desc.destroy), "destroy");
    if (is_contact_kind(m.desc.kind)) require(reinterpret_cast<const void*>(m.desc.contact), "contact");
    if (m.desc.kind == DOMEL_KIND_INSERTION) require(reinterpret_cast<const void*>(m.desc.insert), "insert");
    if (m.desc.kind == DOMEL_KIND_FLUID || m.desc.kind == DOMEL_KIND_CONTROLLER)
      refuse(file, who + ": " + what + ": this domel does not run " + kind_name(m.desc.kind) +
                       " models yet (this ABI has no callbacks for them)");
    m.version = m.desc.version;
    m.summary = m.desc.summary ? m.desc.summary : "";
    try {
      m.schema = nlohmann::json::parse(m.desc.params_schema_json);
    } catch (const std::exception& e) {
      refuse(file, who + ": " + what + " has an invalid parameter schema: " + e.what());
    }
    if (const RegisteredModel* other = find(m.desc.kind, m.name))
      refuse(file, who + ": duplicate " + what + ", already provided by '" +
                       libraries_[other->library].path.string() + "'");
    for (const auto& prev : incoming)
      if (prev.desc.kind == m.desc.kind && prev.name == m.name)
        refuse(file, who + ": duplicate " + what + " within the library");
    m.library = libraries_.size();
    incoming.push_back(std::move(m));
  }

  libraries_.push_back({file, lib_name, lib_version, lib->abi_major, lib->abi_minor});
  handles_.push_back(std::move(handle));
  for (auto& m : incoming) models_.push_back(std::move(m));
  spdlog::debug("loaded plugin library '{}' {} (ABI {}.{}) from {} with {} model(s)", lib_name,
                lib_version, lib->abi_major, lib->abi_minor, file.string(), lib->model_count);
}

std::size_t PluginRegistry::load_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return 0;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const auto ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".so" || ext == ".dylib" || ext == ".dll"))
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());  // deterministic order
  std::size_t loaded = 0;
  for (const auto& f : files) {
    try {
      load(f);
      ++loaded;
    } catch (const PluginError& e) {
      refused_.push_back(e.what());
    }
  }
  return loaded;
}

const RegisteredModel* PluginRegistry::find(uint32_t kind, const std::string& name) const {
  for (const auto& m : models_)
    if (m.desc.kind == kind && m.name == name) return &m;
  return nullptr;
}

std::vector<std::string> PluginRegistry::names(uint32_t kind) const {
  std::vector<std::string> out;
  for (const auto& m : models_)
    if (m.desc.kind == kind) out.push_back(m.name);
  return out;
}

std::vector<std::filesystem::path> default_plugin_directories() {
  std::vector<std::filesystem::path> dirs;
  try {
    const std::filesystem::path exe = boost::dll::program_location().string();
    dirs.push_back(exe.parent_path().parent_path() / "plugins");              // build tree
    dirs.push_back(exe.parent_path().parent_path() / "lib" / "domel" / "plugins");  // install
  } catch (const std::exception&) {
  }
  if (const char* env = std::getenv("DOMEL_PLUGIN_PATH")) {
    std::stringstream ss(env);
    std::string item;
    while (std::getline(ss, item, ':'))
      if (!item.empty()) dirs.emplace_back(item);
  }
  // Drop duplicates, keep order.
  std::vector<std::filesystem::path> unique;
  for (const auto& d : dirs) {
    std::error_code ec;
    const auto c = std::filesystem::weakly_canonical(d, ec);
    const auto key = ec ? d : c;
    if (std::find(unique.begin(), unique.end(), key) == unique.end()) unique.push_back(key);
  }
  return unique;
}

ModelInstance::ModelInstance(const RegisteredModel& model, const nlohmann::json& params,
                             const std::string& where)
    : model_(&model) {
  char err[1024] = {0};
  const std::string text = params.dump();
  const domel_status st = model.desc.create(text.c_str(), host_services(), &handle_, err, sizeof err);
  if (st != DOMEL_OK || handle_ == nullptr) {
    handle_ = nullptr;
    throw PluginError((where.empty() ? std::string() : where + ": ") + kind_name(model.desc.kind) + " model '" + model.name +
                      "' refused its parameters: " + (err[0] ? err : "no message"));
  }
}

ModelInstance::~ModelInstance() {
  if (handle_) model_->desc.destroy(handle_);
}

void ModelInstance::contact(domel_contact_batch_v1& batch) const {
  char err[1024] = {0};
  const domel_status st = model_->desc.contact(handle_, &batch, err, sizeof err);
  if (st != DOMEL_OK)
    throw PluginError(std::string(kind_name(model_->desc.kind)) + " model '" + model_->name +
                      "' failed: " + (err[0] ? err : "no message"));
}

void ModelInstance::insert(const domel_insert_request_v1& request, std::vector<double>& x,
                           std::vector<double>& y, std::vector<double>& z, std::vector<double>& r) const {
  std::size_t capacity = 4096;
  for (int attempt = 0; attempt < 3; ++attempt) {
    x.resize(capacity); y.resize(capacity); z.resize(capacity); r.resize(capacity);
    domel_insert_output_v1 out{sizeof(domel_insert_output_v1), capacity, attempt ? capacity : 0, x.data(), y.data(), z.data(), r.data()};
    char err[1024] = {0};
    const domel_status st = model_->desc.insert(handle_, &request, &out, err, sizeof err);
    if (st == DOMEL_OK) {
      x.resize(out.count); y.resize(out.count); z.resize(out.count); r.resize(out.count);
      return;
    }
    if (st != DOMEL_ERR_CAPACITY)
      throw PluginError("insertion model '" + model_->name + "' failed: " + (err[0] ? err : "no message"));
    capacity = out.count;
  }
  throw PluginError("insertion model '" + model_->name + "' kept asking for a larger buffer");
}

}  // namespace domel::platform
