// SPDX-License-Identifier: MIT
// Guards the wall loads on a moving wall (issue 18 item 6): in the rotating
// drum of scenarios/examples/drum.json, rolling at a steady angle, the
// torque the bed puts on the drum about its axis equals the moment of the
// bed's weight about that axis, sum m_i ((x_i - o) x g) . e_y = g sum m_i x_i
// (the bed's angular momentum is steady, so the walls' torque on it and its
// weight's moment cancel on average), within 5 % (the tolerance; the
// instantaneous torque fluctuates by about 5 %, its mean over 0.7 s of rows
// by far less); and the drum carries the bed's weight, force_z = -M g,
// within 1 % (the centre of mass's vertical acceleration averages out over
// the window's 140 rows: 0.4 % measured; over only 15 instants it was 1.6 %).
// The moment is computed from the particle frames (every 0.05 s of the
// window), the loads are the means of probes.csv's rows (every 5 ms). Label "slow": about 30 s on two threads.
#include "support/fixture.hpp"

#include <gtest/gtest.h>

#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

namespace dt = domel::test;
namespace fs = std::filesystem;
using nlohmann::json;

TEST(Drum, TheDrumsTorqueIsTheMomentOfTheBedsWeightAndItCarriesTheWeight) {
  std::ifstream in(DOMEL_SOURCE_DIR "/scenarios/examples/drum.json");
  json doc = json::parse(in);
  doc["run"]["duration"] = 1.5;  // turning from 0.3 s, steady from about 0.6 s
  doc["output"].erase("contacts");
  const fs::path out = dt::run_into_temp(doc, DOMEL_SOURCE_DIR "/scenarios/examples/drum.json", "drum", 2);

  // probes.csv: time -> (torque, force_z)
  std::map<double, std::pair<double, double>> rows;
  const dt::Csv csv = dt::read_csv(out / "probes.csv");
  for (std::size_t r = 0; r < csv.rows.size(); ++r)
    rows[csv.at(r, "time")] = {csv.at(r, "drum.torque"), csv.at(r, "drum.force_z")};
  const double g = 9.81;
  double torque = 0, moment = 0, force = 0, weight = 0;
  int frames = 0;
  for (int k = 16; k <= 30; ++k) {  // frames every 0.05 s: t = 0.8 ... 1.5 s
    char name[64];
    std::snprintf(name, sizeof name, "particles_%06d.vtp", k);
    vtkNew<vtkXMLPolyDataReader> r;
    r->SetFileName((out / name).c_str());
    r->Update();
    vtkPolyData* p = r->GetOutput();
    vtkDataArray* mass = p->GetPointData()->GetArray("mass");
    ASSERT_NE(mass, nullptr) << name;
    double m_x = 0, m = 0;
    for (vtkIdType q = 0; q < p->GetNumberOfPoints(); ++q) {
      double x[3];
      p->GetPoint(q, x);
      m_x += mass->GetTuple1(q) * x[0];
      m += mass->GetTuple1(q);
    }
    const double t = 0.05 * k;
    // frames and rows fall on the first macro step (8.8 us) at or after their due time: the same one
    const auto it = rows.lower_bound(t - 1e-9);
    ASSERT_TRUE(it != rows.end() && it->first - t < 1e-5) << "no probe row at t = " << t;
    moment += g * m_x;  // (x - o) x (0, 0, -g m) . e_y = g m x (o on the axis at x = 0)
    weight += m * g;
    ++frames;
  }
  ASSERT_EQ(frames, 15);
  moment /= frames;
  weight /= frames;
  // the loads: every row of the window (every 5 ms), for the means of quantities that fluctuate
  int n_rows = 0;
  for (auto it = rows.lower_bound(0.8 - 1e-9); it != rows.end() && it->first <= 1.5 + 1e-5; ++it, ++n_rows) {
    torque += it->second.first;
    force += it->second.second;
  }
  ASSERT_GE(n_rows, 140);
  torque /= n_rows;
  force /= n_rows;
  RecordProperty("torque_Nm", std::to_string(torque));
  RecordProperty("moment_Nm", std::to_string(moment));
  std::printf("drum: mean torque %.5g N m, moment of the weight %.5g N m (%+.2f %%); force_z %.5g N, weight %.5g N\n",
              torque, moment, 100 * (torque / moment - 1), force, weight);
  EXPECT_LT(moment, -1e-3);  // the bed leans to -x: it is carried up on the side the drum's bottom turns to
  EXPECT_NEAR(torque, moment, 0.05 * std::fabs(moment));
  EXPECT_NEAR(force, -weight, 0.01 * weight);
  fs::remove_all(out);
}
