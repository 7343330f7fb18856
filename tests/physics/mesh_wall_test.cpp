// Guards triangle-mesh walls (platform/geometry/triangle_mesh.*): a sphere
// rolling down a tilted plane made of STL triangles moves as on the
// equivalent analytic plane (1 %), and a sphere rolling across the seam of
// two coplanar triangles or over a vertex shared by four does not snag
// (velocity continuous, normal force = m g).
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

namespace dt = domel::test;
using nlohmann::json;

namespace {

constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kG = 9.81, kMu = 0.5;

/// Write triangles (9 numbers each) as an ASCII STL; returns its absolute path.
std::string write_stl(const std::string& name, const std::vector<std::array<double, 9>>& tris) {
  const auto p = std::filesystem::temp_directory_path() / ("domel_physics_" + name + ".stl");
  std::ofstream out(p);
  out.precision(17);
  out << "solid " << name << "\n";
  for (const auto& t : tris) {
    out << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) out << "vertex " << t[3 * k] << " " << t[3 * k + 1] << " " << t[3 * k + 2] << "\n";
    out << "endloop\nendfacet\n";
  }
  out << "endsolid " << name << "\n";
  return p.string();
}

/// A strip x in [x0, x1], y in [-w, w] in the plane z = 0, split into n
/// squares of two triangles each, then rotated by -beta about y (so that it
/// descends towards +x).
std::vector<std::array<double, 9>> strip(double x0, double x1, double w, int n, double beta) {
  std::vector<std::array<double, 9>> tris;
  const double c = std::cos(beta), s = std::sin(beta);
  auto rot = [&](double x, double y, double z, double* o) {
    o[0] = c * x + s * z;
    o[1] = y;
    o[2] = -s * x + c * z;
  };
  for (int k = 0; k < n; ++k) {
    const double a = x0 + (x1 - x0) * k / n, b = x0 + (x1 - x0) * (k + 1) / n;
    std::array<double, 9> t1, t2;
    rot(a, -w, 0, &t1[0]); rot(b, -w, 0, &t1[3]); rot(b, w, 0, &t1[6]);
    rot(a, -w, 0, &t2[0]); rot(b, w, 0, &t2[3]); rot(a, w, 0, &t2[6]);
    tris.push_back(t1);
    tris.push_back(t2);
  }
  return tris;
}

}  // namespace

TEST(MeshWall, TiltedMeshPlaneMatchesTheAnalyticPlane) {
  // Tolerance 1 % (the acceptance criterion): both runs use the same contact
  // law, time step and normal; only the geometry route differs (closest
  // feature of 16 triangles, crossing 15 seams, vs the plane's gap()).
  const double beta = 20.0 * M_PI / 180.0;
  const double nrm[3] = {std::sin(beta), 0.0, std::cos(beta)};
  double final_state[2][4];
  for (int variant = 0; variant < 2; ++variant) {
    json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, kMu);
    doc["gravity"] = {0, 0, -kG};
    if (variant == 0) {
      dt::add_plane(doc, "slope", {0, 0, 0}, {nrm[0], nrm[1], nrm[2]});
    } else {
      doc["walls"].push_back({{"name", "slope"}, {"type", "mesh"}, {"material", "m"},
                              {"file", write_stl("incline", strip(-0.05, 0.35, 0.02, 8, beta))}});
    }
    auto sim = dt::build(doc);
    auto& sd = *sim->subdomains[0];
    auto& s = sd.store();
    s.add(1, nrm[0] * kR, 0, nrm[2] * kR, kR, kRho);
    const auto rep = sd.estimate_time_step(0.1);
    sd.set_time_step(std::min(rep.contact_time / 50.0, 2e-5));
    sd.set_skin(0.2 * kD);
    sd.setup();
    while (sd.time() < 0.25) sd.step();
    final_state[variant][0] = s.x[0];
    final_state[variant][1] = s.z[0];
    final_state[variant][2] = s.vx[0];
    final_state[variant][3] = s.vz[0];
  }
  const double dist = std::hypot(final_state[0][0], final_state[0][1]);
  const double speed = std::hypot(final_state[0][2], final_state[0][3]);
  ASSERT_GT(dist, 0.05);  // it did roll a fair way (about 0.1 m), across several seams
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(final_state[1][k], final_state[0][k], 0.01 * dist) << "position component " << k;
    EXPECT_NEAR(final_state[1][2 + k], final_state[0][2 + k], 0.01 * speed) << "velocity component " << k;
  }
  // and the analytic plane itself rolls at (5/7) g sin(beta) (as incline_rolling_test checks)
  EXPECT_NEAR(speed, 5.0 / 7.0 * kG * std::sin(beta) * 0.25, 0.02 * speed);
}

namespace {

struct Crossing {
  double max_dv = 0;          ///< largest |v(t+dt) - v(t)| while crossing [m/s]
  double v_min = 1e9, v_max = 0;
  double fn_min = 1e9, fn_max = 0;  ///< normal wall force while crossing [N]
  double weight = 0;
  double x_end = 0;
};

/// A sphere rolling at 0.1 m/s in +x on the horizontal mesh `tris`, from x =
/// -0.01 through x = 0.01 (the features to cross lie around x = 0); an
/// empty `tris` rolls on the analytic plane z = 0 instead (the baseline).
Crossing roll_across(const std::vector<std::array<double, 9>>& tris, const std::string& name) {
  json doc = dt::scenario(dt::hertz_mindlin(), 1e-6, 0.5, kMu);
  doc["gravity"] = {0, 0, -kG};
  if (tris.empty())
    dt::add_plane(doc, "floor", {0, 0, 0}, {0, 0, 1});
  else
    doc["walls"].push_back({{"name", "floor"}, {"type", "mesh"}, {"material", "m"}, {"file", write_stl(name, tris)}});
  auto sim = dt::build(doc);
  auto& sd = *sim->subdomains[0];
  auto& s = sd.store();
  s.add(1, -0.02, 0.0, kR, kR, kRho);
  const auto rep = sd.estimate_time_step(0.1);
  sd.set_time_step(std::min(rep.contact_time / 50.0, 2e-5));
  sd.set_skin(0.2 * kD);
  sd.setup();
  // settle on the floor first (the start overlap is zero, so it bounces a little)
  while (sd.time() < 0.05) sd.step();
  s.vx[0] = 0.1;
  s.wy[0] = 0.1 / kR;  // rolling without slip
  s.vz[0] = 0.0;
  Crossing c;
  c.weight = s.mass[0] * kG;
  double v_prev = s.vx[0];
  while (s.x[0] < 0.01) {
    sd.step();
    if (s.x[0] < -0.01) continue;
    const double v = s.vx[0];
    c.max_dv = std::max(c.max_dv, std::fabs(v - v_prev));
    v_prev = v;
    c.v_min = std::min(c.v_min, v);
    c.v_max = std::max(c.v_max, v);
    const double fn = s.fz[0] + c.weight;  // fz holds the wall force plus the weight -m g
    c.fn_min = std::min(c.fn_min, fn);
    c.fn_max = std::max(c.fn_max, fn);
  }
  c.x_end = s.x[0];
  return c;
}

}  // namespace

TEST(MeshWall, RollingAcrossASeamDoesNotSnag) {
  // Two triangles whose shared edge runs diagonally across the path at x = 0.
  const std::vector<std::array<double, 9>> tris = {{-0.05, -0.05, 0, 0.05, -0.05, 0, 0.05, 0.05, 0},
                                                   {-0.05, -0.05, 0, 0.05, 0.05, 0, -0.05, 0.05, 0}};
  // Tolerances: on a flat analytic floor a settled sphere rolls at constant
  // speed, with the normal force equal to m g to within the residual
  // vertical oscillation left after settling (< 0.5 %). A double-counted
  // seam doubles the normal force; a missed one drops the sphere: both far
  // beyond 1 %. The velocity may wobble by the tangential spring's
  // oscillation (< 0.1 % of 0.1 m/s), and no step-to-step jump may exceed
  // the analytic plane's by more than 1e-6 m/s (1e-5 of the speed).
  const Crossing base = roll_across({}, "plane");
  const Crossing c = roll_across(tris, "seam");
  EXPECT_GT(c.x_end, 0.01);
  EXPECT_LT(c.fn_max, 1.01 * c.weight);
  EXPECT_GT(c.fn_min, 0.99 * c.weight);
  EXPECT_LT(c.v_max - c.v_min, 1e-4);
  EXPECT_LT(c.max_dv, base.max_dv + 1e-6);
}

TEST(MeshWall, RollingOverASharedVertexDoesNotSnag) {
  // Four triangles fanned around the vertex (0, 0, 0), which lies on the path.
  const double L = 0.05;
  const std::vector<std::array<double, 9>> tris = {{-L, -L, 0, L, -L, 0, 0, 0, 0},
                                                   {L, -L, 0, L, L, 0, 0, 0, 0},
                                                   {L, L, 0, -L, L, 0, 0, 0, 0},
                                                   {-L, L, 0, -L, -L, 0, 0, 0, 0}};
  const Crossing base = roll_across({}, "plane");
  const Crossing c = roll_across(tris, "fan");  // tolerances as for the seam
  EXPECT_GT(c.x_end, 0.01);
  EXPECT_LT(c.fn_max, 1.01 * c.weight);
  EXPECT_GT(c.fn_min, 0.99 * c.weight);
  EXPECT_LT(c.v_max - c.v_min, 1e-4);
  EXPECT_LT(c.max_dv, base.max_dv + 1e-6);
}
