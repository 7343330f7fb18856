// SPDX-License-Identifier: MIT
// Guards the cell-average output (platform/io/cell_grid_output.cpp): the .vti
// frames read back with VTK's own reader (geometry, array names, component
// counts, values in the CellFields order), the .pvd lists every frame with
// its time, no temporary file remains, and the profile CSV has one row per
// layer per output time.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkXMLImageDataReader.h>

#include "averaging/cell_grid.hpp"
#include "core/particle_store.hpp"
#include "io/cell_grid_output.hpp"

namespace fs = std::filesystem;
using domel::platform::CellFields;
using domel::platform::CellGrid;
using domel::platform::CellGridSpec;
using domel::platform::ContactRecord;
using domel::platform::ParticleStore;
using domel::platform::io::CellGridProfileCsv;
using domel::platform::io::CellGridVtkSeries;

namespace {

/// A fresh directory under the system temp dir, removed with its contents.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() / ("domel_grid_test_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(stamp) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// 3x2x2 grid over [0,3]x[0,2]x[0,1] (cells of 1 x 1 x 0.5) with one moving
/// particle in cell (2,1,1) and a repulsive pair in cell (0,0,0).
CellGrid make_sampled_grid(const std::string& name) {
  CellGridSpec spec;
  spec.name = name;
  spec.hi[0] = 3;
  spec.hi[1] = 2;
  spec.hi[2] = 1;
  spec.cells[0] = 3;
  spec.cells[1] = 2;
  spec.cells[2] = 2;
  CellGrid grid(spec);
  ParticleStore s;
  s.add(0, 2.5, 1.5, 0.75, 0.1, 1000);
  s.add(1, 0.2, 0.5, 0.2, 0.1, 1000);
  s.add(2, 0.4, 0.5, 0.2, 0.1, 1000);
  s.vx[0] = 1;
  s.vy[0] = 2;
  s.vz[0] = 3;
  std::vector<ContactRecord> rec = {ContactRecord{1, 2, -5.0, 0, 0, s.x[2], s.y[2], s.z[2]}};
  grid.sample(s, {&rec}, 0.25);
  return grid;
}

std::vector<double> fields(const std::string& line) {
  std::vector<double> out;
  std::istringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) out.push_back(std::stod(cell));
  return out;
}

}  // namespace

TEST(IoCellGridVtkSeries, FramesReadBackAndCollectionListsThem) {
  TempDir dir;
  const fs::path out = dir.path() / "grids";  // created by the writer
  CellGrid grid = make_sampled_grid("silo");
  const CellFields& f = grid.latest();
  CellGridVtkSeries writer(out, "silo");
  const fs::path first = writer.write(0.25, grid, f);
  const fs::path second = writer.write(0.5, grid, f);
  EXPECT_EQ(first.filename(), "silo_000000.vti");
  EXPECT_EQ(second.filename(), "silo_000001.vti");
  EXPECT_EQ(writer.files_written(), 2u);

  vtkNew<vtkXMLImageDataReader> reader;
  reader->SetFileName(second.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  ASSERT_NE(img, nullptr);
  int dims[3];
  img->GetDimensions(dims);
  EXPECT_EQ(dims[0], 4);
  EXPECT_EQ(dims[1], 3);
  EXPECT_EQ(dims[2], 3);
  double spacing[3];
  img->GetSpacing(spacing);
  EXPECT_DOUBLE_EQ(spacing[2], 0.5);
  ASSERT_EQ(img->GetNumberOfCells(), 12);
  vtkCellData* cd = img->GetCellData();
  const struct {
    const char* name;
    int comps;
  } arrays[] = {{"count", 1},   {"count_fixed", 1}, {"mass", 1},           {"volume_fraction", 1},
                {"velocity", 3}, {"pressure", 1},   {"stress", 9},         {"stress_kinetic", 9},
                {"accessible", 1}};
  for (const auto& a : arrays) {
    vtkDataArray* arr = cd->GetArray(a.name);
    ASSERT_NE(arr, nullptr) << a.name;
    EXPECT_EQ(arr->GetNumberOfComponents(), a.comps) << a.name;
    EXPECT_EQ(arr->GetNumberOfTuples(), 12) << a.name;
  }
  // VTK's cell order (x fastest) must be the CellFields order.
  const std::size_t moving = grid.index(2, 1, 1);
  const double* v = cd->GetArray("velocity")->GetTuple3(static_cast<vtkIdType>(moving));
  // m v / m may differ from v in the last bit: same value as written, near the input
  EXPECT_EQ(v[2], f.vz[moving]);
  EXPECT_DOUBLE_EQ(v[0], 1.0);
  EXPECT_DOUBLE_EQ(v[1], 2.0);
  EXPECT_DOUBLE_EQ(v[2], 3.0);
  EXPECT_EQ(cd->GetArray("count")->GetTuple1(static_cast<vtkIdType>(moving)), 1.0);
  EXPECT_EQ(cd->GetArray("count")->GetTuple1(0), 2.0);
  EXPECT_EQ(cd->GetArray("stress")->GetComponent(0, 0), f.stress[0]);
  EXPECT_GT(cd->GetArray("pressure")->GetTuple1(0), 0.0);
  ASSERT_NE(img->GetFieldData()->GetArray("TimeValue"), nullptr);
  EXPECT_EQ(img->GetFieldData()->GetArray("TimeValue")->GetTuple1(0), 0.5);

  const std::string pvd = read_all(out / "silo.pvd");
  EXPECT_NE(pvd.find("<VTKFile type=\"Collection\""), std::string::npos);
  EXPECT_NE(pvd.find("timestep=\"0.25\" group=\"\" part=\"0\" file=\"silo_000000.vti\""), std::string::npos);
  EXPECT_NE(pvd.find("timestep=\"0.5\" group=\"\" part=\"0\" file=\"silo_000001.vti\""), std::string::npos);
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
  EXPECT_THROW(CellGridVtkSeries(out, "a/b"), std::invalid_argument);
}

TEST(IoCellGridProfileCsv, OneRowPerLayerPerOutputTime) {
  TempDir dir;
  CellGrid grid = make_sampled_grid("bed");
  CellGridProfileCsv csv(dir.path() / "out", "bed", 2);
  EXPECT_EQ(csv.path().filename(), "bed_profile.csv");
  csv.write(0.25, grid, grid.latest());
  csv.write(0.5, grid, grid.mean_since_last_take());
  std::istringstream text(read_all(csv.path()));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(text, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 1u + 2u * 2u);  // header + 2 layers x 2 times
  EXPECT_EQ(lines[0], "time,layer,centre,accessible_volume,count,volume_fraction,pressure,vx,vy,vz");
  // layer 1 (z in [0.5, 1)) holds the moving particle; the grid is fully accessible (volume 3)
  const std::vector<double> row = fields(lines[2]);
  ASSERT_EQ(row.size(), 10u);
  const std::vector<double> expected = {0.25, 1, 0.75, 3, 1, 4.0 / 3.0 * 3.14159265358979323846e-3 / 3.0, 0, 1, 2, 3};
  for (std::size_t k = 0; k < row.size(); ++k) {
    // round-off only (m v / m, a kinetic stress of ~1e-32 for a lone particle)
    EXPECT_NEAR(row[k], expected[k], 1e-12) << "column " << k << " of " << lines[2];
  }
  EXPECT_EQ(lines[3].rfind("0.5,0,0.25,3,2,", 0), 0u) << lines[3];
  EXPECT_THROW(CellGridProfileCsv(dir.path(), "x", 3), std::invalid_argument);
}
