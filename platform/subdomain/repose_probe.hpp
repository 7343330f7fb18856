// SPDX-License-Identifier: MIT
// Angle-of-repose probe: the slope of a heap's free surface, measured the
// way the peers' repose analysis does (its "pooled" fit; docs/validation/repose.md)
// so that numbers compare directly:
//  - mobile particles only, and of them only those inside `region` and
//    slower than `max_speed` when these are set (a heap on a plate in a
//    scene with particles elsewhere); height h = z + r - base_height;
//  - horizontal centre = centroid (x, y) of the particles;
//  - square xy cells of side cell * d (d = mean diameter), surface height of
//    a cell = highest particle top in it, at the cell centre's distance r from
//    the centre: horizontal radius for a cone; for a planar heap (a slot
//    heap, a heap against a mirror wall), the distance along one horizontal
//    axis from the crest line, by default the centroid's coordinate;
//  - least-squares line h(r) through the cells with band_lo < h/H_max < band_hi
//    (drops the rounded apex and the one-particle-thick toe);
//  - angle = atan(-slope), in degrees.
#pragma once

#include "core/particle_store.hpp"

#include <domel/sdk/abi.h>

#include <optional>

namespace domel::platform {

struct ReposeProbeSettings {
  double base_height = 0.0;  ///< [m] height of the floor the heap rests on
  double cell = 1.5;         ///< cell side in mean particle diameters
  double band_lo = 0.2, band_hi = 0.8;
  bool planar = false;                ///< false: a cone about a vertical axis; true: a planar heap
  int axis = 0;                       ///< planar: 0 = x, 1 = y, the direction the heap slopes along
  std::optional<double> crest;        ///< planar: [m] coordinate of the crest line along axis; default: centroid
  std::optional<domel_region_v1> region;  ///< only particles whose centre is inside; default: all
  std::optional<double> max_speed;        ///< [m/s] only particles slower than this; default: all
};

/// The angle in degrees, or nothing when the surface gives no descending fit.
std::optional<double> repose_angle(const ParticleStore& s, const ReposeProbeSettings& settings);

}  // namespace domel::platform
