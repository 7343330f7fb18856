// SPDX-License-Identifier: MIT
// STL reading, welding and topology of triangle-mesh walls; closest features
// and the per-particle contact choice (see triangle_mesh.hpp).
#include "geometry/triangle_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>

namespace domel::platform {

namespace {

double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

std::string quoted(const std::filesystem::path& f) { return "'" + f.string() + "'"; }

/// A word of the file as a message may show it: at most 40 characters, bytes
/// outside printable ASCII as '?' (a binary file's bytes would garble the terminal).
std::string printable(const std::string& w) {
  std::string p = w.size() > 40 ? w.substr(0, 37) + "..." : w;
  for (char& c : p)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return p;
}

std::vector<double> read_ascii_stl(const std::filesystem::path& file, const std::string& text) {
  std::vector<double> out;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  int corners = 0;   // vertices seen in the current facet
  bool in_facet = false;
  bool saw_solid = false, saw_endsolid = false;
  auto fail = [&](const std::string& what) {
    throw MeshError("STL file " + quoted(file) + ", line " + std::to_string(line_no) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ls(line);
    std::string word;
    if (!(ls >> word)) continue;
    if (word == "solid") {
      saw_solid = true;
    } else if (word == "facet") {
      if (in_facet) fail("'facet' inside a facet (missing 'endfacet')");
      in_facet = true;
      corners = 0;
    } else if (word == "outer" || word == "endloop") {
    } else if (word == "vertex") {
      if (!in_facet) fail("'vertex' outside a facet");
      double v[3];
      for (double& c : v) {
        std::string tok;
        if (!(ls >> tok)) fail("expected 3 coordinates after 'vertex'");
        char* end = nullptr;
        c = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0') fail("expected a number, found '" + printable(tok) + "'");
        if (!std::isfinite(c)) fail("non-finite coordinate '" + printable(tok) + "'");
      }
      if (++corners > 3) fail("more than 3 vertices in a facet (triangle " + std::to_string(out.size() / 9 + 1) + ")");
      out.insert(out.end(), v, v + 3);
    } else if (word == "endfacet") {
      if (!in_facet) fail("'endfacet' without 'facet'");
      if (corners != 3)
        fail("facet (triangle " + std::to_string(out.size() / 9 + 1) + ") has " + std::to_string(corners) +
             " vertices, expected 3");
      in_facet = false;
    } else if (word == "endsolid") {
      if (in_facet) fail("'endsolid' inside a facet");
      saw_endsolid = true;
    } else {
      fail("unexpected '" + printable(word) + "' (expected solid, facet, outer loop, vertex, endloop, endfacet or endsolid)");
    }
  }
  if (in_facet) fail("file ends inside a facet");
  if (!saw_solid) throw MeshError("STL file " + quoted(file) + ": not an STL file (neither 'solid ...' text nor a binary STL of 84 + 50 n bytes)");
  if (!saw_endsolid) fail("the file ends without 'endsolid': it is truncated");
  return out;
}

}  // namespace

std::vector<double> read_stl(const std::filesystem::path& file) {
  // a folder opens as a stream on Linux and fails only when read, with an
  // error of the C++ library that names neither the file nor the wall
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw MeshError("STL file " + quoted(file) + " is a folder, not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw MeshError("cannot open STL file " + quoted(file));
  std::string bytes;
  try {
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {
    throw MeshError("cannot read STL file " + quoted(file) + ": " + e.what());
  }
  if (bytes.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);  // little-endian on every platform domel builds on
    if (bytes.size() == 84 + 50ull * n) {
      std::vector<double> out(9ull * n);
      for (uint32_t t = 0; t < n; ++t) {
        const char* rec = bytes.data() + 84 + 50ull * t;
        for (int k = 0; k < 9; ++k) {
          float f;
          std::memcpy(&f, rec + 12 + 4 * k, 4);
          if (!std::isfinite(f))
            throw MeshError("STL file " + quoted(file) + " (binary): triangle " + std::to_string(t + 1) +
                            " has a non-finite coordinate");
          out[9ull * t + k] = f;
        }
      }
      if (n == 0) throw MeshError("STL file " + quoted(file) + " (binary) holds no triangles");
      return out;
    }
  }
  const auto first = bytes.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || bytes.compare(first, 5, "solid") != 0)
    throw MeshError("STL file " + quoted(file) + ": not an STL file (" + std::to_string(bytes.size()) +
                    " bytes: neither text beginning with 'solid' nor a binary STL of 84 + 50 n bytes)");
  std::vector<double> out = read_ascii_stl(file, bytes);
  if (out.empty()) throw MeshError("STL file " + quoted(file) + " holds no triangles");
  return out;
}

double TriangleMesh::max_distance_from(const double o[3]) const {
  double m2 = 0;
  for (std::size_t v = 0; v < vertices.size(); v += 3) {
    const double dx = vertices[v] - o[0], dy = vertices[v + 1] - o[1], dz = vertices[v + 2] - o[2];
    m2 = std::max(m2, dx * dx + dy * dy + dz * dz);
  }
  return std::sqrt(m2);
}

TriangleMesh TriangleMesh::from_soup(const std::vector<double>& corners, double tol) {
  TriangleMesh m;
  // Weld: quantise to cells of size tol and merge with any vertex within tol
  // in the 27 neighbouring cells.
  struct Key {
    long long i, j, k;
    bool operator==(const Key& o) const { return i == o.i && j == o.j && k == o.k; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return std::hash<long long>()(k.i * 73856093LL ^ k.j * 19349663LL ^ k.k * 83492791LL);
    }
  };
  std::unordered_map<Key, std::vector<uint32_t>, Hash> cells;
  const double inv = tol > 0 ? 1.0 / tol : 0.0;
  auto weld = [&](const double* v) -> uint32_t {
    const Key c{static_cast<long long>(std::floor(v[0] * inv)), static_cast<long long>(std::floor(v[1] * inv)),
                static_cast<long long>(std::floor(v[2] * inv))};
    for (long long di = -1; di <= 1; ++di)
      for (long long dj = -1; dj <= 1; ++dj)
        for (long long dk = -1; dk <= 1; ++dk) {
          auto it = cells.find({c.i + di, c.j + dj, c.k + dk});
          if (it == cells.end()) continue;
          for (uint32_t idx : it->second) {
            const double* w = &m.vertices[3 * idx];
            const double dx = w[0] - v[0], dy = w[1] - v[1], dz = w[2] - v[2];
            if (dx * dx + dy * dy + dz * dz <= tol * tol) {
              ++m.welded;
              return idx;
            }
          }
        }
    const uint32_t idx = static_cast<uint32_t>(m.vertices.size() / 3);
    m.vertices.insert(m.vertices.end(), v, v + 3);
    cells[c].push_back(idx);
    return idx;
  };
  for (std::size_t t = 0; t + 9 <= corners.size(); t += 9) {
    const uint32_t a = weld(&corners[t]), b = weld(&corners[t + 3]), c = weld(&corners[t + 6]);
    const double* pa = &m.vertices[3 * a];
    const double* pb = &m.vertices[3 * b];
    const double* pc = &m.vertices[3 * c];
    const double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    const double w[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
    const double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    if (a == b || b == c || c == a || dot(cr, cr) <= 0.0) {
      ++m.dropped_degenerate;
      continue;
    }
    m.tri.insert(m.tri.end(), {a, b, c});
  }
  // Edges: one per unordered vertex pair.
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> edge_index;
  const std::size_t nt = m.triangle_count();
  m.tri_edge.resize(3 * nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.tri[3 * t + k], b = m.tri[3 * t + (k + 1) % 3];
      const auto key = std::minmax(a, b);
      auto [it, fresh] = edge_index.emplace(key, static_cast<uint32_t>(m.edge.size() / 2));
      if (fresh) m.edge.insert(m.edge.end(), {key.first, key.second});
      m.tri_edge[3 * t + k] = it->second;
    }
  auto csr = [&](std::size_t n, auto&& each, std::vector<uint32_t>& offset, std::vector<uint32_t>& items) {
    offset.assign(n + 1, 0);
    for (std::size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) ++offset[each(t, k) + 1];
    for (std::size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
    items.resize(offset[n]);
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) items[fill[each(t, k)]++] = static_cast<uint32_t>(t);
  };
  csr(m.edge_count(), [&](std::size_t t, int k) { return m.tri_edge[3 * t + k]; }, m.edge_tri_offset, m.edge_tris);
  csr(m.vertex_count(), [&](std::size_t t, int k) { return m.tri[3 * t + k]; }, m.vertex_tri_offset, m.vertex_tris);
  return m;
}

TriangleMesh load_stl_mesh(const std::filesystem::path& file, double scale, const double translate[3]) {
  std::vector<double> corners = read_stl(file);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < corners.size(); ++i) {
    corners[i] = corners[i] * scale + translate[i % 3];
    lo[i % 3] = std::min(lo[i % 3], corners[i]);
    hi[i % 3] = std::max(hi[i % 3], corners[i]);
  }
  const double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  TriangleMesh m = TriangleMesh::from_soup(corners, 1e-6 * diag);
  if (m.triangle_count() == 0)
    throw MeshError("STL file " + quoted(file) + ": all " + std::to_string(corners.size() / 9) +
                    " triangles are degenerate (zero area after welding)");
  return m;
}

TriangleFeature closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3],
                                    double q[3]) {
  // Ericson 2005, §5.1.5: test the Voronoi regions of the vertices and edges
  // with barycentric-style dot products, the face last.
  const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto set = [&](const double* o, double s, const double* dir, double t, const double* dir2) {
    for (int i = 0; i < 3; ++i) q[i] = o[i] + s * dir[i] + t * dir2[i];
  };
  const double zero[3] = {0, 0, 0};
  if (d1 <= 0.0 && d2 <= 0.0) { set(a, 0, zero, 0, zero); return TriangleFeature::vertex0; }
  const double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) { set(b, 0, zero, 0, zero); return TriangleFeature::vertex1; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    set(a, d1 / (d1 - d3), ab, 0, zero);
    return TriangleFeature::edge0;
  }
  const double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) { set(c, 0, zero, 0, zero); return TriangleFeature::vertex2; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    set(a, d2 / (d2 - d6), ac, 0, zero);
    return TriangleFeature::edge2;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double bc[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
    set(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), bc, 0, zero);
    return TriangleFeature::edge1;
  }
  const double denom = 1.0 / (va + vb + vc);
  set(a, vb * denom, ab, vc * denom, ac);
  return TriangleFeature::face;
}

void TriangleGrid::build(const std::vector<double>& verts, const TriangleMesh& mesh, double reach) {
  const std::size_t nt = mesh.triangle_count();
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t v = 0; v < verts.size(); v += 3)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], verts[v + a] - reach);
      hi[a] = std::max(hi[a], verts[v + a] + reach);
    }
  // Cells at least 2 reach wide, and at most ~2M of them. A flat mesh has
  // little volume: its cells grow until their count fits too (a reach of
  // 1e-12 m across a 10 cm chute asked for 10^11 cells), counted as doubles
  // before they are converted.
  double cell = 2.0 * reach;
  const double vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  cell = std::max(cell, std::cbrt(vol / 2.0e6));
  double n[3];
  for (;;) {
    inv_cell_ = 1.0 / cell;
    double count = 1.0;
    for (int a = 0; a < 3; ++a) {
      n[a] = std::max(1.0, std::ceil((hi[a] - lo[a]) * inv_cell_));  // NaN (an infinite extent): 1
      count *= n[a];
    }
    if (count <= 4.0e6) break;
    cell *= std::max(1.25, std::cbrt(count / 2.0e6));
  }
  for (int a = 0; a < 3; ++a) {
    lo_[a] = lo[a];
    dims_[a] = static_cast<int>(n[a]);
  }
  const std::size_t ncell = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  std::vector<std::pair<uint32_t, uint32_t>> pairs;  // (cell, triangle)
  const double half_diag = 0.8660254037844386 * cell;
  for (std::size_t t = 0; t < nt; ++t) {
    const double* a = &verts[3 * mesh.tri[3 * t]];
    const double* b = &verts[3 * mesh.tri[3 * t + 1]];
    const double* c = &verts[3 * mesh.tri[3 * t + 2]];
    int i0[3], i1[3];
    for (int k = 0; k < 3; ++k) {
      const double mn = std::min({a[k], b[k], c[k]}) - reach, mx = std::max({a[k], b[k], c[k]}) + reach;
      i0[k] = std::clamp(static_cast<int>(std::floor((mn - lo_[k]) * inv_cell_)), 0, dims_[k] - 1);
      i1[k] = std::clamp(static_cast<int>(std::floor((mx - lo_[k]) * inv_cell_)), 0, dims_[k] - 1);
    }
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double len = std::sqrt(dot(nrm, nrm));
    for (double& x : nrm) x /= len;
    for (int i = i0[0]; i <= i1[0]; ++i)
      for (int j = i0[1]; j <= i1[1]; ++j)
        for (int k = i0[2]; k <= i1[2]; ++k) {
          // skip cells whose centre is farther from the triangle's plane than reach + half a cell diagonal
          const double ctr[3] = {lo_[0] + (i + 0.5) * cell - a[0], lo_[1] + (j + 0.5) * cell - a[1],
                                 lo_[2] + (k + 0.5) * cell - a[2]};
          if (std::fabs(dot(ctr, nrm)) > reach + half_diag) continue;
          pairs.emplace_back(static_cast<uint32_t>((static_cast<std::size_t>(i) * dims_[1] + j) * dims_[2] + k),
                             static_cast<uint32_t>(t));
        }
  }
  start_.assign(ncell + 1, 0);
  for (const auto& pr : pairs) ++start_[pr.first + 1];
  for (std::size_t i = 0; i < ncell; ++i) start_[i + 1] += start_[i];
  items_.resize(pairs.size());
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (const auto& pr : pairs) items_[fill[pr.first]++] = pr.second;
}

void TriangleGrid::query(double x, double y, double z, std::vector<uint32_t>& out) const {
  const double p[3] = {x, y, z};
  int idx[3];
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - lo_[a]) * inv_cell_);
    if (!(f >= 0.0) || f >= dims_[a]) return;  // outside the grid: no triangle within reach
    idx[a] = static_cast<int>(f);
  }
  const std::size_t cellid = (static_cast<std::size_t>(idx[0]) * dims_[1] + idx[1]) * dims_[2] + idx[2];
  out.insert(out.end(), items_.begin() + start_[cellid], items_.begin() + start_[cellid + 1]);
}

void triangle_bounds(const TriangleMesh& mesh, const std::vector<double>& verts, std::vector<double>& bounds) {
  const std::size_t nt = mesh.triangle_count();
  bounds.resize(4 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const double* v[3] = {&verts[3 * mesh.tri[3 * t]], &verts[3 * mesh.tri[3 * t + 1]], &verts[3 * mesh.tri[3 * t + 2]]};
    double c[3];
    for (int a = 0; a < 3; ++a) c[a] = (v[0][a] + v[1][a] + v[2][a]) / 3.0;
    double r2 = 0;
    for (const double* x : v)
      r2 = std::max(r2, (x[0] - c[0]) * (x[0] - c[0]) + (x[1] - c[1]) * (x[1] - c[1]) + (x[2] - c[2]) * (x[2] - c[2]));
    for (int a = 0; a < 3; ++a) bounds[4 * t + a] = c[a];
    bounds[4 * t + 3] = std::sqrt(r2) * (1.0 + 1e-12);
  }
}

void resolve_mesh_contacts(const TriangleMesh& mesh, const double* verts, const double p[3], double r,
                           const uint32_t* tris, std::size_t count, MeshScratch& s, std::vector<MeshContact>& out,
                           const double* bounds) {
  out.clear();
  s.feature.resize(count);
  s.dist.resize(count);
  s.q.resize(3 * count);
  s.covered_edges.clear();
  s.covered_vertices.clear();
  s.counted_edges.clear();
  s.counted_vertices.clear();
  auto has = [](const std::vector<uint32_t>& v, uint32_t x) { return std::find(v.begin(), v.end(), x) != v.end(); };
  auto add = [&](uint32_t slot) {
    MeshContact c;
    c.slot = slot;
    c.d = s.dist[slot];
    for (int a = 0; a < 3; ++a) c.q[a] = s.q[3 * slot + a];
    if (c.d > 1e-12 * r) {
      for (int a = 0; a < 3; ++a) c.n[a] = (p[a] - c.q[a]) / c.d;
    } else {  // centre on the surface: the triangle's normal
      const uint32_t t = tris[slot];
      const double* a = &verts[3 * mesh.tri[3 * t]];
      const double* b = &verts[3 * mesh.tri[3 * t + 1]];
      const double* cc = &verts[3 * mesh.tri[3 * t + 2]];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double w[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
      double nv[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      const double len = std::sqrt(dot(nv, nv));
      for (int k = 0; k < 3; ++k) c.n[k] = nv[k] / len;
    }
    out.push_back(c);
  };
  // Pass 1: closest features; face contacts count and cover their edges and vertices.
  for (std::size_t k = 0; k < count; ++k) {
    const uint32_t t = tris[k];
    if (bounds) {  // cheap screen: the sphere cannot reach the triangle's enclosing sphere
      const double* b = bounds + 4 * t;
      const double dx = p[0] - b[0], dy = p[1] - b[1], dz = p[2] - b[2], reach = r + b[3];
      if (dx * dx + dy * dy + dz * dz >= reach * reach) {
        s.feature[k] = 255;
        s.dist[k] = r;
        continue;
      }
    }
    const uint32_t* tv = &mesh.tri[3 * t];
    double* q = &s.q[3 * k];
    const TriangleFeature f = closest_on_triangle(p, &verts[3 * tv[0]], &verts[3 * tv[1]], &verts[3 * tv[2]], q);
    const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    s.dist[k] = std::sqrt(dx * dx + dy * dy + dz * dz);
    s.feature[k] = s.dist[k] < r ? static_cast<uint8_t>(f) : uint8_t{255};
    if (f == TriangleFeature::face && s.dist[k] < r) {
      add(static_cast<uint32_t>(k));
      for (int e = 0; e < 3; ++e) {
        s.covered_edges.push_back(mesh.tri_edge[3 * t + e]);
        s.covered_vertices.push_back(tv[e]);
      }
    }
  }
  // Pass 2: edges not covered by a face contact, each once; they cover their end vertices.
  for (std::size_t k = 0; k < count; ++k) {
    const uint8_t f = s.feature[k];
    if (f < 1 || f > 3) continue;
    const uint32_t e = mesh.tri_edge[3 * tris[k] + (f - 1)];
    if (has(s.covered_edges, e) || has(s.counted_edges, e)) continue;
    s.counted_edges.push_back(e);
    s.covered_vertices.push_back(mesh.edge[2 * e]);
    s.covered_vertices.push_back(mesh.edge[2 * e + 1]);
    add(static_cast<uint32_t>(k));
  }
  // Pass 3: vertices not covered by a face or a counted edge, each once.
  for (std::size_t k = 0; k < count; ++k) {
    const uint8_t f = s.feature[k];
    if (f < 4 || f > 6) continue;
    const uint32_t v = mesh.tri[3 * tris[k] + (f - 4)];
    if (has(s.covered_vertices, v) || has(s.counted_vertices, v)) continue;
    s.counted_vertices.push_back(v);
    add(static_cast<uint32_t>(k));
  }
}

}  // namespace domel::platform
