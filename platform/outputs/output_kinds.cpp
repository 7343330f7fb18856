// SPDX-License-Identifier: MIT
// The registry of output kinds (output_kinds.hpp).
#include "outputs/output_kinds.hpp"

#include <stdexcept>

namespace domel::platform {

namespace {
std::vector<OutputKind>& registry() {
  static std::vector<OutputKind> kinds;
  return kinds;
}
}  // namespace

const std::vector<OutputKind>& output_kinds() { return registry(); }

OutputKindRegistration::OutputKindRegistration(OutputKind kind) {
  for (const auto& k : registry())
    if (k.key == kind.key) throw std::logic_error("output kind '" + kind.key + "' registered twice");
  registry().push_back(std::move(kind));
}

}  // namespace domel::platform
