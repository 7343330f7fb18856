// SPDX-License-Identifier: MIT
#include "distributed/particle_exchange.hpp"

#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace domel::platform {

std::size_t particle_bytes(const ParticleStore& s) {
  std::size_t b = 0;
  s.for_each_array([&b](const auto& v) { b += sizeof(typename std::decay_t<decltype(v)>::value_type); });
  return b;
}

std::vector<char> pack_particles(const ParticleStore& s, const std::vector<std::uint32_t>& which,
                                 const std::vector<std::array<double, 3>>* shift) {
  std::vector<char> out(which.size() * particle_bytes(s));
  char* p = out.data();
  const void* position[3] = {&s.x, &s.y, &s.z};
  // array-major within the buffer: one pass per array
  s.for_each_array([&](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    int axis = -1;
    for (int a = 0; a < 3; ++a)
      if (static_cast<const void*>(&v) == position[a]) axis = a;
    for (std::size_t q = 0; q < which.size(); ++q) {
      T value = v[which[q]];
      if constexpr (std::is_same_v<T, double>)
        if (shift && axis >= 0) value += (*shift)[q][static_cast<std::size_t>(axis)];
      std::memcpy(p, &value, sizeof(T));
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

std::uint64_t claim_ids(std::uint64_t count, std::uint64_t& next_id, const Communicator& comm) {
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(comm.size()), 0);
  counts[static_cast<std::size_t>(comm.rank())] = count;
  comm.sum(counts);  // every rank's count, on every rank
  std::uint64_t first = next_id;
  for (int r = 0; r < comm.rank(); ++r) first += counts[static_cast<std::size_t>(r)];
  for (std::uint64_t c : counts) next_id += c;
  return first;
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

namespace {
/// Values of `arrays` for the particles `which`, particle-major.
std::vector<char> gather_values(const std::vector<const std::vector<double>*>& arrays,
                                const std::vector<std::uint32_t>& which) {
  std::vector<char> out(which.size() * arrays.size() * sizeof(double));
  auto* p = reinterpret_cast<double*>(out.data());
  for (std::uint32_t k : which)
    for (const auto* a : arrays) *p++ = (*a)[k];
  return out;
}
}  // namespace

ExchangeCounts GhostExchange::build(const ParticleStore& owned, ParticleStore& ghosts, const Decomposition& d,
                                    double cutoff, const Communicator& comm, const PeriodicBox& box) {
  const auto nr = static_cast<std::size_t>(comm.size());
  sent_.assign(nr, {});
  shift_.assign(nr, {});
  double period[3], inv[3];
  box.periods(period, inv);
  for (int a = 0; a < 3; ++a)
    if (box.axis[a] && period[a] < 2.0 * cutoff)
      throw std::invalid_argument("GhostExchange: a periodic axis shorter than twice the ghost cut-off");
  std::vector<std::array<double, 3>> shifts{{0.0, 0.0, 0.0}};
  for (const auto& s : box.image_shifts()) shifts.push_back({s[0] * period[0], s[1] * period[1], s[2] * period[2]});
  std::vector<int> near;
  ExchangeCounts c;
  for (std::size_t k = 0; k < owned.size(); ++k)
    for (std::size_t i = 0; i < shifts.size(); ++i) {
      const auto& sh = shifts[i];
      const double p[3] = {owned.x[k] + sh[0], owned.y[k] + sh[1], owned.z[k] + sh[2]};
      d.parts_within(p, cutoff, near, box);
      for (int r : near)
        if ((r != comm.rank() || i > 0) && static_cast<std::size_t>(r) < nr) {
          sent_[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(k));
          shift_[static_cast<std::size_t>(r)].push_back(sh);
          ++c.sent;
        }
    }
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    send[r] = pack_particles(owned, sent_[r], &shift_[r]);
  }
  ghosts = ParticleStore{};
  if (owned.has_external_force()) ghosts.enable_external_force();
  ghosts.add_aux(owned.aux.size());
  const auto recv = comm.all_to_all(send);
  const std::size_t per = particle_bytes(owned);
  first_.assign(nr + 1, 0);
  for (std::size_t r = 0; r < nr; ++r) {
    first_[r] = ghosts.size();
    unpack_particles(ghosts, recv[r]);
    c.received += recv[r].size() / per;
  }
  first_[nr] = ghosts.size();
  return c;
}

void GhostExchange::update(const ParticleStore& owned, ParticleStore& ghosts, const Communicator& comm) const {
  if (first_.empty() || ghosts.size() != first_.back())
    throw std::logic_error("GhostExchange::update: no build(), or the ghosts changed since");
  const std::vector<const std::vector<double>*> motion = {&owned.x,  &owned.y,  &owned.z,  &owned.vx, &owned.vy,
                                                          &owned.vz, &owned.wx, &owned.wy, &owned.wz};
  std::vector<std::vector<char>> send(sent_.size());
  for (std::size_t r = 0; r < sent_.size(); ++r) {
    send[r] = gather_values(motion, sent_[r]);
    auto* v = reinterpret_cast<double*>(send[r].data());
    for (std::size_t q = 0; q < sent_[r].size(); ++q)
      for (std::size_t a = 0; a < 3; ++a) v[q * motion.size() + a] += shift_[r][q][a];  // images: shifted positions
  }
  const auto recv = comm.all_to_all(send);
  std::vector<double>* into[9] = {&ghosts.x,  &ghosts.y,  &ghosts.z,  &ghosts.vx, &ghosts.vy,
                                  &ghosts.vz, &ghosts.wx, &ghosts.wy, &ghosts.wz};
  for (std::size_t r = 0; r < recv.size(); ++r) {
    const std::size_t n = first_[r + 1] - first_[r];
    if (recv[r].size() != n * std::size(into) * sizeof(double))
      throw std::runtime_error("GhostExchange::update: rank " + std::to_string(r) + " sent another number of ghosts");
    const auto* p = reinterpret_cast<const double*>(recv[r].data());
    for (std::size_t g = first_[r]; g < first_[r + 1]; ++g)
      for (auto* a : into) (*a)[g] = *p++;
  }
}

void GhostExchange::reverse(const ParticleStore& ghosts, ParticleStore& owned, const Communicator& comm) const {
  if (first_.empty() || ghosts.size() != first_.back())
    throw std::logic_error("GhostExchange::reverse: no build(), or the ghosts changed since");
  const std::vector<const std::vector<double>*> loads = {&ghosts.fx, &ghosts.fy, &ghosts.fz,
                                                         &ghosts.tx, &ghosts.ty, &ghosts.tz};
  const std::size_t nr = sent_.size();
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    std::vector<std::uint32_t> mine(first_[r + 1] - first_[r]);
    for (std::size_t g = 0; g < mine.size(); ++g) mine[g] = static_cast<std::uint32_t>(first_[r] + g);
    send[r] = gather_values(loads, mine);
  }
  const auto recv = comm.all_to_all(send);
  std::vector<double>* into[6] = {&owned.fx, &owned.fy, &owned.fz, &owned.tx, &owned.ty, &owned.tz};
  for (std::size_t r = 0; r < nr; ++r) {  // in rank order: fixed sums
    if (recv[r].size() != sent_[r].size() * std::size(into) * sizeof(double))
      throw std::runtime_error("GhostExchange::reverse: rank " + std::to_string(r) + " returned another number of ghosts");
    const auto* p = reinterpret_cast<const double*>(recv[r].data());
    for (std::uint32_t k : sent_[r])
      for (auto* a : into) (*a)[k] += *p++;
  }
}

}  // namespace domel::platform
