// SPDX-License-Identifier: MIT
// Refinement and coarsening between two resolution levels as operations with
// exact books (issue 42; docs/adaptive.md has the design and its choices).
//
// Refine: a coarse parcel's material becomes fine particles, (alpha_c /
// alpha_f)^3 of them per parcel in general not a whole number, so the mass
// that does not make a whole fine particle is carried (in the integer mass
// units of the flow balance, flow/particle_flow.hpp) to the next parcel of
// the same kind. The children are placed on a face-centred cubic cluster,
// randomly turned, inside the parcel's own sphere, at the radius at which
// they touch neither each other nor the sphere's surface; they start at that
// radius and grow to their own (a parcel in a dense packing holds its solid
// volume, which as fine spheres needs the packing's whole space: no
// placement at full size can be free of overlaps). Each child moves with the
// parcel's rigid motion, v + w x (x_i - X), and spins with w.
//
// Coarsen: fine particles, taken one after another (in space order, the
// caller's grouping), are added up until they make a parcel's mass; the
// parcel gets the mass-weighted position and velocity of what it took, the
// part of the last particle beyond the parcel's mass carried to the next
// parcel. The parcel's spin carries the group's angular momentum about its
// centre unless that would raise the kinetic energy: then its spin is
// lowered until it does not (energy is never created; the angular momentum
// not carried is reported).
//
// Books of every operation: mass in units (exact: the residual is checked
// to be zero), linear momentum (round-off), angular momentum about the
// centre, kinetic energy, and the granular temperature the operation added
// (refine: the children's velocities about their mean) or removed (coarsen).
#pragma once

#include "flow/particle_flow.hpp"

#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace domel::platform {

/// One particle's state as a conversion reads or makes it.
struct ConvertedBody {
  double x[3] = {0, 0, 0};   ///< [m] centre
  double v[3] = {0, 0, 0};   ///< [m/s]
  double w[3] = {0, 0, 0};   ///< [rad/s]
  double radius = 0;         ///< [m] its own (full) radius
  double mass = 0;           ///< [kg]
  double start_radius = 0;   ///< [m] made by refine or coarsen: the radius to place it at, growing to `radius`
};

/// What the refinements of one kind (a material and size) owe to the next
/// one: mass short of a whole fine particle, and its momentum.
struct CarriedMass {
  MassUnits units = 0;
  double momentum[3] = {0, 0, 0};  ///< [kg m/s]
};

/// The books of one or more operations: sums over everything that went in
/// (parcels or particles) and everything that came out (particles or
/// parcels, and the change of the mass carried or gathered between
/// operations, with its momentum).
struct ConversionBooks {
  std::uint64_t in = 0, out = 0;          ///< bodies consumed and made
  MassUnits mass_in = 0, mass_out = 0;
  double momentum_in[3] = {0, 0, 0}, momentum_out[3] = {0, 0, 0};
  /// about each operation's centre (the parcel's, or the made parcel's),
  /// summed; the carried mass's share is left out of both
  double angular_in[3] = {0, 0, 0}, angular_out[3] = {0, 0, 0};
  double kinetic_in = 0, kinetic_out = 0;  ///< [J] translation and rotation
  /// [J] kinetic energy of the velocities about each operation's mean
  /// velocity: what refining added as granular temperature, what coarsening
  /// took away (3/2 N k T in particle units: T = 2 E / (3 N m))
  double fluctuation = 0;
  double smallest_start = 1;               ///< smallest start_radius / radius of what was made
  MassUnits mass_residual() const { return mass_in - mass_out; }
  /// the largest component of momentum_in - momentum_out [kg m/s]
  double momentum_residual() const;
  /// the same over its scale, the largest |momentum| component that went in or out (0 when both are 0)
  double momentum_relative() const;
  void add(const ConversionBooks& o);
};

/// Solid-sphere moment of inertia.
inline double sphere_inertia(double mass, double radius) { return 0.4 * mass * radius * radius; }

/// The n points of a face-centred cubic lattice (nearest neighbours 1 apart)
/// closest to a random point, turned by a random rotation, with their
/// centroid moved to the origin; `reach` gets the largest distance from the
/// origin. The same generator state gives the same points.
std::vector<std::array<double, 3>> fcc_cluster(std::size_t n, std::mt19937_64& rng, double& reach);

/// Refine `parcel` into fine particles of radius `fine_radius` and mass
/// `fine_mass`: appends them to `made`, updates `carried` and `books`.
/// Makes as many whole fine particles as the parcel's mass and the carried
/// mass hold (in units of fine_mass's units): none while they hold less than
/// one; a particle short of a millionth of its mass counts as whole (a
/// parcel of a whole ratio k makes k^3 although the masses round apart),
/// the carried mass then that much below zero. The books count the parcel in, and the children and the change of
/// the carried mass (and its momentum) out, so that each operation's mass
/// residual is exactly zero and books summed over many close alike.
void refine_parcel(const ConvertedBody& parcel, double fine_radius, double fine_mass, CarriedMass& carried,
                   std::mt19937_64& rng, std::vector<ConvertedBody>& made, ConversionBooks& books);

/// A parcel being gathered from fine particles (coarsen_add), with what
/// the last parcel left of the particle that completed it. Positions are
/// taken about `ref` (the first particle of the gather) so that the sums of
/// the angular momentum do not lose digits to coordinates far from the origin.
struct CoarsenGather {
  MassUnits units = 0;
  double mass = 0;                       ///< [kg] the same mass as a double
  double ref[3] = {0, 0, 0};             ///< [m]
  double moment[3] = {0, 0, 0};          ///< sum of m (x - ref) [kg m]
  double momentum[3] = {0, 0, 0};        ///< sum of m v [kg m/s]
  double cross[3] = {0, 0, 0};           ///< sum of m (x - ref) x v [kg m^2/s]
  double spin[3] = {0, 0, 0};            ///< sum of I w [kg m^2/s]
  double kinetic = 0;                    ///< [J] translation and rotation
  double translation = 0;                ///< [J] translation alone
};

/// Coarsening: add `fine` to the parcel being gathered; each time the
/// gathered mass reaches `parcel_mass` (in its units) a parcel of
/// `parcel_radius` is appended to `made`, and the part of `fine` beyond it
/// stays gathered for the next. Its start_radius is `parcel_radius`: where
/// it may go and at what size is the caller's to say (it knows the
/// neighbours).
void coarsen_add(const ConvertedBody& fine, double parcel_radius, double parcel_mass, CoarsenGather& gather,
                 std::vector<ConvertedBody>& made, ConversionBooks& books);

}  // namespace domel::platform
