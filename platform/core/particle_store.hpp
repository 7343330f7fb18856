// SPDX-License-Identifier: MIT
// The particle store of one subdomain: structure of arrays, one std::vector
// per scalar component, no per-particle objects. Every per-particle field is
// listed once, in for_each_field(), with its sync policy: what a re-order,
// a removal, a rank's migration, its ghosts, the reverse exchange and a
// checkpoint do with it all follow from that list (waLBerla mesa_pd's
// property list is the model: issue 40).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace domel::platform {

class ArchiveWriter;
class ArchiveReader;
class CheckpointFields;

struct ParticleStore {
  std::vector<std::uint64_t> id;           ///< unique within the run, stable
  std::vector<double> x, y, z;             ///< position [m]
  std::vector<double> vx, vy, vz;          ///< velocity [m/s]
  std::vector<double> wx, wy, wz;          ///< angular velocity [rad/s]
  std::vector<double> fx, fy, fz;          ///< force [N] (rebuilt every step)
  std::vector<double> tx, ty, tz;          ///< torque [N m] (rebuilt every step)
  std::vector<double> radius;              ///< [m] (parcel radius, alpha already applied)
  std::vector<double> mass;                ///< [kg]
  std::vector<double> inv_mass;            ///< 1/mass [1/kg]
  std::vector<double> inv_inertia;         ///< 1/I, I = 2/5 m r^2 for a solid sphere [1/(kg m^2)]
  std::vector<std::uint32_t> contacts;     ///< contact count in the last force evaluation
  std::vector<std::uint8_t> flags;         ///< kFixed, ...
  /// The particle's material, as an index into its subdomain's materials
  /// (Subdomain::materials(): 0 is the subdomain's own; at most kMaxMaterials).
  std::vector<std::uint8_t> material;
  static constexpr std::size_t kMaxMaterials = 256;
  /// External force per particle [N] (controllers, fluid drag): the second
  /// entry of the body-force list (integrator.hpp), added to m g at every
  /// force reset. Empty until enable_external_force(); from then on it moves
  /// with the particles like every other array, and new particles get 0.
  std::vector<double> ext_fx, ext_fy, ext_fz;
  /// Further per-particle values a module asks for with add_aux() or
  /// add_field() (the fluid coupling's linearised drag and velocity
  /// integral): each moves with the particles like every other array, with
  /// its own name and sync policy, and new particles get 0.
  std::vector<std::vector<double>> aux;

  /// What happens to a field besides moving with its particle in the store
  /// (a re-order, a removal): a set of these per field (for_each_field()).
  enum Sync : unsigned {
    kMigrate = 1u << 0,      ///< goes with its particle to a new owner rank, and into a gather
    kGhostBuild = 1u << 1,   ///< copied into the ghosts at a list build
    kGhostUpdate = 1u << 2,  ///< refreshed in the ghosts every step between builds (doubles)
    kReverse = 1u << 3,      ///< the ghosts' values added to their owners' every step (doubles)
    kCheckpoint = 1u << 4,   ///< written to checkpoints and read back
  };
  /// The policy of a field that only rides along: it travels, and is saved.
  static constexpr unsigned kCarried = kMigrate | kGhostBuild | kCheckpoint;

  /// A fixed particle is never moved (inverse mass and inertia 0, so the
  /// integrator leaves it at rest) but is a full contact partner with its real
  /// mass in m*, as LIGGGHTS' non-integrated particles are (a rough floor).
  static constexpr std::uint8_t kFixed = 1;
  bool fixed(std::size_t k) const { return (flags[k] & kFixed) != 0; }

  std::size_t size() const { return id.size(); }

  bool has_external_force() const { return external_force_; }
  /// Give every particle an external force, 0 to start with. Idempotent.
  void enable_external_force() {
    if (external_force_) return;
    for (auto* v : {&ext_fx, &ext_fy, &ext_fz}) v->assign(size(), 0.0);
    external_force_ = true;
  }

  /// Append k zero-filled aux arrays named aux<index>, carried
  /// (kCarried); returns the index of the first.
  std::size_t add_aux(std::size_t k) {
    const std::size_t first = aux.size();
    for (std::size_t a = 0; a < k; ++a) add_field("aux" + std::to_string(aux.size()), kCarried);
    return first;
  }
  /// Append one zero-filled per-particle field (an aux array) with its name
  /// (its checkpoint section) and sync policy; returns its index in aux.
  /// Throws std::invalid_argument for a name already taken.
  std::size_t add_field(const std::string& name, unsigned sync);
  /// The aux fields' names and sync policies, by index.
  const std::vector<std::string>& aux_names() const { return aux_name_; }
  const std::vector<unsigned>& aux_sync() const { return aux_sync_; }
  /// An empty store with the same fields (the external-force switch and the
  /// aux fields with their names and policies), to gather particles into.
  ParticleStore empty_like() const;

  /// Incremented by every change of which particle sits in which slot (add,
  /// swap_remove, permute), so that index-based structures (neighbour lists)
  /// know they are stale without comparing ids every step.
  std::uint64_t layout_version = 0;

  /// Append one particle at rest. Mass from density and radius; `mat` is
  /// its material's index in the subdomain's materials.
  void add(std::uint64_t pid, double px, double py, double pz, double r, double density, bool fixed = false,
           std::uint8_t mat = 0);

  /// Make room for n particles in every array, so that a block of known
  /// size (an insertion, a state file) is appended without the doubling
  /// growth of push_back, which leaves up to half of each array unused.
  void reserve(std::size_t n) {
    for_each_array([n](auto& v) { v.reserve(n); });
  }

  /// Remove particle k by moving the last one into its place.
  void swap_remove(std::size_t k);

  /// Remove every particle k with remove[k] != 0, keeping the others in
  /// their order (a stable compaction: the spatial order of the store, and so
  /// its cache locality, survives). Returns the number removed.
  std::size_t remove_marked(const std::vector<std::uint8_t>& remove);

  /// Keep particles [0, n) and drop the rest (the ghosts after a rank's own
  /// particles, distributed/).
  void truncate(std::size_t n) {
    if (n >= size()) return;
    for_each_array([n](auto& v) { v.resize(n); });
    ++layout_version;
  }

  /// Apply a permutation: new index k holds old particle order[k].
  void permute(const std::vector<std::uint32_t>& order);
  /// Append every particle of `other` (the same external-force switch and
  /// aux count: throws std::invalid_argument otherwise).
  void append(const ParticleStore& other);
  /// Append the particles `which` of `other` (indices into it, in that order),
  /// under the same conditions.
  void append(const ParticleStore& other, const std::vector<std::uint32_t>& which);

  /// The order that sorts the particles by cubic cells of side `cell`, cell
  /// rows in z-y-x order (ties keep the current order): new index k holds
  /// old particle order[k], for permute(). Particles close in space end up
  /// close in memory, so the pair loop's gathers hit the cache.
  std::vector<std::uint32_t> spatial_order(double cell) const;

  /// Visit every per-particle field, f(name, array, sync), in one fixed
  /// order: the one list of the store's fields. The contact counts go home
  /// from the ghosts on demand (reverse_counts), not every step.
  template <class F>
  void for_each_field(F&& f) {
    constexpr unsigned motion = kCarried | kGhostUpdate, load = kCarried | kReverse;
    f("id", id, kCarried);
    f("x", x, motion); f("y", y, motion); f("z", z, motion);
    f("vx", vx, motion); f("vy", vy, motion); f("vz", vz, motion);
    f("wx", wx, motion); f("wy", wy, motion); f("wz", wz, motion);
    f("fx", fx, load); f("fy", fy, load); f("fz", fz, load);
    f("tx", tx, load); f("ty", ty, load); f("tz", tz, load);
    f("radius", radius, kCarried); f("mass", mass, kCarried); f("inv_mass", inv_mass, kCarried);
    f("inv_inertia", inv_inertia, kCarried);
    f("contacts", contacts, kCarried); f("flags", flags, kCarried); f("material", material, kCarried);
    if (external_force_) {
      f("ext_fx", ext_fx, kCarried); f("ext_fy", ext_fy, kCarried); f("ext_fz", ext_fz, kCarried);
    }
    for (std::size_t a = 0; a < aux.size(); ++a) f(aux_name_[a].c_str(), aux[a], aux_sync_[a]);
  }
  template <class F>
  void for_each_field(F&& f) const {
    const_cast<ParticleStore*>(this)->for_each_field(
        [&f](const char* name, const auto& v, unsigned sync) { f(name, v, sync); });
  }
  /// Visit every per-particle array (for permutation, removal, resizing).
  template <class F>
  void for_each_array(F&& f) {
    for_each_field([&f](const char*, auto& v, unsigned) { f(v); });
  }
  template <class F>
  void for_each_array(F&& f) const {
    const_cast<ParticleStore*>(this)->for_each_array([&f](const auto& v) { f(v); });
  }

  /// Every field with kCheckpoint, the external-force switch, the aux count
  /// and the layout version, under `prefix` (checkpoints, core/archive.hpp).
  void save(ArchiveWriter& w, const std::string& prefix) const;
  /// The inverse of save(); throws ConfigError when a section is missing or
  /// the arrays' lengths disagree.
  void load(const ArchiveReader& r, const std::string& prefix);
  /// Both directions of save and load, field by field (core/archive.hpp).
  void fields(CheckpointFields& f);

  /// Bytes held by the arrays (their capacity).
  std::size_t bytes() const {
    std::size_t b = 0;
    for_each_array([&b](const auto& v) { b += v.capacity() * sizeof(v[0]); });
    return b;
  }

 private:
  bool external_force_ = false;
  std::vector<std::string> aux_name_;
  std::vector<unsigned> aux_sync_;
};

}  // namespace domel::platform
