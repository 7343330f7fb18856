// Guards STL reading (ASCII, binary, binary beginning with "solid"), vertex
// welding and topology, the errors for malformed files, the closest-feature
// classification of a triangle (Ericson 2005 §5.1.5) against hand-computed
// points, and the face/edge/vertex de-duplication of mesh contacts.
#include "geometry/triangle_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace dp = domel::platform;
namespace fs = std::filesystem;

namespace {

fs::path temp_file(const std::string& name, const std::string& bytes) {
  const fs::path p = fs::temp_directory_path() / ("domel_mesh_test_" + name);
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

/// Two triangles forming the unit square in z = 0 (shared diagonal).
const char* kSquareAscii =
    "solid square\n"
    "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 1 1 0\n"
    "    endloop\n  endfacet\n"
    "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 1 0\n      vertex 0 1 0\n"
    "    endloop\n  endfacet\n"
    "endsolid square\n";

std::string binary_stl(const std::vector<std::array<float, 9>>& tris, const std::string& header) {
  std::string b(80, ' ');
  std::memcpy(b.data(), header.data(), std::min<std::size_t>(80, header.size()));
  const uint32_t n = static_cast<uint32_t>(tris.size());
  b.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    float rec[12] = {0, 0, 1};
    std::copy(t.begin(), t.end(), rec + 3);
    b.append(reinterpret_cast<const char*>(rec), 48);
    b.append(2, '\0');
  }
  return b;
}

std::string error_of(const fs::path& p) {
  try {
    dp::read_stl(p);
  } catch (const dp::MeshError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(StlReader, AsciiSquareWeldsToFourVerticesAndFiveEdges) {
  const auto p = temp_file("square.stl", kSquareAscii);
  const double zero[3] = {0, 0, 0};
  const dp::TriangleMesh m = dp::load_stl_mesh(p, 1.0, zero);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.welded, 2u);
  EXPECT_EQ(m.edge_count(), 5u);
  // the diagonal is shared by both triangles, the four sides by one each
  int shared = 0;
  for (std::size_t e = 0; e < m.edge_count(); ++e)
    shared += (m.edge_tri_offset[e + 1] - m.edge_tri_offset[e]) == 2 ? 1 : 0;
  EXPECT_EQ(shared, 1);
}

TEST(StlReader, BinaryIsReadEvenWhenItsHeaderSaysSolid) {
  const std::vector<std::array<float, 9>> tris = {{0, 0, 0, 2, 0, 0, 2, 2, 0}, {0, 0, 0, 2, 2, 0, 0, 2, 0}};
  for (const std::string header : {"binary export", "solid written by a CAD tool"}) {
    const auto p = temp_file("bin.stl", binary_stl(tris, header));
    const auto corners = dp::read_stl(p);
    ASSERT_EQ(corners.size(), 18u) << header;
    EXPECT_DOUBLE_EQ(corners[3], 2.0);
    const double shift[3] = {1, 0, 0};
    const dp::TriangleMesh m = dp::load_stl_mesh(p, 0.5, shift);  // scale then translate
    EXPECT_EQ(m.vertex_count(), 4u);
    EXPECT_DOUBLE_EQ(m.vertices[0], 1.0);
    EXPECT_DOUBLE_EQ(m.vertices[3], 2.0);
  }
}

TEST(StlReader, WeldsCornersWithinTheRelativeTolerance) {
  // the second triangle's corners are off by 1e-9 of a unit-size mesh: welded
  std::vector<double> soup = {0, 0, 0, 1, 0, 0, 1, 1, 0, 1e-9, 0, 0, 1, 1 + 1e-9, 0, 0, 1, 0};
  const dp::TriangleMesh m = dp::TriangleMesh::from_soup(soup, 1e-6 * std::sqrt(2.0));
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.edge_count(), 5u);
}

TEST(StlReader, MalformedFilesNameTheFileAndTheLine) {
  const auto garbage = temp_file("garbage.stl", "this is not a mesh\n");
  EXPECT_NE(error_of(garbage).find("not an STL file"), std::string::npos) << error_of(garbage);
  EXPECT_NE(error_of(garbage).find("garbage.stl"), std::string::npos);

  std::string bad_number = kSquareAscii;
  bad_number.replace(bad_number.find("vertex 1 0 0"), 12, "vertex 1 x 0");
  const auto p = temp_file("badnum.stl", bad_number);
  const std::string e = error_of(p);
  EXPECT_NE(e.find("line 5"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a number, found 'x'"), std::string::npos) << e;

  std::string two_vertices = kSquareAscii;
  two_vertices.erase(two_vertices.find("      vertex 1 1 0\n"), 19);
  const std::string e2 = error_of(temp_file("twov.stl", two_vertices));
  EXPECT_NE(e2.find("triangle 1) has 2 vertices, expected 3"), std::string::npos) << e2;

  EXPECT_NE(error_of(fs::temp_directory_path() / "domel_no_such.stl").find("cannot open STL file"), std::string::npos);
}

TEST(ClosestFeature, FaceEdgesAndVerticesOfAHandComputedTriangle) {
  // a = origin, b = (2,0,0), c = (0,2,0); edge0 = ab, edge1 = bc, edge2 = ca
  const double a[3] = {0, 0, 0}, b[3] = {2, 0, 0}, c[3] = {0, 2, 0};
  struct Case {
    double p[3];
    dp::TriangleFeature f;
    double q[3];
  };
  const Case cases[] = {
      {{0.5, 0.5, 1.0}, dp::TriangleFeature::face, {0.5, 0.5, 0}},
      {{1.0, -1.0, 0.3}, dp::TriangleFeature::edge0, {1.0, 0, 0}},
      {{1.5, 1.5, -2.0}, dp::TriangleFeature::edge1, {1.0, 1.0, 0}},
      {{-1.0, 1.0, 0.0}, dp::TriangleFeature::edge2, {0, 1.0, 0}},
      {{-1.0, -1.0, 0.5}, dp::TriangleFeature::vertex0, {0, 0, 0}},
      {{3.0, -0.5, 0.0}, dp::TriangleFeature::vertex1, {2, 0, 0}},
      {{-0.5, 3.0, 1.0}, dp::TriangleFeature::vertex2, {0, 2, 0}},
  };
  for (const auto& cs : cases) {
    double q[3];
    const auto f = dp::closest_on_triangle(cs.p, a, b, c, q);
    EXPECT_EQ(static_cast<int>(f), static_cast<int>(cs.f)) << cs.p[0] << " " << cs.p[1] << " " << cs.p[2];
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(q[k], cs.q[k], 1e-14);
  }
}

TEST(MeshContacts, SeamAndSharedVertexGiveOneContact) {
  // Four triangles around the vertex (1,1,0): a 2 x 2 square split into a fan.
  std::vector<double> soup = {0, 0, 0, 2, 0, 0, 1, 1, 0,   2, 0, 0, 2, 2, 0, 1, 1, 0,
                              2, 2, 0, 0, 2, 0, 1, 1, 0,   0, 2, 0, 0, 0, 0, 1, 1, 0};
  const dp::TriangleMesh m = dp::TriangleMesh::from_soup(soup, 1e-9);
  ASSERT_EQ(m.vertex_count(), 5u);
  const uint32_t all[4] = {0, 1, 2, 3};
  dp::MeshScratch scratch;
  std::vector<dp::MeshContact> out;
  // on a face: one face contact
  const double on_face[3] = {1.0, 0.3, 0.09};
  dp::resolve_mesh_contacts(m, m.vertices.data(), on_face, 0.1, all, 4, scratch, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].d, 0.09, 1e-14);
  EXPECT_NEAR(out[0].n[2], 1.0, 1e-14);
  // exactly over the seam between triangles 0 and 1 (the edge from (2,0) to (1,1)): one edge contact
  const double on_seam[3] = {1.5, 0.5, 0.09};
  dp::resolve_mesh_contacts(m, m.vertices.data(), on_seam, 0.1, all, 4, scratch, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].d, 0.09, 1e-14);
  // exactly over the shared vertex: one contact, straight up
  const double on_vertex[3] = {1.0, 1.0, 0.09};
  dp::resolve_mesh_contacts(m, m.vertices.data(), on_vertex, 0.1, all, 4, scratch, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].n[2], 1.0, 1e-14);
  // beside the square's outer edge, below its plane: an edge contact from the side
  const double beside[3] = {2.05, 1.0, -0.05};
  dp::resolve_mesh_contacts(m, m.vertices.data(), beside, 0.1, all, 4, scratch, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].d, std::sqrt(2.0) * 0.05, 1e-14);
  EXPECT_NEAR(out[0].n[0], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(out[0].n[2], -std::sqrt(0.5), 1e-12);
}

TEST(MeshContacts, ConcaveCornerKeepsBothFaces) {
  // a floor and a wall meeting at x = 0: a sphere in the corner touches both faces
  std::vector<double> soup = {0, -1, 0, 1, -1, 0, 1, 1, 0,   0, -1, 0, 1, 1, 0, 0, 1, 0,
                              0, -1, 0, 0, 1, 0, 0, 1, 1,   0, -1, 0, 0, 1, 1, 0, -1, 1};
  const dp::TriangleMesh m = dp::TriangleMesh::from_soup(soup, 1e-9);
  const uint32_t all[4] = {0, 1, 2, 3};
  dp::MeshScratch scratch;
  std::vector<dp::MeshContact> out;
  const double p[3] = {0.09, 0.2, 0.09};
  dp::resolve_mesh_contacts(m, m.vertices.data(), p, 0.1, all, 4, scratch, out);
  EXPECT_EQ(out.size(), 2u);
}
