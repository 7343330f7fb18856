// SPDX-License-Identifier: MIT
// Triangle-mesh walls: STL reading (ASCII and binary), vertex welding, edge
// and adjacency tables, the closest feature of a triangle to a point, and the
// choice of which features of one particle's candidate triangles count as
// contacts (so that a sphere crossing the seam between two triangles feels
// one contact, not two or none).
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace domel::platform {

/// A problem with a mesh file: the message names the file and, where it
/// applies, the line (ASCII) or triangle (binary) at fault.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Welded triangle mesh with its topology. Triangle t has vertices
/// tri[3t..3t+2]; its edge k joins vertex k and vertex (k+1)%3 and has the
/// global index tri_edge[3t+k].
struct TriangleMesh {
  std::vector<double> vertices;     ///< x, y, z per welded vertex
  std::vector<uint32_t> tri;        ///< 3 vertex indices per triangle
  std::vector<uint32_t> edge;       ///< 2 vertex indices per edge (lower index first)
  std::vector<uint32_t> tri_edge;   ///< 3 edge indices per triangle
  std::vector<uint32_t> edge_tri_offset, edge_tris;      ///< triangles sharing each edge (CSR)
  std::vector<uint32_t> vertex_tri_offset, vertex_tris;  ///< triangles containing each vertex (CSR)
  std::size_t welded = 0;           ///< corner vertices merged into another by welding
  std::size_t dropped_degenerate = 0;

  std::size_t vertex_count() const { return vertices.size() / 3; }
  std::size_t triangle_count() const { return tri.size() / 3; }
  std::size_t edge_count() const { return edge.size() / 2; }
  /// Largest distance of a vertex from the point o.
  double max_distance_from(const double o[3]) const;

  /// Build from raw triangle corners (9 doubles per triangle): weld
  /// vertices closer than `weld_tolerance`, drop triangles that collapse,
  /// build the edge and adjacency tables.
  static TriangleMesh from_soup(const std::vector<double>& corners, double weld_tolerance);
};

/// Triangle corners (9 doubles per triangle) read from an STL file, ASCII
/// or binary (told apart by size: binary is exactly 84 + 50 n bytes, since a
/// binary file may also begin with "solid"). Throws MeshError.
std::vector<double> read_stl(const std::filesystem::path& file);

/// read_stl, then scale and translate, then weld with a tolerance of 1e-6
/// times the bounding-box diagonal. Throws MeshError.
TriangleMesh load_stl_mesh(const std::filesystem::path& file, double scale, const double translate[3]);

/// Feature of a triangle closest to a point.
enum class TriangleFeature : uint8_t { face = 0, edge0, edge1, edge2, vertex0, vertex1, vertex2 };

/// Closest point (qx, qy, qz) of triangle (a, b, c) to p and which feature it
/// lies on (Ericson, Real-Time Collision Detection, 2005, §5.1.5: Voronoi
/// regions of the vertices, then of the edges, else the face). Edge k joins
/// corner k and corner (k+1)%3.
TriangleFeature closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3],
                                    double q[3]);

/// Uniform grid over a mesh's triangles for candidate searches: each cell
/// lists the triangles whose bounding box, grown by `reach`, overlaps it.
class TriangleGrid {
 public:
  void build(const std::vector<double>& verts, const TriangleMesh& mesh, double reach);
  /// Triangles that may lie within `reach` of the point (appended to out; may repeat none).
  void query(double x, double y, double z, std::vector<uint32_t>& out) const;

 private:
  double lo_[3] = {0, 0, 0};
  double inv_cell_ = 1.0;
  int dims_[3] = {0, 0, 0};
  std::vector<uint32_t> start_, items_;
};

}  // namespace domel::platform

namespace domel::platform {

/// One counted contact of a particle with a mesh.
struct MeshContact {
  uint32_t slot;     ///< index into the particle's candidate triangles
  double d;          ///< centre distance from the contact point
  double n[3];       ///< unit normal from the contact point to the centre
  double q[3];       ///< contact point
};

/// Per-thread scratch of resolve_mesh_contacts().
struct MeshScratch {
  std::vector<uint8_t> feature;
  std::vector<double> dist, q;
  std::vector<uint32_t> covered_edges, covered_vertices, counted_edges, counted_vertices;
};

/// The contacts of a sphere (centre p, radius r) with its candidate
/// triangles `tris[0..count)` of `mesh` at vertex positions `verts`.
///
/// The normal points from the closest point to the centre, so a mesh acts
/// from both sides. De-duplication (the standard rule for spheres on
/// triangulated walls, e.g. Kremmer & Favier 2001, Su et al. 2011): every
/// face contact counts; an edge contact counts once, and only if no triangle
/// sharing that edge has a face contact; a vertex contact counts once, and
/// only if no triangle containing it has a face contact and no counted edge
/// contact ends at it. A triangle's own face contact covers its three edges
/// and vertices, so no adjacency lookup is needed.
///
/// `bounds` (4 per triangle: centre and radius of a sphere enclosing it, see
/// triangle_bounds()) screens out the candidates that cannot touch before
/// their closest point is computed; may be null.
void resolve_mesh_contacts(const TriangleMesh& mesh, const double* verts, const double p[3], double r,
                           const uint32_t* tris, std::size_t count, MeshScratch& scratch,
                           std::vector<MeshContact>& out, const double* bounds = nullptr);

/// Enclosing spheres of the triangles at vertex positions `verts`: centroid
/// and largest centroid-corner distance, 4 doubles per triangle.
void triangle_bounds(const TriangleMesh& mesh, const std::vector<double>& verts, std::vector<double>& bounds);

}  // namespace domel::platform
