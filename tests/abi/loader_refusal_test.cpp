// SPDX-License-Identifier: MIT
//
// ABI acceptance tests for the plugin loader. Each refusal case loads a
// deliberately broken plugin library built from tests/abi/broken/ and checks
// that PluginRegistry::load throws PluginError whose message names the file
// ("plugin '<canonical path>' refused: ...") and the specific reason. Further
// tests cover what the host does with a valid plugin that misbehaves at run
// time (create refusing its parameters, a kernel failing) and the registry's
// bookkeeping: refused libraries leave no trace, load_directory keeps going
// past a broken library, and loading the same file twice is a no-op.
#include "core/error.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"

#include "log_capture.hpp"

#include <domel/sdk/abi.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <iterator>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;
using domel::platform::ModelInstance;
using domel::platform::PluginError;
using domel::platform::PluginRegistry;

fs::path module_file(const char* dir, const std::string& name) {
  return fs::path(dir) / (std::string(DOMEL_ABI_MODULE_PREFIX) + name + DOMEL_ABI_MODULE_SUFFIX);
}
fs::path broken(const std::string& name) { return module_file(DOMEL_ABI_BROKEN_DIR, name); }
fs::path good(const std::string& name) { return module_file(DOMEL_ABI_GOOD_DIR, name); }

/// The path as the registry reports it.
std::string shown(const fs::path& p) { return fs::weakly_canonical(p).string(); }

/// Load `file` into `registry`, expecting a refusal; returns the message
/// ("" and a test failure if the library was accepted). Checks the common
/// "plugin '<file>' refused: " prefix and prints the message for the record.
std::string refusal(PluginRegistry& registry, const fs::path& file) {
  try {
    registry.load(file);
  } catch (const PluginError& e) {
    const std::string message = e.what();
    std::cout << "[refusal] " << message << "\n";
    const std::string prefix = "plugin '" + shown(file) + "' refused: ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << "message does not start with \"" << prefix << "\": " << message;
    return message;
  }
  ADD_FAILURE() << file << " was accepted, expected a refusal";
  return "";
}

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "missing \"" << (needle) << "\" in: " << (haystack)

/// A contact batch of n contacts with every array allocated (one rolling or
/// twisting stage reads kinematics and fn and adds torque).
struct Batch {
  explicit Batch(uint32_t n)
      : overlap(n, 1e-5), nx(n, 0.0), ny(n, 0.0), nz(n, 1.0), r_eff(n, 5e-4), m_eff(n, 1e-3), radius_i(n, 1e-3),
        radius_j(n, 1e-3), mass(n, 2e-3), vn(n, 0.1), vt(n, 0.0), wx(n, 0.0), wy(n, 0.0), wz(n, 10.0), out(n, 0.0),
        fn(n, 2.0), tqx(n, 0.0), tqy(n, 0.0), tqz(n, 0.0) {
    pair.struct_size = sizeof pair;
    pair.youngs_eff = 1e7;
    pair.shear_eff = 4e6;
    pair.restitution = 0.9;
    pair.friction = 0.5;
    pair.coarse_grain = 1.0;
    b.struct_size = sizeof b;
    b.n = n;
    b.dt = 1e-6;
    b.pair = &pair;
    b.overlap = overlap.data();
    b.nx = nx.data(); b.ny = ny.data(); b.nz = nz.data();
    b.r_eff = r_eff.data(); b.m_eff = m_eff.data();
    b.radius_i = radius_i.data(); b.radius_j = radius_j.data();
    b.mass_i = mass.data(); b.mass_j = mass.data();
    b.vn = vn.data();
    b.vtx = vt.data(); b.vty = vt.data(); b.vtz = vt.data();
    b.wx = wx.data(); b.wy = wy.data(); b.wz = wz.data();
    b.fn_elastic = out.data(); b.kn = out.data(); b.kn_tangent = out.data(); b.contact_radius = out.data();
    b.fn_damping = out.data(); b.eta_n = out.data();
    b.fn = fn.data();
    b.ftx = out.data(); b.fty = out.data(); b.ftz = out.data();
    b.tqx = tqx.data(); b.tqy = tqy.data(); b.tqz = tqz.data();
  }
  domel_pair_v2 pair{};
  std::vector<double> overlap, nx, ny, nz, r_eff, m_eff, radius_i, radius_j, mass, vn, vt, wx, wy, wz, out, fn, tqx, tqy, tqz;
  domel_contact_batch_v2 b{};
};

/// Every broken library of tests/abi/broken, by file stem.
const std::vector<std::string> kBroken = {"abi1_plugin",      "abi_major_3",      "entry_v3_only",
                                          "not_a_plugin",     "missing_create",   "missing_contact",
                                          "missing_control",  "missing_exchange", "no_models",
                                          "duplicate_within", "bad_schema",       "newer_minor"};

const std::string kRuntime = std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR);

}  // namespace

// Guards the fixtures: the good plugins load and work, so every refusal below is due to its one defect.
TEST(AbiLoader, ValidPluginsLoadAndRun) {
  PluginRegistry registry;
  registry.load(good("good_plugin"));
  registry.load(good("failing_kernel"));
  ASSERT_EQ(registry.libraries().size(), 2u);
  const auto* rolling = registry.find(DOMEL_KIND_ROLLING, "abi_good_rolling");
  ASSERT_NE(rolling, nullptr);
  EXPECT_EQ(rolling->version, "1.2.3");
  EXPECT_EQ(registry.libraries()[rolling->library].path.string(), shown(good("good_plugin")));
  ASSERT_NE(registry.find(DOMEL_KIND_TWISTING, "abi_failing_twisting"), nullptr);

  ModelInstance instance(*rolling, {{"model", "abi_good_rolling"}, {"coefficient", 0.1}}, "test");
  Batch batch(2);
  instance.contact(batch.b);
  // -mu_r R* F_n along omega (z): -0.1 * 5e-4 * 2.
  EXPECT_DOUBLE_EQ(batch.tqz[0], -1e-4);
  EXPECT_DOUBLE_EQ(batch.tqz[1], -1e-4);
  EXPECT_EQ(batch.tqx[0], 0.0);
}

// Guards ABI 2.1's masses on demand (abi.h, DOMEL_CONTACT_IGNORES_MASSES): a C++-layer model that
// does not declare kReadsMasses = false, and a contact table of the 2.0 size (no flags), both get
// the masses; the built-in models declare that they never read them.
TEST(AbiLoader, MassesAreFilledUnlessEveryStageDeclaresItIgnoresThem) {
  PluginRegistry registry;
  registry.load(good("good_plugin"));
  registry.load(good("failing_kernel"));
  ModelInstance good_rolling(*registry.find(DOMEL_KIND_ROLLING, "abi_good_rolling"),
                             {{"model", "abi_good_rolling"}, {"coefficient", 0.1}}, "test");
  EXPECT_TRUE(good_rolling.reads_masses());
  ModelInstance older_table(*registry.find(DOMEL_KIND_TWISTING, "abi_failing_twisting"),
                            {{"model", "abi_failing_twisting"}}, "test");
  EXPECT_TRUE(older_table.reads_masses());
  EXPECT_EQ(registry.find(DOMEL_KIND_TWISTING, "abi_failing_twisting")->contact.flags, 0u);
}

// Guards the ABI-1 policy (docs/sdk-guide.md, "Versions"): a plugin built against SDK 1.1
// (domel_plugin_entry_v1) is refused, naming its ABI 1.1, this runtime's ABI and the fix.
TEST(AbiLoader, RefusesAbi1PluginNamingBothVersions) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("abi1_plugin"));
  EXPECT_CONTAINS(m, "library 'abi1_plugin' 0.9.0 was built for domel ABI 1.1");
  EXPECT_CONTAINS(m, "this runtime speaks ABI " + kRuntime);
  EXPECT_CONTAINS(m, "rebuild it against domel SDK " + std::to_string(DOMEL_ABI_MAJOR));
  EXPECT_TRUE(registry.models().empty());
}

// Guards case (a), the future direction: a library description claiming ABI 3.0 is refused on the major,
// naming both versions.
TEST(AbiLoader, RefusesFutureAbiMajorNamingBothVersions) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("abi_major_3"));
  EXPECT_CONTAINS(m, "library 'abi_major_3'");
  EXPECT_CONTAINS(m, "built for domel ABI 3.0");
  EXPECT_CONTAINS(m, "this runtime speaks ABI " + kRuntime);
  EXPECT_TRUE(registry.models().empty());
}

// Guards case (b): an SDK-3 plugin (only domel_plugin_entry_v3) is named as such, not as "not a plugin".
TEST(AbiLoader, RefusesEntryOfAFutureMajor) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("entry_v3_only"));
  EXPECT_CONTAINS(m, "exports 'domel_plugin_entry_v3'");
  EXPECT_CONTAINS(m, "built for domel ABI 3.x");
  EXPECT_CONTAINS(m, "this runtime speaks ABI " + kRuntime);
}

// Guards case (c): a shared library without the entry symbol is refused as "not a domel plugin".
TEST(AbiLoader, RefusesLibraryWithoutEntrySymbol) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("not_a_plugin"));
  EXPECT_CONTAINS(m, "not a domel plugin");
  EXPECT_CONTAINS(m, "does not export 'domel_plugin_entry_v2'");
}

// Guards case (d): a model whose create is NULL is refused, naming the model and 'create'.
TEST(AbiLoader, RefusesModelWithoutCreate) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("missing_create"));
  EXPECT_CONTAINS(m, "normal model 'missing_create_normal'");
  EXPECT_CONTAINS(m, "lacks required member 'create'");
}

// Guards case (e): a contact-kind model whose family table has a NULL kernel is refused, naming 'contact'.
TEST(AbiLoader, RefusesContactModelWithoutKernel) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("missing_contact"));
  EXPECT_CONTAINS(m, "tangential model 'missing_contact_tangential'");
  EXPECT_CONTAINS(m, "lacks required callback 'contact' (domel_contact_family_v2)");
}

// Guards case (e) for the controller family: a table whose struct_size ends before 'control' is refused, naming it.
TEST(AbiLoader, RefusesControllerWithTruncatedTable) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("missing_control"));
  EXPECT_CONTAINS(m, "controller model 'missing_control_controller'");
  EXPECT_CONTAINS(m, "lacks required callback 'control'");
  EXPECT_CONTAINS(m, "domel_controller_family_v1 is " + std::to_string(offsetof(domel_controller_family_v1, control)) +
                         " bytes");
}

// Guards case (e) for the fluid_coupler family: a NULL 'exchange' is refused, naming it.
TEST(AbiLoader, RefusesFluidCouplerWithoutExchange) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("missing_exchange"));
  EXPECT_CONTAINS(m, "fluid_coupler model 'missing_exchange_coupler'");
  EXPECT_CONTAINS(m, "lacks required callback 'exchange' (domel_fluid_coupler_family_v1)");
}

// Guards case (f): a library with model_count 0 is refused as registering nothing.
TEST(AbiLoader, RefusesLibraryThatRegistersNothing) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("no_models"));
  EXPECT_CONTAINS(m, "library 'no_models'");
  EXPECT_CONTAINS(m, "registers no models");
}

// Guards case (g): a (kind, name) already provided by another library is refused, naming that library's file.
TEST(AbiLoader, RefusesDuplicateModelAcrossLibraries) {
  PluginRegistry registry;
  registry.load(good("good_plugin"));
  const std::string m = refusal(registry, broken("duplicate_of_good"));
  EXPECT_CONTAINS(m, "duplicate rolling model 'abi_good_rolling'");
  EXPECT_CONTAINS(m, "already provided by '" + shown(good("good_plugin")) + "'");
  // The first registration stands.
  const auto* kept = registry.find(DOMEL_KIND_ROLLING, "abi_good_rolling");
  ASSERT_NE(kept, nullptr);
  EXPECT_EQ(kept->version, "1.2.3");
}

// Guards case (g): the same (kind, name) twice inside one library is refused.
TEST(AbiLoader, RefusesDuplicateModelWithinLibrary) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("duplicate_within"));
  EXPECT_CONTAINS(m, "duplicate normal model 'duplicate_twin'");
  EXPECT_CONTAINS(m, "within the library");
  EXPECT_TRUE(registry.models().empty());
}

// Guards case (h): a params_schema_json that is not JSON is refused at load time.
TEST(AbiLoader, RefusesInvalidParameterSchema) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("bad_schema"));
  EXPECT_CONTAINS(m, "rolling model 'bad_schema_rolling'");
  EXPECT_CONTAINS(m, "invalid parameter schema");
}

// Guards case (i): a library built against a newer ABI minor than the host is refused as "newer".
TEST(AbiLoader, RefusesNewerAbiMinor) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("newer_minor"));
  EXPECT_CONTAINS(m, "newer");
  EXPECT_CONTAINS(m, "ABI " + std::to_string(DOMEL_ABI_MAJOR) + "." + std::to_string(DOMEL_ABI_MINOR + 1));
  EXPECT_CONTAINS(m, "supports up to " + kRuntime);
}

// Guards case (j): a path that does not exist is refused with "not found".
TEST(AbiLoader, RefusesMissingFile) {
  PluginRegistry registry;
  const std::string m = refusal(registry, broken("does_not_exist"));
  EXPECT_CONTAINS(m, "not found");
}

// A plugin file cut short (a copy that did not finish, or one node's damaged
// copy) is refused naming the cut: dlopen would map the segments its headers
// name past the end of the file, and the first touch raised SIGBUS in the
// host (a copy cut to 3,000 bytes did). Cut at the start of its sections, in
// the middle and one byte short of its end.
TEST(AbiLoader, RefusesALibraryCutShortInsteadOfCrashing) {
  const fs::path whole = good("good_plugin");
  const auto size = fs::file_size(whole);
  std::ifstream in(whole, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path dir = fs::temp_directory_path() / ("domel_cut_plugin_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const std::uintmax_t cut : {std::uintmax_t{3000}, size / 2, size - 1}) {
    SCOPED_TRACE("cut to " + std::to_string(cut) + " of " + std::to_string(size) + " bytes");
    const fs::path file = dir / ("libcut_" + std::to_string(cut) + ".so");
    std::ofstream(file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(cut));
    PluginRegistry registry;
    const std::string m = refusal(registry, file);
    EXPECT_CONTAINS(m, "cut short");
    EXPECT_TRUE(registry.models().empty());
  }
  fs::remove_all(dir);
}

// Guards case (k): create() refusing bad parameters becomes PluginError with the model name and the plugin's message.
TEST(AbiLoader, CreateRefusalCarriesPluginMessage) {
  PluginRegistry registry;
  registry.load(good("good_plugin"));
  const auto* model = registry.find(DOMEL_KIND_ROLLING, "abi_good_rolling");
  ASSERT_NE(model, nullptr);
  const std::string where = "scenario.json: at /subdomains/0/contact/rolling";
  const std::vector<std::pair<nlohmann::json, std::string>> cases = {
      {{{"coefficient", -1.0}}, "abi_good_rolling wants a positive 'coefficient', got -1"},
      {nlohmann::json::object(), "abi_good_rolling needs a 'coefficient'"},
      {{{"coefficient", "large"}}, "expected a number for 'coefficient'"}};  // the SDK's Params message
  for (const auto& [bad, own_message] : cases) {
    try {
      ModelInstance instance(*model, bad, where);
      ADD_FAILURE() << "create accepted " << bad.dump();
    } catch (const PluginError& e) {
      const std::string m = e.what();
      std::cout << "[create refusal] " << m << "\n";
      EXPECT_EQ(m.rfind(where + ": ", 0), 0u) << m;
      EXPECT_CONTAINS(m, "rolling model 'abi_good_rolling' refused its parameters: ");
      EXPECT_CONTAINS(m, own_message);
    }
  }
}

// Guards case (l): a kernel returning DOMEL_ERR_RUNTIME throws PluginError with its message; the host stays usable.
TEST(AbiLoader, KernelFailureBecomesPluginError) {
  PluginRegistry registry;
  registry.load(good("failing_kernel"));
  const auto* model = registry.find(DOMEL_KIND_TWISTING, "abi_failing_twisting");
  ASSERT_NE(model, nullptr);
  ModelInstance instance(*model, nlohmann::json::object(), "test");
  Batch batch(3);
  for (int call = 0; call < 2; ++call) {  // a second call proves the instance survived the first failure
    try {
      instance.contact(batch.b);
      ADD_FAILURE() << "the failing kernel reported success";
    } catch (const PluginError& e) {
      const std::string m = e.what();
      if (call == 0) std::cout << "[kernel failure] " << m << "\n";
      EXPECT_CONTAINS(m, "twisting model 'abi_failing_twisting' (library 'abi_failing') at test: contact kernel failed");
      EXPECT_CONTAINS(m, "deliberate failure on a batch of 3 contacts");
    }
  }
}

// Guards issue 13 item 7: a kernel that fails in the middle of a run is
// reported with the subdomain, the step, the simulated time and the ids of
// the batch's particles (here a sphere that falls onto a floor: the failing
// twisting model is first called at its first contact, step ~755: a fall of
// 0.1 d takes sqrt(0.2 d / g) = 7.55 ms at 1e-5 s a step).
TEST(AbiLoader, KernelFailureDuringARunNamesItsPlace) {
  PluginRegistry registry;
  registry.load_directory(DOMEL_BINARY_DIR "/plugins");
  registry.load(good("failing_kernel"));
  const double d = 0.0028;
  const nlohmann::json doc = {
      {"gravity", {0, 0, -9.81}},
      {"materials", {{"m", {{"density", 2500}, {"youngs_modulus", 5e6}, {"poisson_ratio", 0.3}}}}},
      {"interactions", {{{"materials", {"m", "m"}}, {"restitution", 0.5}, {"friction", 0.5}}}},
      {"walls", {{{"name", "floor"}, {"type", "plane"}, {"material", "m"}, {"point", {0, 0, 0}}, {"normal", {0, 0, 1}}}}},
      {"subdomains",
       {{{"name", "column"},
         {"material", "m"},
         {"time_step", 1e-5},
         {"contact", {{"twisting", {{"model", "abi_failing_twisting"}}}}}}}},
      {"run", {{"duration", 1.0}}},
      {"output", {{"vtk_interval", 0}, {"probe_interval", 0}}}};
  // built without particles (the time-step estimate would call the failing
  // kernel); the sphere is added before set-up, 0.1 d above the floor: its
  // first contact is a few hundred steps away
  auto sim = domel::platform::load_scenario(doc, "fall.json", registry);
  auto& sd = *sim->subdomains[0];
  auto& s = sd.store();
  const std::uint64_t id = 42;
  s.add(id, 0.0, 0.0, 0.6 * d, 0.5 * d, 2500.0);
  sd.setup();
  try {
    for (int k = 0; k < 2000; ++k) sd.step();
    ADD_FAILURE() << "the failing kernel was never called";
  } catch (const PluginError& e) {
    const std::string m = e.what();
    std::cout << "[run failure] " << m << "\n";
    EXPECT_CONTAINS(m, "subdomain 'column', step ");
    EXPECT_CONTAINS(m, ", t = ");
    EXPECT_CONTAINS(m, "twisting model 'abi_failing_twisting'");
    EXPECT_CONTAINS(m, "deliberate failure on a batch of 1 contacts");
    EXPECT_CONTAINS(m, "particle id " + std::to_string(id) + " with wall 'floor'");
    EXPECT_GT(sd.steps(), 100u);  // during the run, not at set-up
  }
}

// Guards atomicity: a refused library registers none of its models, even the valid ones listed before the bad one.
TEST(AbiLoader, RefusedLibraryLeavesRegistryUnchanged) {
  PluginRegistry registry;
  registry.load(good("good_plugin"));
  const std::size_t libraries = registry.libraries().size();
  const std::size_t models = registry.models().size();
  std::vector<std::string> all = kBroken;
  all.push_back("duplicate_of_good");
  for (const auto& name : all) {
    EXPECT_THROW(registry.load(broken(name)), PluginError) << name;
    EXPECT_EQ(registry.libraries().size(), libraries) << name;
    EXPECT_EQ(registry.models().size(), models) << name;
  }
  EXPECT_EQ(registry.find(DOMEL_KIND_DAMPING, "missing_create_valid"), nullptr);
  EXPECT_EQ(registry.find(DOMEL_KIND_DAMPING, "duplicate_of_good_unique"), nullptr);
  EXPECT_EQ(registry.find(DOMEL_KIND_NORMAL, "duplicate_twin"), nullptr);
  // A refused file is not remembered as loaded: trying it again refuses it again.
  EXPECT_THROW(registry.load(broken("missing_create")), PluginError);
  // And the registry still takes good libraries afterwards.
  registry.load(good("failing_kernel"));
  EXPECT_EQ(registry.libraries().size(), libraries + 1);
}

// Guards load_directory: a broken library in a folder is recorded in refused() and does not stop the good one.
TEST(AbiLoader, LoadDirectoryKeepsGoodAndRecordsBroken) {
  const fs::path dir = fs::temp_directory_path() / ("domel_abi_mixed_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path good_copy = dir / good("good_plugin").filename();
  const fs::path broken_copy = dir / broken("missing_contact").filename();
  fs::copy_file(good("good_plugin"), good_copy);
  fs::copy_file(broken("missing_contact"), broken_copy);
  {
    PluginRegistry registry;
    EXPECT_EQ(registry.load_directory(dir), 1u);
    ASSERT_EQ(registry.libraries().size(), 1u);
    EXPECT_EQ(registry.libraries()[0].path.string(), shown(good_copy));
    EXPECT_NE(registry.find(DOMEL_KIND_ROLLING, "abi_good_rolling"), nullptr);
    ASSERT_EQ(registry.refused().size(), 1u);
    std::cout << "[refused()] " << registry.refused()[0] << "\n";
    EXPECT_CONTAINS(registry.refused()[0], "plugin '" + shown(broken_copy) + "' refused: ");
    EXPECT_CONTAINS(registry.refused()[0], "lacks required callback 'contact'");
  }
  fs::remove_all(dir);
}

// Guards load_directory over the whole broken folder: every broken library is refused, each message naming its own file.
TEST(AbiLoader, LoadDirectoryOfBrokenLibrariesLoadsNothing) {
  PluginRegistry registry;
  // duplicate_of_good is valid on its own (it only clashes with good_plugin), so it is the one that loads.
  EXPECT_EQ(registry.load_directory(DOMEL_ABI_BROKEN_DIR), 1u);
  ASSERT_EQ(registry.libraries().size(), 1u);
  EXPECT_EQ(registry.libraries()[0].name, "duplicate_of_good");
  ASSERT_EQ(registry.refused().size(), kBroken.size());
  for (const auto& name : kBroken) {
    const std::string prefix = "plugin '" + shown(broken(name)) + "' refused: ";
    std::size_t hits = 0;
    for (const auto& r : registry.refused()) hits += r.rfind(prefix, 0) == 0 ? 1 : 0;
    EXPECT_EQ(hits, 1u) << name;
  }
}

// Guards idempotence: loading the same file twice (also under another spelling of its path) is a no-op.
TEST(AbiLoader, LoadingSamePathTwiceIsNoOp) {
  PluginRegistry registry;
  registry.load(good("good_plugin"));
  registry.load(good("good_plugin"));
  registry.load(fs::path(DOMEL_ABI_GOOD_DIR) / ".." / "good" / good("good_plugin").filename());
  EXPECT_EQ(registry.libraries().size(), 1u);
  EXPECT_EQ(registry.models().size(), 1u);
  EXPECT_EQ(registry.load_directory(DOMEL_ABI_GOOD_DIR), 4u);  // load() counts the no-op as loaded
  EXPECT_EQ(registry.libraries().size(), 4u);  // only failing_kernel, family_plugins and abi21_fluid are new
  EXPECT_TRUE(registry.refused().empty());
}

namespace {

/// One level's views for the controller and fluid_coupler tests: a 2x1x1
/// grid of 1 m cells from the origin, and particles, all owned here.
struct Level {
  Level(const char* name, std::vector<double> px, std::vector<double> pvx, std::vector<uint32_t> pcell)
      : x(std::move(px)), vx(std::move(pvx)), cell(std::move(pcell)) {
    const std::size_t n = x.size();
    id.resize(n);
    for (std::size_t k = 0; k < n; ++k) id[k] = 100 + k;
    y.assign(n, 0.5); z.assign(n, 0.5); vy.assign(n, 0.0); vz.assign(n, 0.0);
    mass.assign(n, 2.0); radius.assign(n, 0.01); fx.assign(n, 0.0); fy.assign(n, 0.0); fz.assign(n, 0.0);
    grid.struct_size = sizeof grid;
    grid.nx = 2; grid.ny = 1; grid.nz = 1;
    for (int d = 0; d < 3; ++d) { grid.origin[d] = 0.0; grid.spacing[d] = 1.0; }
    grid.n_cells = 2;
    grid.count = count.data(); grid.volume_fraction = phi.data(); grid.mass = cmass.data();
    grid.ux = ux.data(); grid.uy = zero.data(); grid.uz = zero.data();
    grid.u_min_x = zero.data(); grid.u_min_y = zero.data(); grid.u_min_z = umin_z.data();
    grid.u_max_x = zero.data(); grid.u_max_y = zero.data(); grid.u_max_z = umax_z.data();
    grid.stress = stress.data();
    particles = {static_cast<uint32_t>(sizeof particles), 0, n, id.data(), x.data(), y.data(), z.data(), vx.data(), vy.data(),
                 vz.data(), mass.data(), radius.data(), cell.data(), fx.data(), fy.data(), fz.data()};
    level = {static_cast<uint32_t>(sizeof level), 0, name, 1.0, &grid, &particles};
  }
  std::vector<double> x, y, z, vx, vy, vz, mass, radius, fx, fy, fz;
  std::vector<uint64_t> id;
  std::vector<uint32_t> cell;
  std::vector<uint32_t> count = {3, 1};
  std::vector<double> phi = {0.25, 0.5}, cmass = {6.0, 2.0}, ux = {1.5, -0.5}, zero = {0.0, 0.0},
                      umin_z = {-0.2, 0.1}, umax_z = {0.3, 0.4}, stress = std::vector<double>(12, 0.0);
  domel_cell_grid_v1 grid{};
  domel_particles_v1 particles{};
  domel_level_v1 level{};
};

using domel::test::LogCapture;

}  // namespace

// Guards the controller family (abi.h, domel_controller_family_v1): the model loads, the loader's
// ModelInstance calls `control` with two levels' cell averages (incl. min/max velocity) and particles,
// the forces it writes to both levels arrive, the instance keeps its state between calls, and its
// host log lines carry its kind, name, library and location.
TEST(AbiFamilies, ControllerReadsBothLevelsAndWritesForcesToBoth) {
  PluginRegistry registry;
  registry.load(good("family_plugins"));
  const auto* model = registry.find(DOMEL_KIND_CONTROLLER, "abi_test_controller");
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->library_name, "abi_families");
  ModelInstance instance(*model, {{"gain", 10.0}}, "scenario.json: at /couplings/0");
  // level 0 (fine): particles at x = 0.5 (coarse cell 0) and 1.5 (cell 1); level 1 (coarse): in cells 1 and 0.
  Level fine("fine", {0.5, 1.5}, {1.0, 0.0}, {0, 1});
  Level coarse("coarse", {1.2, 0.7}, {0.0, 0.0}, {1, 0});
  domel_level_v1* levels[] = {&fine.level, &coarse.level};
  domel_control_step_v1 step{static_cast<uint32_t>(sizeof step), 2, 0.25, 0.01, levels};
  LogCapture log;
  instance.control(step);
  instance.control(step);
  // fine: F_x = gain m (u_x(coarse cell) - v_x), added over two calls
  EXPECT_DOUBLE_EQ(fine.fx[0], 2 * 10.0 * 2.0 * (1.5 - 1.0));
  EXPECT_DOUBLE_EQ(fine.fx[1], 2 * 10.0 * 2.0 * (-0.5 - 0.0));
  // coarse: F_z = -m (u_max_z - u_min_z) of its own cell; F_y = calls so far (1 + 2)
  EXPECT_DOUBLE_EQ(coarse.fz[0], 2 * -2.0 * (0.4 - 0.1));
  EXPECT_DOUBLE_EQ(coarse.fz[1], 2 * -2.0 * (0.3 - -0.2));
  EXPECT_DOUBLE_EQ(coarse.fy[0], 3.0);
  const std::string logged = log.text.str();
  std::cout << "[controller log] " << logged;
  EXPECT_CONTAINS(logged, "[controller model 'abi_test_controller' (library 'abi_families') at scenario.json: at "
                          "/couplings/0] control call 2");
  // one level is not enough for this controller: its message arrives with the context
  step.level_count = 1;
  try {
    instance.control(step);
    ADD_FAILURE() << "a step with one level was accepted";
  } catch (const PluginError& e) {
    EXPECT_CONTAINS(e.what(), "controller model 'abi_test_controller' (library 'abi_families') at scenario.json: at "
                              "/couplings/0: control failed: needs two levels, got 1");
  }
}

// Guards the fluid_coupler family (domel_fluid_coupler_family_v1): `exchange` is called through
// ModelInstance and returns per-particle fluid forces; an error reported through the host's error
// service is kept with the instance's context and the failure carries the plugin's message.
TEST(AbiFamilies, FluidCouplerReturnsPerParticleForcesAndReportsErrorsWithContext) {
  PluginRegistry registry;
  registry.load(good("family_plugins"));
  const auto* model = registry.find(DOMEL_KIND_FLUID_COUPLER, "abi_test_drag");
  ASSERT_NE(model, nullptr);
  ModelInstance instance(*model, {{"viscosity", 1e-3}, {"flow_x", 2.0}}, "test");
  Level level("bed", {0.5, 1.5}, {1.0, 3.0}, {0, 1});
  domel_fluid_exchange_v1 ex{static_cast<uint32_t>(sizeof ex), 0, 1.0, 1e-3, &level.level};
  instance.exchange(ex);
  const double stokes = 6.0 * M_PI * 1e-3 * 0.01;
  EXPECT_DOUBLE_EQ(level.fx[0], stokes * (2.0 - 1.0) * (1.0 - 0.25));
  EXPECT_DOUBLE_EQ(level.fx[1], stokes * (2.0 - 3.0) * (1.0 - 0.5));
  // without a grid: no (1 - phi) factor
  level.level.cells = nullptr;
  level.fx.assign(2, 0.0);
  instance.exchange(ex);
  EXPECT_DOUBLE_EQ(level.fx[0], stokes * (2.0 - 1.0));

  level.level.particles = nullptr;
  LogCapture log;
  try {
    instance.exchange(ex);
    ADD_FAILURE() << "an exchange without particles was accepted";
  } catch (const PluginError& e) {
    EXPECT_CONTAINS(e.what(), "fluid_coupler model 'abi_test_drag' (library 'abi_families') at test: exchange failed: "
                              "nothing to couple");
  }
  EXPECT_EQ(instance.last_error(), "level 'bed' handed no particles to couple");
  EXPECT_CONTAINS(log.text.str(), "[fluid_coupler model 'abi_test_drag' (library 'abi_families') at test] error 2: "
                                  "level 'bed' handed no particles to couple");
  // a contact-family call on a fluid coupler is refused by the wrapper, not sent to a null pointer
  domel_control_step_v1 step{static_cast<uint32_t>(sizeof step), 0, 0.0, 0.0, nullptr};
  EXPECT_THROW(instance.control(step), PluginError);
}
