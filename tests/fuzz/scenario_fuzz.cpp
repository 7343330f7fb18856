// SPDX-License-Identifier: MIT
// libFuzzer harness for the scenario reader and validator (docs/reliability.md):
// each input is written as a scenario file and given to
// validate_scenario_file(), which reads it, validates it against the
// schemas and builds it without stepping (insertions, state files, meshes,
// time steps). The promise is that any input gives a list of diagnostics: an
// exception that escapes is a defect, so the harness aborts on one (the
// fuzzer then keeps the input), as it does on a sanitizer report, a crash or
// a hang (libFuzzer's -timeout).
#include "core/error.hpp"
#include "fuzz_support.hpp"
#include "loader/plugin_registry.hpp"
#include "scenario/scenario.hpp"

#include <spdlog/spdlog.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace {

using domel::fuzz::registry;
using domel::fuzz::work_dir;

}  // namespace

/// The most particles one input may ask for: validation builds the
/// scenario, and a mutated region or diameter can ask for 10^7 (the default
/// run.max_particles), which takes minutes and gigabytes under the
/// sanitizers. Above this ceiling the input is refused like any larger
/// one in a normal run, so the limit's own path is exercised too.
constexpr std::size_t kParticleCeiling = 200000;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::off);  // millions of inputs: no log lines
  domel::platform::set_particle_ceiling(kParticleCeiling);
  registry();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = work_dir() / ("input_" + std::to_string(::getpid()) + ".json");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    (void)domel::platform::validate_scenario_file(file, registry());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "validate_scenario_file threw instead of returning diagnostics: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "validate_scenario_file threw a non-standard exception\n");
    std::abort();
  }
  return 0;
}
