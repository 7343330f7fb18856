// SPDX-License-Identifier: MIT
#include "distributed/particle_exchange.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

namespace domel::platform {

std::size_t particle_bytes(const ParticleStore& s) {
  std::size_t b = 0;
  s.for_each_array([&b](const auto& v) { b += sizeof(typename std::decay_t<decltype(v)>::value_type); });
  return b;
}

std::vector<char> pack_particles(const ParticleStore& s, const std::vector<std::uint32_t>& which) {
  std::vector<char> out(which.size() * particle_bytes(s));
  char* p = out.data();
  // array-major within the buffer: one pass per array
  s.for_each_array([&](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    for (std::uint32_t k : which) {
      std::memcpy(p, &v[k], sizeof(T));
      p += sizeof(T);
    }
  });
  return out;
}

void unpack_particles(ParticleStore& s, const std::vector<char>& bytes) {
  const std::size_t per = particle_bytes(s);
  if (bytes.size() % per != 0)
    throw std::runtime_error("unpack_particles: " + std::to_string(bytes.size()) + " bytes are not whole particles of " +
                             std::to_string(per) + " bytes (a store of another layout sent them)");
  const std::size_t n = bytes.size() / per;
  if (n == 0) return;
  const char* p = bytes.data();
  s.for_each_array([&](auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const std::size_t old = v.size();
    v.resize(old + n);
    std::memcpy(static_cast<void*>(v.data() + old), p, n * sizeof(T));
    p += n * sizeof(T);
  });
  ++s.layout_version;
}

ExchangeCounts migrate(ParticleStore& s, const Decomposition& d, const Communicator& comm) {
  const auto nr = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<std::uint32_t>> leaving(nr);
  std::vector<std::uint8_t> remove(s.size(), 0);
  ExchangeCounts c;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double p[3] = {s.x[k], s.y[k], s.z[k]};
    const int r = d.owner(p);
    if (r == comm.rank()) continue;
    if (r < 0 || static_cast<std::size_t>(r) >= nr)
      throw std::runtime_error("migrate: the decomposition has more parts than the communicator has ranks");
    leaving[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(k));
    remove[k] = 1;
    ++c.sent;
  }
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) send[r] = pack_particles(s, leaving[r]);
  s.remove_marked(remove);
  const auto recv = comm.all_to_all(send);
  const std::size_t per = particle_bytes(s);
  for (const auto& b : recv) {
    unpack_particles(s, b);
    c.received += b.size() / per;
  }
  return c;
}

ExchangeCounts exchange_ghosts(const ParticleStore& owned, ParticleStore& ghosts, const Decomposition& d,
                               double cutoff, const Communicator& comm) {
  const auto nr = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<std::uint32_t>> copies(nr);
  std::vector<int> near;
  ExchangeCounts c;
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const double p[3] = {owned.x[k], owned.y[k], owned.z[k]};
    d.parts_within(p, cutoff, near);
    for (int r : near)
      if (r != comm.rank() && static_cast<std::size_t>(r) < nr) {
        copies[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(k));
        ++c.sent;
      }
  }
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) send[r] = pack_particles(owned, copies[r]);
  ghosts = ParticleStore{};
  if (owned.has_external_force()) ghosts.enable_external_force();
  ghosts.add_aux(owned.aux.size());
  const auto recv = comm.all_to_all(send);
  const std::size_t per = particle_bytes(owned);
  for (const auto& b : recv) {
    unpack_particles(ghosts, b);
    c.received += b.size() / per;
  }
  return c;
}

}  // namespace domel::platform
