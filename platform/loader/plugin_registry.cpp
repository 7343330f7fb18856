// SPDX-License-Identifier: MIT
// Plugin loading with Boost.DLL, descriptor checks and the model registry.
// Checks follow the GDExtension/OBS pattern: struct sizes first, then the
// ABI version, then each required member by name.
#include "loader/plugin_registry.hpp"

#include "core/interrupt.hpp"

#include <boost/dll/runtime_symbol_info.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>
#include <type_traits>

#include <elf.h>

namespace domel::platform {

namespace {

struct KindName { uint32_t kind; const char* name; };
constexpr KindName kKindNames[] = {
    {DOMEL_KIND_NORMAL, "normal"},       {DOMEL_KIND_DAMPING, "damping"},
    {DOMEL_KIND_TANGENTIAL, "tangential"}, {DOMEL_KIND_ROLLING, "rolling"},
    {DOMEL_KIND_TWISTING, "twisting"},   {DOMEL_KIND_INSERTION, "insertion"},
    {DOMEL_KIND_FLUID_COUPLER, "fluid_coupler"}, {DOMEL_KIND_CONTROLLER, "controller"}};

/// The leading members of an ABI 1 library description (domel_library_v1 of
/// SDK 1.x, frozen here): enough to name the library and its version in the
/// refusal. ABI 2 keeps the same leading members.
struct LibraryHeadV1 {
  uint32_t struct_size;
  uint32_t abi_major;
  uint32_t abi_minor;
  const char* name;
  const char* version;
};

const std::string kRuntimeAbi = std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR);

[[noreturn]] void refuse(const std::filesystem::path& file, const std::string& why) {
  throw PluginError("plugin '" + file.string() + "' refused: " + why);
}

/// A 64-bit ELF file whose headers reach past its end (a copy cut short, a
/// file still being written) is refused before dlopen: the dynamic loader
/// maps the segments its program headers name, and touching the pages past
/// the end of the file raises SIGBUS in the host (a plugin truncated to
/// 3,000 bytes did). Other files are left to dlopen, which refuses what it
/// cannot load with a message.
void refuse_cut_short_elf(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  Elf64_Ehdr eh{};
  if (!in.read(reinterpret_cast<char*>(&eh), sizeof eh)) return;  // too short to be an ELF: dlopen says so
  if (std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64) return;
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(file, ec);
  if (ec) return;
  auto reach = [&](std::uint64_t offset, std::uint64_t count, std::uint64_t each, const char* what) {
    if (count == 0) return;
    if (offset > size || each == 0 || count > (size - offset) / each)
      refuse(file, std::string("the file is cut short: its ELF ") + what + " reach past its end (" +
                       std::to_string(size) + " bytes); a copy that did not finish?");
  };
  reach(eh.e_phoff, eh.e_phnum, eh.e_phentsize, "program headers");
  if (eh.e_shoff != 0) reach(eh.e_shoff, eh.e_shnum, eh.e_shentsize, "section headers");
  if (eh.e_phentsize != sizeof(Elf64_Phdr)) return;  // dlopen refuses it
  in.seekg(static_cast<std::streamoff>(eh.e_phoff));
  for (unsigned k = 0; k < eh.e_phnum; ++k) {
    Elf64_Phdr ph{};
    if (!in.read(reinterpret_cast<char*>(&ph), sizeof ph)) return;
    if (ph.p_filesz > 0 && (ph.p_offset > size || ph.p_filesz > size - ph.p_offset))
      refuse(file, "the file is cut short: its ELF segment " + std::to_string(k) + " reaches byte " +
                       std::to_string(ph.p_offset + ph.p_filesz) + " of a file of " + std::to_string(size) +
                       " bytes; a copy that did not finish?");
  }
}

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

bool is_contact_kind(uint32_t k) {
  return k == DOMEL_KIND_NORMAL || k == DOMEL_KIND_DAMPING || k == DOMEL_KIND_TANGENTIAL ||
         k == DOMEL_KIND_ROLLING || k == DOMEL_KIND_TWISTING;
}

void PluginRegistry::load(const std::filesystem::path& path) {
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(path, ec);
  const auto file = ec ? path : canonical;
  for (const auto& lib : libraries_)
    if (lib.path == file) return;
  if (!std::filesystem::exists(file)) refuse(file, "file not found");

  refuse_cut_short_elf(file);
  boost::dll::shared_library handle;
  try {
    handle.load(boost::dll::fs::path(file.string()),
                boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
  } catch (const std::exception& e) {
    refuse(file, std::string("cannot be loaded as a shared library: ") + e.what());
  }
  if (!handle.has(DOMEL_ENTRY_SYMBOL)) {
    // ABI 1: refused, naming both versions (docs/sdk-guide.md, "Versions").
    // The v1 entry is called only to read the library's name and version.
    if (handle.has("domel_plugin_entry_v1")) {
      const LibraryHeadV1* old = nullptr;
      try {
        old = handle.get<const LibraryHeadV1*()>("domel_plugin_entry_v1")();
      } catch (const std::exception&) {
      }
      std::string built = "domel ABI 1";
      if (old != nullptr && old->struct_size >= sizeof(LibraryHeadV1))
        built = std::string("library '") + (old->name ? old->name : "") + "' " + (old->version ? old->version : "") +
                " was built for domel ABI " + std::to_string(old->abi_major) + "." + std::to_string(old->abi_minor);
      else
        built = "it was built for domel ABI 1.x";
      refuse(file, built + " (it exports 'domel_plugin_entry_v1'); this runtime speaks ABI " + kRuntimeAbi +
                       ": rebuild it against domel SDK " + std::to_string(DOMEL_ABI_MAJOR) +
                       " (docs/sdk-guide.md, \"Versions\")");
    }
    for (int major = DOMEL_ABI_MAJOR + 1; major <= 9; ++major) {
      const std::string other = "domel_plugin_entry_v" + std::to_string(major);
      if (handle.has(other))
        refuse(file, "it exports '" + other + "', i.e. it was built for domel ABI " + std::to_string(major) +
                         ".x; this runtime speaks ABI " + kRuntimeAbi + ": use a domel that speaks ABI " +
                         std::to_string(major) + ", or rebuild the plugin against domel SDK " +
                         std::to_string(DOMEL_ABI_MAJOR));
    }
    refuse(file, std::string("not a domel plugin: it does not export '") + DOMEL_ENTRY_SYMBOL + "'");
  }
  const domel_library_v2* lib = nullptr;
  try {
    lib = handle.get<const domel_library_v2*()>(DOMEL_ENTRY_SYMBOL)();
  } catch (const std::exception& e) {
    refuse(file, std::string("its entry function failed: ") + e.what());
  }
  if (lib == nullptr) refuse(file, "its entry function returned no library description");
  if (lib->struct_size < offsetof(domel_library_v2, models) + sizeof(lib->models))
    refuse(file, "its library description is truncated (struct_size " + std::to_string(lib->struct_size) +
                     ", expected at least " +
                     std::to_string(offsetof(domel_library_v2, models) + sizeof(lib->models)) + ")");

  const std::string lib_name = lib->name ? lib->name : "";
  const std::string lib_version = lib->version ? lib->version : "";
  const std::string who = "library '" + lib_name + "' " + lib_version;
  const std::string built = std::to_string(lib->abi_major) + "." + std::to_string(lib->abi_minor);
  if (lib->abi_major != DOMEL_ABI_MAJOR)
    refuse(file, who + " was built for domel ABI " + built + "; this runtime speaks ABI " + kRuntimeAbi +
                     (lib->abi_major > DOMEL_ABI_MAJOR
                          ? ": use a domel that speaks ABI " + std::to_string(lib->abi_major) +
                                ", or rebuild the plugin against domel SDK " + std::to_string(DOMEL_ABI_MAJOR)
                          : ": rebuild it against domel SDK " + std::to_string(DOMEL_ABI_MAJOR)));
  if (lib->abi_minor > DOMEL_ABI_MINOR)
    refuse(file, who + " was built for the newer domel ABI " + built + "; this runtime supports up to " +
                     kRuntimeAbi + ": upgrade domel or rebuild the plugin against this SDK");
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
    const domel_model_v2* d = lib->models[k];
    const std::string slot = "model #" + std::to_string(k);
    if (d == nullptr) refuse(file, who + ": " + slot + " is null");
    if (d->struct_size < offsetof(domel_model_v2, family) + sizeof(d->family))
      refuse(file, who + ": " + slot + " descriptor is truncated (struct_size " + std::to_string(d->struct_size) +
                       ", expected at least " + std::to_string(offsetof(domel_model_v2, family) + sizeof(d->family)) +
                       ")");
    RegisteredModel m;
    std::memcpy(&m.desc, d, std::min<std::size_t>(d->struct_size, sizeof(domel_model_v2)));
    m.desc.struct_size = sizeof(domel_model_v2);
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
    require(m.desc.family, "family");
    // The family table: copied zero-filled up to its struct_size; a required
    // callback beyond that size or null is missing, and named.
    // `Table::*member` is the family's required callback.
    auto table = [&](auto& out, const char* table_name, const char* callback, auto member) {
      using Table = std::remove_reference_t<decltype(out)>;
      const Table probe{};
      const std::size_t callback_end = static_cast<std::size_t>(reinterpret_cast<const char*>(&(probe.*member)) -
                                                                reinterpret_cast<const char*>(&probe)) +
                                       sizeof(probe.*member);
      const uint32_t size = *static_cast<const uint32_t*>(m.desc.family);
      if (size < sizeof(uint32_t))
        refuse(file, who + ": " + what + ": its " + table_name + " has struct_size " + std::to_string(size));
      std::memcpy(&out, m.desc.family, std::min<std::size_t>(size, sizeof(out)));
      out.struct_size = sizeof(out);
      if (size < callback_end)
        refuse(file, who + ": " + what + " lacks required callback '" + callback + "': its " + table_name +
                         " is " + std::to_string(size) + " bytes, the callback ends at byte " +
                         std::to_string(callback_end));
      if (out.*member == nullptr)
        refuse(file, who + ": " + what + " lacks required callback '" + callback + "' (" + table_name + ")");
    };
    if (is_contact_kind(m.desc.kind))
      table(m.contact, "domel_contact_family_v2", "contact", &domel_contact_family_v2::contact);
    else if (m.desc.kind == DOMEL_KIND_INSERTION)
      table(m.insertion, "domel_insertion_family_v2", "insert", &domel_insertion_family_v2::insert);
    else if (m.desc.kind == DOMEL_KIND_CONTROLLER)
      table(m.controller, "domel_controller_family_v1", "control", &domel_controller_family_v1::control);
    else if (m.desc.kind == DOMEL_KIND_FLUID_COUPLER)
      table(m.fluid_coupler, "domel_fluid_coupler_family_v1", "exchange", &domel_fluid_coupler_family_v1::exchange);
    m.library_name = lib_name;
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

/// The instance's side of its domel_host_v2: the context prefix and the
/// last error the plugin reported.
struct ModelInstance::HostContext {
  std::string prefix;
  mutable std::mutex mutex;
  std::string last_error;
  domel_host_v2 host{};

  static void log(void* context, int level, const char* message) {
    const auto* c = static_cast<const HostContext*>(context);
    const char* m = message ? message : "";
    switch (level) {
      case 0: spdlog::debug("[{}] {}", c->prefix, m); break;
      case 1: spdlog::info("[{}] {}", c->prefix, m); break;
      case 2: spdlog::warn("[{}] {}", c->prefix, m); break;
      default: spdlog::error("[{}] {}", c->prefix, m); break;
    }
  }
  static void error(void* context, domel_status code, const char* message) {
    auto* c = static_cast<HostContext*>(context);
    const char* m = message ? message : "";
    spdlog::error("[{}] error {}: {}", c->prefix, static_cast<int>(code), m);
    std::lock_guard<std::mutex> lock(c->mutex);
    c->last_error = m;
  }
  static int stop_requested(void*) { return stop_overdue() ? 1 : 0; }
};

ModelInstance::ModelInstance(const RegisteredModel& model, const nlohmann::json& params,
                             const std::string& where)
    : model_(&model), host_(std::make_unique<HostContext>()) {
  host_->prefix = std::string(kind_name(model.desc.kind)) + " model '" + model.name + "' (library '" +
                  model.library_name + "')" + (where.empty() ? std::string() : " at " + where);
  host_->host = {sizeof(domel_host_v2), DOMEL_ABI_MINOR, host_.get(), &HostContext::log, &HostContext::error,
                 &HostContext::stop_requested};
  char err[1024] = {0};
  const std::string text = params.dump();
  const domel_status st = model.desc.create(text.c_str(), &host_->host, &handle_, err, sizeof err);
  if (st != DOMEL_OK || handle_ == nullptr) {
    handle_ = nullptr;
    const std::string reported = last_error();
    throw PluginError((where.empty() ? std::string() : where + ": ") + kind_name(model.desc.kind) + " model '" + model.name +
                      "' refused its parameters: " + (err[0] ? err : reported.empty() ? "no message" : reported.c_str()));
  }
}

ModelInstance::~ModelInstance() {
  if (handle_) model_->desc.destroy(handle_);
}

const std::string& ModelInstance::context() const { return host_->prefix; }

std::string ModelInstance::last_error() const {
  std::lock_guard<std::mutex> lock(host_->mutex);
  return host_->last_error;
}

void ModelInstance::fail(const char* what, const char* err) const {
  const std::string reported = err[0] ? std::string() : last_error();
  throw PluginError(host_->prefix + ": " + what + " failed: " +
                    (err[0] ? std::string(err) : reported.empty() ? std::string("no message") : reported));
}

void ModelInstance::contact(domel_contact_batch_v2& batch) const {
  char err[1024] = {0};
  if (model_->contact.contact(handle_, &batch, err, sizeof err) != DOMEL_OK) fail("contact kernel", err);
}

bool ModelInstance::control_setup(const domel_control_setup_v1& setup) const {
  if (model_->controller.setup == nullptr) return false;
  char err[1024] = {0};
  if (model_->controller.setup(handle_, &setup, err, sizeof err) != DOMEL_OK) fail("setup", err);
  return true;
}

void ModelInstance::control(domel_control_step_v1& step) const {
  if (model_->controller.control == nullptr)
    throw PluginError(host_->prefix + ": is not a controller (it has no 'control' callback)");
  char err[1024] = {0};
  if (model_->controller.control(handle_, &step, err, sizeof err) != DOMEL_OK) fail("control", err);
}

void ModelInstance::exchange(domel_fluid_exchange_v1& ex) const {
  if (model_->fluid_coupler.exchange == nullptr)
    throw PluginError(host_->prefix + ": is not a fluid coupler (it has no 'exchange' callback)");
  char err[1024] = {0};
  if (model_->fluid_coupler.exchange(handle_, &ex, err, sizeof err) != DOMEL_OK) fail("exchange", err);
}

bool ModelInstance::fluid_fields(domel_fluid_fields_v1& out) const {
  if (model_->fluid_coupler.fields == nullptr) return false;
  out = domel_fluid_fields_v1{};
  out.struct_size = sizeof out;
  char err[1024] = {0};
  if (model_->fluid_coupler.fields(handle_, &out, err, sizeof err) != DOMEL_OK) fail("fields", err);
  return true;
}

bool ModelInstance::fluid_limits(domel_fluid_limits_v1& out) const {
  if (model_->fluid_coupler.limits == nullptr) return false;
  out = domel_fluid_limits_v1{};
  out.struct_size = sizeof out;
  char err[1024] = {0};
  if (model_->fluid_coupler.limits(handle_, &out, err, sizeof err) != DOMEL_OK) fail("limits", err);
  return true;
}

namespace {

/// The save_state and load_state of the instance's family (null if none).
std::pair<domel_save_state_fn, domel_load_state_fn> state_callbacks(const RegisteredModel& m) {
  if (m.desc.kind == DOMEL_KIND_CONTROLLER) return {m.controller.save_state, m.controller.load_state};
  if (m.desc.kind == DOMEL_KIND_FLUID_COUPLER) return {m.fluid_coupler.save_state, m.fluid_coupler.load_state};
  return {nullptr, nullptr};
}

}  // namespace

bool ModelInstance::has_state() const {
  const auto [save, load] = state_callbacks(*model_);
  return save != nullptr && load != nullptr;
}

std::vector<unsigned char> ModelInstance::save_state() const {
  const auto [save, load] = state_callbacks(*model_);
  (void)load;
  if (save == nullptr) throw PluginError(host_->prefix + ": cannot save its state (no save_state, ABI 2.3)");
  std::vector<unsigned char> bytes;
  domel_state_sink_v1 sink{sizeof(domel_state_sink_v1), 0, &bytes, [](void* host, const void* data, size_t n) {
                             auto* out = static_cast<std::vector<unsigned char>*>(host);
                             if (n > 0 && data == nullptr) return DOMEL_ERR_RUNTIME;
                             const auto* p = static_cast<const unsigned char*>(data);
                             out->insert(out->end(), p, p + n);
                             return DOMEL_OK;
                           }};
  char err[1024] = {0};
  if (save(handle_, &sink, err, sizeof err) != DOMEL_OK) fail("save_state", err);
  return bytes;
}

void ModelInstance::load_state(const std::vector<unsigned char>& bytes) const {
  const auto [save, load] = state_callbacks(*model_);
  (void)save;
  if (load == nullptr) throw PluginError(host_->prefix + ": cannot load a state (no load_state, ABI 2.3)");
  char err[1024] = {0};
  if (load(handle_, bytes.data(), bytes.size(), err, sizeof err) != DOMEL_OK) fail("load_state", err);
}

void ModelInstance::insert(const domel_insert_request_v1& request, std::vector<double>& x,
                           std::vector<double>& y, std::vector<double>& z, std::vector<double>& r,
                           std::vector<uint32_t>* component) const {
  constexpr uint32_t kUnset = 0xFFFFFFFFu;  // the fill a model that names no component leaves
  std::size_t capacity = 4096;
  for (int attempt = 0; attempt < 3; ++attempt) {
    x.resize(capacity); y.resize(capacity); z.resize(capacity); r.resize(capacity);
    if (component) component->assign(capacity, kUnset);
    domel_insert_output_v1 out{sizeof(domel_insert_output_v1), capacity, attempt ? capacity : 0, x.data(), y.data(),
                               z.data(), r.data(), component ? component->data() : nullptr};
    char err[1024] = {0};
    const domel_status st = model_->insertion.insert(handle_, &request, &out, err, sizeof err);
    if (st == DOMEL_OK) {
      x.resize(out.count); y.resize(out.count); z.resize(out.count); r.resize(out.count);
      if (component) {
        component->resize(out.count);
        if (std::find(component->begin(), component->end(), kUnset) != component->end())
          throw PluginError(host_->prefix + ": the model did not say which component of the mixture each particle "
                                            "is (ABI 2.4: rebuild it against this SDK and draw its sizes with "
                                            "SizeDistribution::draw, pushing each particle with its component)");
      }
      return;
    }
    if (st != DOMEL_ERR_CAPACITY) fail("insertion", err);
    capacity = out.count;
  }
  throw PluginError(host_->prefix + ": kept asking for a larger buffer");
}

}  // namespace domel::platform
