// SPDX-License-Identifier: MIT
#include "distributed/particle_exchange.hpp"

#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>

namespace domel::platform {

std::size_t particle_bytes(const ParticleStore& s, unsigned sync) {
  std::size_t b = 0;
  s.for_each_field([&](const char*, const auto& v, unsigned f) {
    if (f & sync) b += sizeof(typename std::decay_t<decltype(v)>::value_type);
  });
  return b;
}

std::vector<char> pack_particles(const ParticleStore& s, const std::vector<std::uint32_t>& which,
                                 const std::vector<std::array<double, 3>>* shift, unsigned sync) {
  std::vector<char> out(which.size() * particle_bytes(s, sync));
  char* p = out.data();
  const void* position[3] = {&s.x, &s.y, &s.z};
  // array-major within the buffer: one pass per field
  s.for_each_field([&](const char*, const auto& v, unsigned f) {
    if (!(f & sync)) return;
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

void unpack_particles(ParticleStore& s, const std::vector<char>& bytes, unsigned sync) {
  const std::size_t per = particle_bytes(s, sync);
  if (per == 0 || bytes.size() % per != 0)
    throw std::runtime_error("unpack_particles: " + std::to_string(bytes.size()) + " bytes are not whole particles of " +
                             std::to_string(per) + " bytes (a store of another layout sent them)");
  const std::size_t n = bytes.size() / per;
  if (n == 0) return;
  const char* p = bytes.data();
  s.for_each_field([&](const char*, auto& v, unsigned f) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const std::size_t old = v.size();
    v.resize(old + n);  // a field not sent: zero
    if (!(f & sync)) return;
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

namespace {
/// The rows of each set whose leading particle leaves (destination: its new
/// rank) go there, all sets in one message; each set becomes its kept rows,
/// then the received ones by sending rank. A set's rows have the same
/// stride on every rank (one contact model per subdomain). Returns the
/// number of rows sent.
std::size_t migrate_histories(const std::vector<PairHistories*>& sets,
                              const std::unordered_map<std::uint64_t, std::size_t>& destination,
                              const Communicator& comm) {
  // a row: set index, id_i, id_j, then the values (bytes of doubles)
  const std::size_t nr = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<char>> send(nr);
  std::vector<PairHistories> kept(sets.size());
  std::size_t sent = 0;
  auto append = [](std::vector<char>& b, const void* p, std::size_t bytes) {
    const auto* c = static_cast<const char*>(p);
    b.insert(b.end(), c, c + bytes);
  };
  for (std::size_t set = 0; set < sets.size(); ++set) {
    const PairHistories& h = *sets[set];
    const std::size_t stride = h.stride;
    kept[set].stride = h.stride;
    for (std::size_t k = 0; k < h.size(); ++k) {
      const auto it = destination.find(h.id_i[k]);
      const double* v = h.values.data() + k * stride;
      if (it == destination.end()) {
        kept[set].id_i.push_back(h.id_i[k]);
        kept[set].id_j.push_back(h.id_j[k]);
        kept[set].values.insert(kept[set].values.end(), v, v + stride);
        continue;
      }
      ++sent;
      std::vector<char>& b = send[it->second];
      const std::uint64_t head[3] = {set, h.id_i[k], h.id_j[k]};
      append(b, head, sizeof(head));
      append(b, v, stride * sizeof(double));
    }
  }
  const auto recv = comm.all_to_all(send);
  for (const auto& b : recv)
    for (std::size_t at = 0; at < b.size();) {
      std::uint64_t head[3];
      if (b.size() - at < sizeof(head)) throw std::runtime_error("migrate: a truncated contact history arrived");
      std::memcpy(head, b.data() + at, sizeof(head));
      at += sizeof(head);
      if (head[0] >= kept.size()) throw std::runtime_error("migrate: contact histories of an unknown set arrived");
      PairHistories& into = kept[head[0]];
      const std::size_t bytes = into.stride * sizeof(double);
      if (b.size() - at < bytes) throw std::runtime_error("migrate: a truncated contact history arrived");
      into.id_i.push_back(head[1]);
      into.id_j.push_back(head[2]);
      const std::size_t old = into.values.size();
      into.values.resize(old + into.stride);
      if (bytes > 0) std::memcpy(into.values.data() + old, b.data() + at, bytes);
      at += bytes;
    }
  for (std::size_t set = 0; set < sets.size(); ++set) *sets[set] = std::move(kept[set]);
  return sent;
}
}  // namespace

ExchangeCounts migrate(ParticleStore& s, const Decomposition& d, const Communicator& comm,
                       const std::vector<PairHistories*>& histories) {
  const auto nr = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<std::uint32_t>> leaving(nr);
  std::vector<std::uint8_t> remove(s.size(), 0);
  std::unordered_map<std::uint64_t, std::size_t> destination;  // of the leaving particles' ids
  ExchangeCounts c;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double p[3] = {s.x[k], s.y[k], s.z[k]};
    const int r = d.owner(p);
    if (r == comm.rank()) continue;
    if (r < 0 || static_cast<std::size_t>(r) >= nr)
      throw std::runtime_error("migrate: the decomposition has more parts than the communicator has ranks");
    leaving[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(k));
    remove[k] = 1;
    if (!histories.empty()) destination.emplace(s.id[k], static_cast<std::size_t>(r));
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
  if (!histories.empty()) c.histories_sent = migrate_histories(histories, destination, comm);
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

ExchangeCounts GhostExchange::build(ParticleStore& s, std::size_t owned, const Decomposition& d, double cutoff,
                                    const Communicator& comm, const PeriodicBox& box) {
  const auto nr = static_cast<std::size_t>(comm.size());
  s.truncate(owned);
  owned = s.size();
  sent_.assign(nr, {});
  shift_.assign(nr, {});
  double period[3], inv[3];
  box.periods(period, inv);
  for (int a = 0; a < 3; ++a)
    if (box.axis[a] && period[a] < 2.0 * cutoff)
      throw std::invalid_argument("GhostExchange: a periodic axis shorter than twice the ghost cut-off");
  std::vector<std::array<double, 3>> shifts{{0.0, 0.0, 0.0}};
  for (const auto& sh : box.image_shifts()) shifts.push_back({sh[0] * period[0], sh[1] * period[1], sh[2] * period[2]});
  std::vector<int> near;
  ExchangeCounts c;
  for (std::size_t k = 0; k < owned; ++k)
    for (std::size_t i = 0; i < shifts.size(); ++i) {
      const auto& sh = shifts[i];
      const double p[3] = {s.x[k] + sh[0], s.y[k] + sh[1], s.z[k] + sh[2]};
      d.parts_within(p, cutoff, near, box);
      for (int r : near)
        if ((r != comm.rank() || i > 0) && static_cast<std::size_t>(r) < nr) {
          sent_[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(k));
          shift_[static_cast<std::size_t>(r)].push_back(sh);
          ++c.sent;
        }
    }
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) send[r] = pack_particles(s, sent_[r], &shift_[r], ParticleStore::kGhostBuild);
  const auto recv = comm.all_to_all(send);
  const std::size_t per = particle_bytes(s, ParticleStore::kGhostBuild);  // what a ghost carries
  first_.assign(nr + 1, 0);
  for (std::size_t r = 0; r < nr; ++r) {
    first_[r] = s.size();
    unpack_particles(s, recv[r], ParticleStore::kGhostBuild);
    c.received += recv[r].size() / per;
  }
  first_[nr] = s.size();
  return c;
}

void GhostExchange::check(const ParticleStore& s, const char* what) const {
  if (first_.empty() || s.size() != first_.back())
    throw std::logic_error(std::string("GhostExchange::") + what + ": no build(), or the store changed since");
}

namespace {
/// The store's double fields whose sync policy has `sync`, in the table's order.
std::vector<std::vector<double>*> double_fields(ParticleStore& s, unsigned sync) {
  std::vector<std::vector<double>*> out;
  s.for_each_field([&](const char* name, auto& v, unsigned f) {
    if (!(f & sync)) return;
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::vector<double>>) out.push_back(&v);
    else throw std::logic_error(std::string("the per-particle field '") + name + "' is not real-valued: it cannot be "
                                "refreshed in the ghosts or summed at the owners");
  });
  return out;
}
std::vector<const std::vector<double>*> as_const(const std::vector<std::vector<double>*>& v) {
  return {v.begin(), v.end()};
}
}  // namespace

std::size_t GhostExchange::update_bytes(const ParticleStore& s) const {
  std::size_t n = 0;
  for (const auto& r : sent_) n += r.size();
  return n * particle_bytes(s, ParticleStore::kGhostUpdate);
}

std::size_t GhostExchange::reverse_bytes(const ParticleStore& s) const {
  return first_.empty() ? 0 : (first_.back() - first_.front()) * particle_bytes(s, ParticleStore::kReverse);
}

void GhostExchange::update(ParticleStore& s, const Communicator& comm) const {
  check(s, "update");
  // the fields the ghosts follow their owners in (kGhostUpdate; positions
  // shifted for images)
  const std::vector<std::vector<double>*> into = double_fields(s, ParticleStore::kGhostUpdate);
  const std::vector<const std::vector<double>*> motion = as_const(into);
  std::size_t position[3] = {SIZE_MAX, SIZE_MAX, SIZE_MAX};
  for (std::size_t f = 0; f < into.size(); ++f)
    for (int a = 0; a < 3; ++a)
      if (into[f] == (a == 0 ? &s.x : a == 1 ? &s.y : &s.z)) position[a] = f;
  std::vector<std::vector<char>> send(sent_.size());
  for (std::size_t r = 0; r < sent_.size(); ++r) {
    send[r] = gather_values(motion, sent_[r]);
    auto* v = reinterpret_cast<double*>(send[r].data());
    for (std::size_t q = 0; q < sent_[r].size(); ++q)
      for (std::size_t a = 0; a < 3; ++a)
        if (position[a] != SIZE_MAX) v[q * motion.size() + position[a]] += shift_[r][q][a];  // images: shifted
  }
  const auto recv = comm.all_to_all(send);
  for (std::size_t r = 0; r < recv.size(); ++r) {
    const std::size_t n = first_[r + 1] - first_[r];
    if (recv[r].size() != n * into.size() * sizeof(double))
      throw std::runtime_error("GhostExchange::update: rank " + std::to_string(r) + " sent another number of ghosts");
    const auto* p = reinterpret_cast<const double*>(recv[r].data());
    for (std::size_t g = first_[r]; g < first_[r + 1]; ++g)
      for (auto* a : into) (*a)[g] = *p++;
  }
}

void GhostExchange::reverse(ParticleStore& s, const Communicator& comm) const {
  check(s, "reverse");
  // the fields the ghosts add to their owners' (kReverse: forces, torques)
  const std::vector<std::vector<double>*> into = double_fields(s, ParticleStore::kReverse);
  const std::vector<const std::vector<double>*> loads = as_const(into);
  const std::size_t nr = sent_.size();
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    std::vector<std::uint32_t> mine(first_[r + 1] - first_[r]);
    for (std::size_t g = 0; g < mine.size(); ++g) mine[g] = static_cast<std::uint32_t>(first_[r] + g);
    send[r] = gather_values(loads, mine);
  }
  const auto recv = comm.all_to_all(send);
  for (std::size_t r = 0; r < nr; ++r) {  // in rank order: fixed sums
    if (recv[r].size() != sent_[r].size() * into.size() * sizeof(double))
      throw std::runtime_error("GhostExchange::reverse: rank " + std::to_string(r) + " returned another number of ghosts");
    const auto* p = reinterpret_cast<const double*>(recv[r].data());
    for (std::uint32_t k : sent_[r])
      for (auto* a : into) (*a)[k] += *p++;
  }
}

void GhostExchange::reverse_counts(ParticleStore& s, const Communicator& comm) const {
  check(s, "reverse_counts");
  const std::size_t nr = sent_.size();
  std::vector<std::vector<char>> send(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    const std::size_t n = first_[r + 1] - first_[r];
    if (n == 0) continue;  // memcpy's pointers may not be null, even for no bytes
    send[r].resize(n * sizeof(std::uint32_t));
    std::memcpy(send[r].data(), s.contacts.data() + first_[r], send[r].size());
    std::fill_n(s.contacts.begin() + static_cast<std::ptrdiff_t>(first_[r]), n, 0u);
  }
  const auto recv = comm.all_to_all(send);
  for (std::size_t r = 0; r < nr; ++r) {
    if (recv[r].size() != sent_[r].size() * sizeof(std::uint32_t))
      throw std::runtime_error("GhostExchange::reverse_counts: rank " + std::to_string(r) +
                               " returned another number of ghosts");
    for (std::size_t q = 0; q < sent_[r].size(); ++q) {
      std::uint32_t c = 0;
      std::memcpy(&c, recv[r].data() + q * sizeof(c), sizeof(c));
      s.contacts[sent_[r][q]] += c;
    }
  }
}


void GhostExchange::fields(CheckpointFields& f, int ranks) {
  std::vector<std::uint64_t> first(first_.begin(), first_.end()), counts;
  std::vector<std::uint32_t> sent;
  std::vector<double> shift;
  for (std::size_t r = 0; r < sent_.size(); ++r) {
    counts.push_back(sent_[r].size());
    sent.insert(sent.end(), sent_[r].begin(), sent_[r].end());
    for (const auto& a : shift_[r]) shift.insert(shift.end(), a.begin(), a.end());
  }
  f("first", first);
  f("sent_counts", counts);
  f("sent", sent);
  f("shift", shift);
  if (!f.loading()) return;
  const ArchiveReader& r = f.reader();
  const std::string& p = f.prefix();
  const auto n = static_cast<std::size_t>(ranks);
  if (first.size() != n + 1 || counts.size() != n)
    r.fail(p + "first", "was written on " + std::to_string(counts.size()) + " ranks, not " + std::to_string(ranks));
  std::size_t total = 0;
  for (auto c : counts) {
    if (c > sent.size() - total) r.fail(p + "sent_counts", "counts more ghosts sent than the part holds");
    total += c;
  }
  if (sent.size() != total || shift.size() != 3 * total) r.fail(p + "sent", "does not match its counts");
  for (std::size_t q = 0; q < n; ++q)
    if (first[q + 1] < first[q]) r.fail(p + "first", "is not in ascending order");
  for (std::uint32_t k : sent)
    if (k >= first.front()) r.fail(p + "sent", "names a particle that is not one of the rank's own");
  first_.assign(first.begin(), first.end());
  sent_.assign(n, {});
  shift_.assign(n, {});
  std::size_t at = 0;
  for (std::size_t q = 0; q < n; ++q)
    for (std::uint64_t c = 0; c < counts[q]; ++c, ++at) {
      sent_[q].push_back(sent[at]);
      shift_[q].push_back({shift[3 * at], shift[3 * at + 1], shift[3 * at + 2]});
    }
}

void GhostExchange::save(ArchiveWriter& w, const std::string& p) const {
  save_fields(w, p, [&](CheckpointFields& f) { const_cast<GhostExchange*>(this)->fields(f, 0); });
}

void GhostExchange::load(const ArchiveReader& r, const std::string& p, int ranks) {
  load_fields(r, p, [&](CheckpointFields& f) { fields(f, ranks); });
}

}  // namespace domel::platform
