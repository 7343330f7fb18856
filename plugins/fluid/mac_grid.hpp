// SPDX-License-Identifier: MIT
// The staggered (MAC) grid of the built-in fluid coupler (Harlow & Welch
// 1965): pressure, void fraction and the other scalars at the centres of
// nx ny nz uniform cells; the velocity component along axis a on the faces
// normal to a, a grid of (n_a + 1) nodes along a and n_b along the others.
// Cell (i, j, k) has index i + nx (j + ny k), the ordering of the SDK's grids;
// face (i, j, k) of axis a likewise with n_a + 1 along a. Also the
// cloud-in-cell (trilinear) weights of a point on the cell grid or on a face
// grid (Hockney & Eastwood 1988): continuous in the point's position, summing
// to 1, and clamped at the outermost nodes, so a point within half a cell of
// the boundary puts all its weight on the boundary nodes (the deposit keeps
// every particle's whole volume inside the grid).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace domel::plugins::fluid {

struct MacGrid {
  std::array<int, 3> n{1, 1, 1};
  std::array<double, 3> lo{0, 0, 0};
  std::array<double, 3> h{1, 1, 1};

  std::size_t cells() const { return static_cast<std::size_t>(n[0]) * n[1] * n[2]; }
  double cell_volume() const { return h[0] * h[1] * h[2]; }
  std::size_t cell(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(n[0]) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * k);
  }
  /// Nodes along axis d of the face grid of axis a.
  int fn(int a, int d) const { return n[d] + (d == a ? 1 : 0); }
  std::size_t faces(int a) const { return static_cast<std::size_t>(fn(a, 0)) * fn(a, 1) * fn(a, 2); }
  std::size_t face(int a, int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(fn(a, 0)) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(fn(a, 1)) * k);
  }
  double centre(int d, int idx) const { return lo[d] + (idx + 0.5) * h[d]; }
  double hi(int d) const { return lo[d] + n[d] * h[d]; }
  bool contains(const double x[3]) const {
    for (int d = 0; d < 3; ++d)
      if (!(x[d] >= lo[d] && x[d] <= hi(d))) return false;
    return true;
  }
};

/// The 8 nodes and trilinear weights of a point. axis -1: the cell grid;
/// 0, 1, 2: the face grid of that axis. Nodes may repeat where the grid has
/// one node along an axis or the point lies beyond the outermost node.
struct Stencil {
  std::array<std::size_t, 8> node{};
  std::array<double, 8> w{};
};

inline Stencil stencil(const MacGrid& g, int axis, const double x[3]) {
  int i0[3];
  double f[3];
  int count[3];
  for (int d = 0; d < 3; ++d) {
    count[d] = axis < 0 ? g.n[d] : g.fn(axis, d);
    const double off = (axis == d) ? 0.0 : 0.5;
    const double s = (x[d] - g.lo[d]) / g.h[d] - off;
    int i = static_cast<int>(std::floor(s));
    double t = s - i;
    if (count[d] == 1) {
      i = 0;
      t = 0.0;
    } else if (i < 0) {
      i = 0;
      t = 0.0;
    } else if (i >= count[d] - 1) {
      i = count[d] - 2;
      t = 1.0;
    }
    i0[d] = i;
    f[d] = t;
  }
  Stencil st;
  int q = 0;
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di, ++q) {
        const int i = std::min(i0[0] + di, count[0] - 1), j = std::min(i0[1] + dj, count[1] - 1),
                  k = std::min(i0[2] + dk, count[2] - 1);
        st.node[q] = static_cast<std::size_t>(i) + static_cast<std::size_t>(count[0]) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(count[1]) * k);
        st.w[q] = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
      }
  return st;
}

}  // namespace domel::plugins::fluid
