// SPDX-License-Identifier: MIT
// output.state (state_files.hpp).
#include "outputs/state_files.hpp"

#include "io/particle_state.hpp"
#include "subdomain/subdomain.hpp"

#include <cctype>

namespace domel::platform {

void StateFiles::finish(RunContext& ctx, nlohmann::json& summary) {
  for (std::size_t k = 0; k < ctx.subdomains.size(); ++k) {
    const Subdomain& sd = *ctx.subdomains[k];
    std::string f = sd.name() + "_state.csv";
    for (char& c : f)  // a file name whatever the subdomain is called
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') c = '_';
    std::vector<std::string> names;  // of its materials, by local index
    for (std::size_t g : sd.materials()) names.push_back(materials_[g]);
    const ParticleStore& all = ctx.particles(k, ctx.end_time);  // collective on ranks
    if (ctx.writer) io::write_particle_state(ctx.out / f, all, sd.name(), ctx.end_time, sd.coarse_grain(), names);
    summary["outputs"]["state"][sd.name()] = f;
  }
}

}  // namespace domel::platform
