// SPDX-License-Identifier: MIT
// Guards what the contacts show in the output (issue 18 item 4): the load a
// settled layer puts on its floor in probes.csv (output.wall_loads) equals
// its weight and the weight's moment about an axis; the contact files
// (output.contacts) of a sphere on a sphere on a floor hold both contacts
// with the weights they carry and Hertz's overlap; the particle frames carry
// force, torque, mass and material.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace dt = domel::test;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kD = 0.0028, kR = kD / 2, kRho = 2500, kG = 9.81, kE = 5e6, kNu = 0.3;
const double kMass = kRho * M_PI / 6.0 * kD * kD * kD;

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("domel_wall_output_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(d);
  return d;
}

json run(const json& doc, const fs::path& out) {
  auto sim = dt::build(doc);
  domel::platform::RunOptions opt;
  opt.output_directory = out;
  opt.progress = false;
  return sim->run(opt, dt::builtin_registry()).summary;
}

/// The last row of probes.csv, by column name.
std::map<std::string, double> last_probe_row(const fs::path& csv) {
  std::ifstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::map<std::string, double> row;
  std::stringstream hs(header), vs(last);
  std::string name, value;
  while (std::getline(hs, name, ',') && std::getline(vs, value, ',')) row[name] = std::stod(value);
  return row;
}

/// A plane floor (material "m") under gravity, the layer or stack inserted by `insert`.
json on_a_floor(const json& insert, double duration) {
  json doc = dt::scenario(dt::hertz_mindlin(), 2e-6, 0.3, 0.5, kE, kNu, kRho);
  doc["gravity"] = {0, 0, -kG};
  dt::add_plane(doc, "floor", {0, 0, 0}, {0, 0, 1});
  doc["subdomains"][0]["insert"] = insert;
  doc["run"]["duration"] = duration;
  doc["output"]["probe_interval"] = duration / 10;
  return doc;
}

vtkSmartPointer<vtkPolyData> read_vtp(const fs::path& file) {
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(file.c_str());
  r->Update();
  return r->GetOutput();
}

}  // namespace

TEST(WallLoads, AFloorCarriesTheWeightOfASettledLayerAndItsMomentAboutAnAxis) {
  // Nine spheres (a 3 x 3 layer, spacing two diameters, off the origin)
  // dropped by R onto a floor and settled for 0.1 s (about 500 contact
  // times; restitution 0.3). At rest the floor carries the weight: force_z
  // = -9 m g on the floor (it is pushed down), and about the x axis through
  // the origin the moment of the contact forces (0, 0, -m g) at (x_i, y_i, 0)
  // is sum(-y_i m g). Tolerance 1e-6 relative: what is left of the bounce
  // after 500 contact times, far below it (the columns are instantaneous).
  const double a = 2 * kD;
  json insert = {{{"model", "lattice"}, {"diameter", kD}, {"spacing", 2.0},
                  {"region", {{"box", {{"min", {0.0, 0.01, 0.0}}, {"max", {3 * a, 0.01 + 3 * a, a}}}}}}}};
  json doc = on_a_floor(insert, 0.1);
  doc["output"]["wall_loads"] = {{{"wall", "floor"}, {"axis", {{"point", {0, 0, 0}}, {"direction", {1, 0, 0}}}}},
                                 {{"wall", "floor"}, {"name", "floor_plain"}}};
  const fs::path out = scratch("layer");
  run(doc, out);
  const auto row = last_probe_row(out / "probes.csv");
  ASSERT_EQ(row.at("sd.particles"), 9.0);
  const double weight = 9 * kMass * kG;
  EXPECT_NEAR(row.at("floor.force_z"), -weight, 1e-6 * weight);
  EXPECT_NEAR(row.at("floor.force_x"), 0.0, 1e-6 * weight);
  EXPECT_NEAR(row.at("floor.force_y"), 0.0, 1e-6 * weight);
  double moment = 0;  // rows of three at y = 0.01 + (j + 0.5) a
  for (int j = 0; j < 3; ++j) moment += -3 * kMass * kG * (0.01 + (j + 0.5) * a);
  EXPECT_NEAR(row.at("floor.torque"), moment, 1e-6 * std::fabs(moment));
  // a plane has no axis of its own: without one, no torque column
  EXPECT_EQ(row.count("floor_plain.torque"), 0u);
  EXPECT_EQ(row.at("floor_plain.force_z"), row.at("floor.force_z"));
  // the first row (t = 0: the layer is still in the air) has no load
  std::ifstream in(out / "probes.csv");
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  EXPECT_EQ(first.substr(0, 2), "0,");
  fs::remove_all(out);
}

TEST(ContactOutput, ASphereOnASphereOnAFloorShowsTheWeightsTheyCarryAndHertzOverlaps) {
  // Two spheres stacked on a floor, settled for 0.1 s: the pair contact
  // carries m g, the floor contact 2 m g, and each overlap is Hertz's for its
  // load, F = (4/3) E* sqrt(R*) delta^1.5 (docs/physics.md §1.1) with, for
  // equal materials, E* = E / (2 (1 - nu^2)); R* = R/2 for the pair and R
  // for the wall. Tolerance 1e-6 relative (the rest state, as above). Neither
  // contact slides; the tangential forces vanish.
  json insert = {{{"model", "lattice"}, {"diameter", kD}, {"spacing", 1.2},
                  {"region", {{"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {1.2 * kD, 1.2 * kD, 2.4 * kD}}}}}}}};
  json doc = on_a_floor(insert, 0.1);
  doc["output"]["contacts"] = json::object();
  doc["output"]["vtk_interval"] = 0.05;
  const fs::path out = scratch("stack");
  run(doc, out);
  const auto poly = read_vtp(out / "contacts_000002.vtp");  // t = 0.1 s
  ASSERT_EQ(poly->GetNumberOfCells(), 2);
  const double e_star = kE / (2 * (1 - kNu * kNu));
  auto hertz_overlap = [&](double f, double r_star) {
    return std::pow(3 * f / (4 * e_star * std::sqrt(r_star)), 2.0 / 3.0);
  };
  vtkCellData* cd = poly->GetCellData();
  int walls = 0;
  for (vtkIdType c = 0; c < 2; ++c) {
    const bool wall = cd->GetArray("wall")->GetTuple1(c) >= 0;
    walls += wall ? 1 : 0;
    const double load = (wall ? 2 : 1) * kMass * kG;
    EXPECT_NEAR(cd->GetArray("normal_force")->GetTuple1(c), load, 1e-6 * load);
    EXPECT_NEAR(cd->GetArray("overlap")->GetTuple1(c), hertz_overlap(load, wall ? kR : kR / 2),
                1e-6 * hertz_overlap(load, wall ? kR : kR / 2));
    const double* ft = cd->GetArray("tangential_force")->GetTuple3(c);
    EXPECT_LT(std::sqrt(ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]), 1e-9 * load);
    EXPECT_EQ(cd->GetArray("sliding")->GetTuple1(c), 0.0);
    // the line runs from the centre of i to the partner's centre or the contact point on the floor
    double p0[3], p1[3];
    poly->GetCell(c)->GetPoints()->GetPoint(0, p0);
    poly->GetCell(c)->GetPoints()->GetPoint(1, p1);
    if (wall) EXPECT_NEAR(p1[2], 0.0, 1e-12);
    else EXPECT_NEAR(std::fabs(p0[2] - p1[2]), kD - hertz_overlap(load, kR / 2), 1e-9);
  }
  EXPECT_EQ(walls, 1);
  // the particle frame of the same time: the total force on each sphere is
  // zero at rest, its mass and material are there
  const auto particles = read_vtp(out / "particles_000002.vtp");
  ASSERT_EQ(particles->GetNumberOfPoints(), 2);
  vtkPointData* pd = particles->GetPointData();
  for (vtkIdType k = 0; k < 2; ++k) {
    const double* f = pd->GetArray("force")->GetTuple3(k);
    EXPECT_LT(std::fabs(f[2]), 1e-6 * kMass * kG);
    EXPECT_NEAR(pd->GetArray("mass")->GetTuple1(k), kMass, 1e-12 * kMass);
    EXPECT_EQ(pd->GetArray("material")->GetTuple1(k), 0.0);
    ASSERT_NE(pd->GetArray("torque"), nullptr);
  }
  fs::remove_all(out);
}

TEST(ContactOutput, ASlidingContactIsFlaggedAtTheCoulombLimit) {
  // A sphere launched along the floor without spin slides (|F_t| = mu F_n)
  // until it rolls, after 2 v0 / (7 mu g) (moving_wall_test's belt, seen from
  // the belt): 10 ms for v0 = 0.1 m/s, mu = 0.5; the contacts at 2 ms slide,
  // those at 40 ms roll.
  json insert = {{{"model", "lattice"}, {"diameter", kD}, {"velocity", {0.1, 0, 0}},
                  {"region", {{"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {kD, kD, kD}}}}}}}};  // touching the floor
  json doc = on_a_floor(insert, 0.04);
  doc["output"]["contacts"] = {{"interval", 0.002}};
  const fs::path out = scratch("slide");
  run(doc, out);
  const auto early = read_vtp(out / "contacts_000001.vtp");
  ASSERT_EQ(early->GetNumberOfCells(), 1);
  EXPECT_EQ(early->GetCellData()->GetArray("sliding")->GetTuple1(0), 1.0);
  const double fn = early->GetCellData()->GetArray("normal_force")->GetTuple1(0);
  const double* ft = early->GetCellData()->GetArray("tangential_force")->GetTuple3(0);
  EXPECT_NEAR(std::sqrt(ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]), 0.5 * fn, 1e-9 * fn);
  EXPECT_LT(ft[0], 0.0);  // against the motion
  const auto late = read_vtp(out / "contacts_000020.vtp");
  ASSERT_EQ(late->GetNumberOfCells(), 1);
  EXPECT_EQ(late->GetCellData()->GetArray("sliding")->GetTuple1(0), 0.0);
  fs::remove_all(out);
}
