// SPDX-License-Identifier: MIT
// Unit tests of the output writers in platform/io: atomic whole-file writes,
// the ParaView particle series (.vtp frames read back with VTK's own reader,
// .pvd index) and the CSV time series. Every test works in its own fresh
// temporary directory and removes it afterwards.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include <vtkCellArray.h>
#include <vtkFieldData.h>
#include <vtkStringArray.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkVariant.h>
#include <vtkXMLPolyDataReader.h>

#include "core/error.hpp"
#include "core/particle_store.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_series.hpp"
#include "io/vtk_writer.hpp"

namespace fs = std::filesystem;
using domel::platform::ParticleStore;
using domel::platform::RuntimeError;
using domel::platform::io::CsvSeries;
using domel::platform::io::ParticleSet;
using domel::platform::io::VtkSeriesWriter;
using domel::platform::io::write_file_atomically;

namespace {

/// A fresh directory under the system temp dir, removed with its contents.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() /
            ("domel_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(stamp) + "_" +
             std::to_string(counter++));
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

std::vector<std::string> temp_files_in(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.find(".tmp-") != std::string::npos) found.push_back(name);
  }
  return found;
}

std::size_t count(const std::string& haystack, const std::string& needle) {
  std::size_t n = 0;
  for (auto pos = haystack.find(needle); pos != std::string::npos;
       pos = haystack.find(needle, pos + 1)) {
    ++n;
  }
  return n;
}

/// A store of n particles whose every value is distinct and derived from `base`.
ParticleStore make_store(std::size_t n, double base, std::uint64_t first_id) {
  ParticleStore s;
  for (std::size_t i = 0; i < n; ++i) {
    const double b = base + 10.0 * static_cast<double>(i);
    s.id.push_back(first_id + i);
    s.x.push_back(b + 0.1); s.y.push_back(b + 0.2); s.z.push_back(b + 0.3);
    s.vx.push_back(b + 1.1); s.vy.push_back(b + 1.2); s.vz.push_back(b + 1.3);
    s.wx.push_back(b + 2.1); s.wy.push_back(b + 2.2); s.wz.push_back(b + 2.3);
    s.fx.push_back(b + 3.1); s.fy.push_back(b + 3.2); s.fz.push_back(b + 3.3);
    s.tx.push_back(b + 4.1); s.ty.push_back(b + 4.2); s.tz.push_back(b + 4.3);
    s.radius.push_back(0.001 * (b + 1.0));
    s.mass.push_back(b + 5.0); s.inv_mass.push_back(1.0); s.inv_inertia.push_back(1.0);
    s.contacts.push_back(static_cast<std::uint32_t>(i + 3));
    s.material.push_back(static_cast<std::uint8_t>(i % 2));
  }
  return s;
}

}  // namespace

// Guards that write_file_atomically stores exactly the given bytes and replaces an older file.
TEST(IoAtomicFile, ContentsRoundTripAndReplace) {
  TempDir dir;
  const fs::path p = dir.path() / "out.txt";
  write_file_atomically(p, "old contents that are longer\n");
  const std::string contents = std::string("line 1\nline 2\n") + '\0' + "binary\xff";
  write_file_atomically(p, contents);
  EXPECT_EQ(read_all(p), contents);
  write_file_atomically(p, "");
  EXPECT_TRUE(fs::exists(p));
  EXPECT_EQ(fs::file_size(p), 0u);
}

// Guards that no "<path>.tmp-<pid>" file is left behind after a successful write.
TEST(IoAtomicFile, NoTempFileRemains) {
  TempDir dir;
  write_file_atomically(dir.path() / "a.txt", "a");
  write_file_atomically(dir.path() / "b.txt", "b");
  EXPECT_TRUE(temp_files_in(dir.path()).empty());
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2);
}

// Guards that a failed write throws RuntimeError naming the target path.
TEST(IoAtomicFile, MissingDirectoryThrowsWithPath) {
  TempDir dir;
  const fs::path p = dir.path() / "does_not_exist" / "out.txt";
  try {
    write_file_atomically(p, "x");
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(p));
  EXPECT_TRUE(temp_files_in(dir.path()).empty());
}

// Guards that a failed rename (target is a directory) removes the temp file and throws.
TEST(IoAtomicFile, FailedRenameRemovesTempFile) {
  TempDir dir;
  const fs::path p = dir.path() / "occupied";
  fs::create_directories(p / "child");
  EXPECT_THROW(write_file_atomically(p, "x"), RuntimeError);
  EXPECT_TRUE(temp_files_in(dir.path()).empty());
}

// Guards the .vtp contents (points, vertex cells, every array, values) and the .pvd index.
TEST(IoVtkSeriesWriter, WritesFramesAndCollection) {
  TempDir dir;
  const ParticleStore a = make_store(3, 0.0, 100);
  ParticleStore b = make_store(2, 1000.0, (std::uint64_t{1} << 60) + 7);  // id beyond 2^53
  const fs::path out = dir.path() / "vtk";  // created by the writer

  VtkSeriesWriter writer(out, "particles");
  writer.set_material_names({"a", "b", "c", "d", "e", "steel"});
  EXPECT_EQ(writer.files_written(), 0u);
  const std::vector<std::size_t> b_materials = {2, 5};  // b's local materials 0, 1 are the scenario's 2, 5
  const fs::path first = writer.write(0.0, {{&a, 0}, {&b, 3, &b_materials}});
  b.vx[1] = -42.0;
  const fs::path second = writer.write(0.5, {{&a, 0}, {&b, 3, &b_materials}});
  EXPECT_EQ(writer.files_written(), 2u);
  EXPECT_EQ(first, out / "particles_000000.vtp");
  EXPECT_EQ(second, out / "particles_000001.vtp");
  ASSERT_TRUE(fs::exists(first));
  ASSERT_TRUE(fs::exists(second));

  // Appended raw binary, zlib-compressed.
  const std::string raw = read_all(second);
  EXPECT_NE(raw.find("format=\"appended\""), std::string::npos);
  EXPECT_NE(raw.find("encoding=\"raw\""), std::string::npos);
  EXPECT_NE(raw.find("vtkZLibDataCompressor"), std::string::npos);

  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(second.c_str());
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  ASSERT_NE(poly, nullptr);
  ASSERT_EQ(poly->GetNumberOfPoints(), 5);
  ASSERT_EQ(poly->GetNumberOfVerts(), 5);
  EXPECT_EQ(poly->GetNumberOfCells(), 5);
  for (vtkIdType c = 0; c < 5; ++c) EXPECT_EQ(poly->GetCellType(c), VTK_VERTEX);

  // Particle 3 of the output is particle 0 of the second set; particle 4 is b[1].
  double p[3];
  poly->GetPoint(3, p);
  EXPECT_EQ(p[0], b.x[0]);
  EXPECT_EQ(p[1], b.y[0]);
  EXPECT_EQ(p[2], b.z[0]);
  poly->GetPoint(1, p);
  EXPECT_EQ(p[0], a.x[1]);

  vtkPointData* pd = poly->GetPointData();
  struct Expected {
    const char* name;
    int components;
  };
  for (const Expected& e : {Expected{"velocity", 3}, Expected{"angular_velocity", 3}, Expected{"force", 3},
                            Expected{"torque", 3}, Expected{"radius", 1}, Expected{"mass", 1}, Expected{"id", 1},
                            Expected{"subdomain", 1}, Expected{"material", 1}, Expected{"contacts", 1}}) {
    vtkAbstractArray* arr = pd->GetAbstractArray(e.name);
    ASSERT_NE(arr, nullptr) << e.name;
    EXPECT_EQ(arr->GetNumberOfComponents(), e.components) << e.name;
    EXPECT_EQ(arr->GetNumberOfTuples(), 5) << e.name;
  }
  EXPECT_EQ(pd->GetArray("velocity")->GetDataType(), VTK_DOUBLE);
  EXPECT_EQ(pd->GetArray("angular_velocity")->GetDataType(), VTK_DOUBLE);
  EXPECT_EQ(pd->GetArray("radius")->GetDataType(), VTK_DOUBLE);
  EXPECT_EQ(pd->GetArray("id")->GetDataType(), VTK_TYPE_UINT64);
  EXPECT_EQ(pd->GetArray("subdomain")->GetDataType(), VTK_INT);
  EXPECT_EQ(pd->GetArray("contacts")->GetDataType(), VTK_INT);

  double v[3];
  pd->GetArray("velocity")->GetTuple(4, v);
  EXPECT_EQ(v[0], -42.0);
  EXPECT_EQ(v[1], b.vy[1]);
  EXPECT_EQ(v[2], b.vz[1]);
  pd->GetArray("angular_velocity")->GetTuple(4, v);
  EXPECT_EQ(v[0], b.wx[1]);
  EXPECT_EQ(pd->GetArray("radius")->GetTuple1(4), b.radius[1]);
  EXPECT_EQ(pd->GetAbstractArray("id")->GetVariantValue(4).ToTypeUInt64(), b.id[1]);
  EXPECT_EQ(pd->GetAbstractArray("id")->GetVariantValue(0).ToTypeUInt64(), 100u);
  EXPECT_EQ(pd->GetArray("subdomain")->GetTuple1(4), 3.0);
  EXPECT_EQ(pd->GetArray("subdomain")->GetTuple1(2), 0.0);
  EXPECT_EQ(pd->GetArray("contacts")->GetTuple1(4), static_cast<double>(b.contacts[1]));
  pd->GetArray("force")->GetTuple(4, v);
  EXPECT_EQ(v[0], b.fx[1]);
  EXPECT_EQ(v[2], b.fz[1]);
  pd->GetArray("torque")->GetTuple(4, v);
  EXPECT_EQ(v[1], b.ty[1]);
  EXPECT_EQ(pd->GetArray("mass")->GetTuple1(4), b.mass[1]);
  EXPECT_EQ(pd->GetArray("material")->GetTuple1(4), 5.0);  // b[1]: local 1, the scenario's 5
  EXPECT_EQ(pd->GetArray("material")->GetTuple1(3), 2.0);
  EXPECT_EQ(pd->GetArray("material")->GetTuple1(1), 0.0);  // a set without materials: 0
  auto* names = vtkStringArray::SafeDownCast(poly->GetFieldData()->GetAbstractArray("material_names"));
  ASSERT_NE(names, nullptr);
  ASSERT_EQ(names->GetNumberOfValues(), 6);
  EXPECT_EQ(names->GetValue(5), "steel");

  // The first frame still holds the old velocity.
  vtkNew<vtkXMLPolyDataReader> reader0;
  reader0->SetFileName(first.c_str());
  reader0->Update();
  reader0->GetOutput()->GetPointData()->GetArray("velocity")->GetTuple(4, v);
  EXPECT_EQ(v[0], 1000.0 + 10.0 + 1.1);

  const fs::path pvd = out / "particles.pvd";
  ASSERT_TRUE(fs::exists(pvd));
  const std::string xml = read_all(pvd);
  EXPECT_NE(xml.find("<VTKFile type=\"Collection\" version=\"0.1\">"), std::string::npos);
  EXPECT_NE(xml.find("<Collection>"), std::string::npos);
  EXPECT_NE(xml.find("</Collection>"), std::string::npos);
  EXPECT_NE(xml.find("timestep=\"0\" group=\"\" part=\"0\" file=\"particles_000000.vtp\""),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("timestep=\"0.5\" group=\"\" part=\"0\" file=\"particles_000001.vtp\""),
            std::string::npos)
      << xml;
  EXPECT_EQ(count(xml, "<DataSet "), 2u);
  EXPECT_LT(xml.find("particles_000000.vtp"), xml.find("particles_000001.vtp"));

  EXPECT_TRUE(temp_files_in(out).empty());
}

// Guards that an empty frame (no particles) is still a valid, readable file.
TEST(IoVtkSeriesWriter, EmptyFrame) {
  TempDir dir;
  const ParticleStore empty;
  VtkSeriesWriter writer(dir.path(), "empty");
  const fs::path f = writer.write(1.25, {{&empty, 0}});
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(f.c_str());
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), 0);
  EXPECT_NE(read_all(dir.path() / "empty.pvd").find("timestep=\"1.25\""), std::string::npos);
  EXPECT_TRUE(temp_files_in(dir.path()).empty());
}

// Guards the argument checks: bad basename, null store, inconsistent store arrays.
TEST(IoVtkSeriesWriter, RejectsBadInput) {
  TempDir dir;
  EXPECT_THROW(VtkSeriesWriter(dir.path(), ""), std::invalid_argument);
  EXPECT_THROW(VtkSeriesWriter(dir.path(), "a/b"), std::invalid_argument);
  VtkSeriesWriter writer(dir.path(), "p");
  EXPECT_THROW(writer.write(0.0, {{nullptr, 0}}), std::invalid_argument);
  ParticleStore broken = make_store(2, 0.0, 1);
  broken.vz.pop_back();
  EXPECT_THROW(writer.write(0.0, {{&broken, 0}}), RuntimeError);
  EXPECT_EQ(writer.files_written(), 0u);
  EXPECT_FALSE(fs::exists(dir.path() / "p.pvd"));
}

// Guards the header line, the row format and that rows exactly round-trip as doubles.
TEST(IoCsvSeries, HeaderAndRows) {
  TempDir dir;
  const fs::path p = dir.path() / "series.csv";
  {
    CsvSeries csv(p, {"time", "kinetic energy", "a,b"});
    csv.append({0.0, 1.5, -2.0});
    csv.append({0.1, 1.0 / 3.0, 1e-300});
    csv.flush();
    EXPECT_EQ(read_all(p),
              "time,kinetic energy,\"a,b\"\n"
              "0,1.5,-2\n"
              "0.1,0.3333333333333333,1e-300\n");
  }
  std::ifstream in(p);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  std::getline(in, row);
  EXPECT_EQ(std::stod(row.substr(row.find(',') + 1)), 1.0 / 3.0);
  EXPECT_TRUE(temp_files_in(dir.path()).empty());
}

// Guards the automatic flush once flush_every rows are pending (and not before).
TEST(IoCsvSeries, FlushEveryRows) {
  TempDir dir;
  const fs::path p = dir.path() / "s.csv";
  CsvSeries csv(p, {"t", "x"}, 3);
  csv.append({1, 10});
  csv.append({2, 20});
  EXPECT_FALSE(fs::exists(p));
  csv.append({3, 30});
  ASSERT_TRUE(fs::exists(p));
  EXPECT_EQ(read_all(p), "t,x\n1,10\n2,20\n3,30\n");
  csv.append({4, 40});
  EXPECT_EQ(read_all(p), "t,x\n1,10\n2,20\n3,30\n");
  csv.append({5, 50});
  csv.append({6, 60});
  EXPECT_EQ(read_all(p), "t,x\n1,10\n2,20\n3,30\n4,40\n5,50\n6,60\n");
}

// Guards that the destructor writes pending rows, and a header-only file when there are none.
TEST(IoCsvSeries, DestructorFlushes) {
  TempDir dir;
  const fs::path p = dir.path() / "d.csv";
  {
    CsvSeries csv(p, {"t"}, 1000);
    csv.append({0.25});
    EXPECT_FALSE(fs::exists(p));
  }
  EXPECT_EQ(read_all(p), "t\n0.25\n");

  const fs::path q = dir.path() / "header_only.csv";
  { CsvSeries csv(q, {"t", "y"}); }
  EXPECT_EQ(read_all(q), "t,y\n");
}

// Guards that a destructor flush into a missing directory does not throw.
TEST(IoCsvSeries, DestructorNeverThrows) {
  TempDir dir;
  const fs::path p = dir.path() / "missing" / "d.csv";
  EXPECT_NO_THROW({
    CsvSeries csv(p, {"t"});
    csv.append({1.0});
  });
  EXPECT_FALSE(fs::exists(p));
}

// Guards that flushes after the first append to the file (the same file, not
// a rewritten copy), and that a restart's resume() cuts the file back to a
// checkpoint's length and refuses a file of another header.
TEST(IoCsvSeries, AppendsAndResumes) {
  TempDir dir;
  const fs::path p = dir.path() / "a.csv";
  std::size_t at_checkpoint = 0;
  {
    CsvSeries csv(p, {"t", "x"}, 1);
    csv.append({1, 10});
    struct stat before {};
    ASSERT_EQ(::stat(p.c_str(), &before), 0);
    at_checkpoint = csv.size();
    csv.append({2, 20});
    csv.append({3, 30});
    struct stat after {};
    ASSERT_EQ(::stat(p.c_str(), &after), 0);
    EXPECT_EQ(before.st_ino, after.st_ino) << "the file was replaced, not appended to";
    EXPECT_EQ(read_all(p), "t,x\n1,10\n2,20\n3,30\n");
    EXPECT_EQ(csv.size(), read_all(p).size());
  }
  {
    CsvSeries csv(p, {"t", "x"}, 1);
    csv.resume(at_checkpoint);
    EXPECT_EQ(read_all(p), "t,x\n1,10\n");
    csv.append({2, 21});
    EXPECT_EQ(read_all(p), "t,x\n1,10\n2,21\n");
  }
  CsvSeries other(p, {"t", "y"});
  EXPECT_THROW(other.resume(at_checkpoint), domel::platform::RuntimeError);
  CsvSeries longer(p, {"t", "x"});
  EXPECT_THROW(longer.resume(1000), domel::platform::RuntimeError);
  EXPECT_TRUE(temp_files_in(dir.path()).empty());
}

// Guards that a row of the wrong width throws and is not recorded.
TEST(IoCsvSeries, WrongRowSizeThrows) {
  TempDir dir;
  const fs::path p = dir.path() / "w.csv";
  CsvSeries csv(p, {"a", "b"});
  EXPECT_THROW(csv.append({1.0}), std::invalid_argument);
  EXPECT_THROW(csv.append({1.0, 2.0, 3.0}), std::invalid_argument);
  csv.append({1.0, 2.0});
  csv.flush();
  EXPECT_EQ(read_all(p), "a,b\n1,2\n");
  EXPECT_THROW(CsvSeries(p, {}), std::invalid_argument);
}
