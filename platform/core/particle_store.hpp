// SPDX-License-Identifier: MIT
// The particle store of one subdomain: structure of arrays, one std::vector
// per scalar component, no per-particle objects. Everything that moves with a
// particle when the store is re-ordered is listed in for_each_array().
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
  /// Further per-particle values a module asks for with add_aux() (the fluid
  /// coupling's linearised drag and velocity integral): each moves with the
  /// particles like every other array, and new particles get 0.
  std::vector<std::vector<double>> aux;

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

  /// Append k zero-filled aux arrays; returns the index of the first.
  std::size_t add_aux(std::size_t k) {
    const std::size_t first = aux.size();
    for (std::size_t a = 0; a < k; ++a) aux.emplace_back(size(), 0.0);
    return first;
  }

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

  /// Visit every per-particle array (for permutation, removal, resizing).
  template <class F>
  void for_each_array(F&& f) {
    f(id); f(x); f(y); f(z); f(vx); f(vy); f(vz); f(wx); f(wy); f(wz);
    f(fx); f(fy); f(fz); f(tx); f(ty); f(tz);
    f(radius); f(mass); f(inv_mass); f(inv_inertia); f(contacts); f(flags); f(material);
    if (external_force_) {
      f(ext_fx); f(ext_fy); f(ext_fz);
    }
    for (auto& a : aux) f(a);
  }
  template <class F>
  void for_each_array(F&& f) const {
    const_cast<ParticleStore*>(this)->for_each_array([&f](const auto& v) { f(v); });
  }

  /// Every array, the external-force switch, the aux count and the layout
  /// version, under `prefix` (checkpoints, core/archive.hpp).
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
};

}  // namespace domel::platform
