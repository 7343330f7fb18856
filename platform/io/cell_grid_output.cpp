// SPDX-License-Identifier: MIT
// CellGridVtkSeries builds a vtkImageData whose cells are the grid's cells
// (VTK orders cell data x fastest, then y, then z, the same flattening as
// CellFields) and writes it as the next frame of a VtkFrames series
// (vtkXMLImageDataWriter; temporary name then rename; .pvd rewritten).
// CellGridProfileCsv appends the layer profile rows
// to a CsvSeries and flushes it.
#include "io/cell_grid_output.hpp"

#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <unistd.h>

#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkXMLImageDataWriter.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace domel::platform::io {

namespace fs = std::filesystem;

namespace {


/// A cell-data array of `comps` components copied from `values`.
void add_array(vtkCellData* cd, const char* name, const std::vector<double>& values, int comps,
               std::size_t cells) {
  if (values.size() != cells * static_cast<std::size_t>(comps)) {
    throw std::invalid_argument(std::string("CellGridVtkSeries::write: field '") + name + "' has " +
                                std::to_string(values.size()) + " values, expected " +
                                std::to_string(cells * static_cast<std::size_t>(comps)));
  }
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(comps);
  a->SetNumberOfTuples(static_cast<vtkIdType>(cells));
  std::copy(values.begin(), values.end(), a->GetPointer(0));
  cd->AddArray(a);
}

void ensure_directory(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw RuntimeError("cannot create output directory '" + dir.string() + "': " + ec.message());
}

}  // namespace

CellGridVtkSeries::CellGridVtkSeries(fs::path directory, std::string basename)
    : directory_(directory), basename_(basename), frames_(std::move(directory), std::move(basename), "vti") {
  if (basename_.empty() || basename_.find('/') != std::string::npos) {
    throw std::invalid_argument("CellGridVtkSeries: basename must be a non-empty file name, got '" +
                                basename_ + "'");
  }
}

fs::path CellGridVtkSeries::write(double time, const CellGrid& grid, const CellFields& f) {
  const CellGridSpec& spec = grid.spec();
  const std::size_t cells = grid.cell_count();

  vtkNew<vtkImageData> image;
  image->SetDimensions(spec.cells[0] + 1, spec.cells[1] + 1, spec.cells[2] + 1);
  image->SetOrigin(spec.lo[0], spec.lo[1], spec.lo[2]);
  image->SetSpacing(grid.cell_size()[0], grid.cell_size()[1], grid.cell_size()[2]);

  if (f.vx.size() != cells || f.vy.size() != cells || f.vz.size() != cells) {
    throw std::invalid_argument("CellGridVtkSeries::write: velocity does not fit the grid");
  }
  std::vector<double> velocity(3 * cells);
  for (std::size_t c = 0; c < cells; ++c) {
    velocity[3 * c] = f.vx[c];
    velocity[3 * c + 1] = f.vy[c];
    velocity[3 * c + 2] = f.vz[c];
  }
  vtkCellData* cd = image->GetCellData();
  add_array(cd, "count", f.count, 1, cells);
  add_array(cd, "count_fixed", f.count_fixed, 1, cells);
  add_array(cd, "mass", f.mass, 1, cells);
  add_array(cd, "volume_fraction", f.volume_fraction, 1, cells);
  add_array(cd, "velocity", velocity, 3, cells);
  add_array(cd, "pressure", f.pressure, 1, cells);
  add_array(cd, "stress", f.stress, 9, cells);
  add_array(cd, "stress_kinetic", f.stress_kinetic, 9, cells);
  add_array(cd, "accessible", f.accessible, 1, cells);

  vtkNew<vtkDoubleArray> time_value;  // the name ParaView reads as the data set's time
  time_value->SetName("TimeValue");
  time_value->InsertNextValue(time);
  image->GetFieldData()->AddArray(time_value);
  vtkNew<vtkDoubleArray> samples;
  samples->SetName("samples");
  samples->InsertNextValue(static_cast<double>(f.samples));
  image->GetFieldData()->AddArray(samples);

  ensure_directory(directory_);
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetInputData(image);
  return frames_.write(*writer, time);
}

FieldImageSeries::FieldImageSeries(fs::path directory, std::string basename)
    : directory_(directory), frames_(std::move(directory), std::move(basename), "vti") {}

fs::path FieldImageSeries::write(double time, const FieldImage& img) {
  const std::size_t cells = static_cast<std::size_t>(img.cells[0]) * img.cells[1] * img.cells[2];
  if (cells == 0) throw std::invalid_argument("FieldImageSeries::write: the grid has no cells");
  vtkNew<vtkImageData> image;
  image->SetDimensions(static_cast<int>(img.cells[0]) + 1, static_cast<int>(img.cells[1]) + 1,
                       static_cast<int>(img.cells[2]) + 1);
  image->SetOrigin(img.origin[0], img.origin[1], img.origin[2]);
  image->SetSpacing(img.spacing[0], img.spacing[1], img.spacing[2]);
  vtkCellData* cd = image->GetCellData();
  for (const auto& f : img.fields) {
    std::vector<double> values(f.data, f.data + cells * static_cast<std::size_t>(f.components));
    add_array(cd, f.name.c_str(), values, f.components, cells);
  }
  vtkNew<vtkDoubleArray> time_value;
  time_value->SetName("TimeValue");
  time_value->InsertNextValue(time);
  image->GetFieldData()->AddArray(time_value);
  ensure_directory(directory_);
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetInputData(image);
  return frames_.write(*writer, time);
}

namespace {

int checked_axis(int axis) {
  if (axis < 0 || axis > 2) {
    throw std::invalid_argument("CellGridProfileCsv: axis must be 0, 1 or 2, got " + std::to_string(axis));
  }
  return axis;
}

}  // namespace

CellGridProfileCsv::CellGridProfileCsv(fs::path directory, const std::string& name, int axis)
    : directory_(std::move(directory)),
      path_(directory_ / (name + "_profile.csv")),
      axis_(checked_axis(axis)),
      csv_(path_,
           {"time", "layer", "centre", "accessible_volume", "count", "volume_fraction", "pressure", "vx", "vy",
            "vz"},
           // never flush on its own: write() flushes once per output time
           static_cast<std::size_t>(-1)) {}

void CellGridProfileCsv::write(double time, const CellGrid& grid, const CellFields& f) {
  const LayerProfile p = grid.profile(f, axis_);
  for (std::size_t L = 0; L < p.centre.size(); ++L) {
    csv_.append({time, static_cast<double>(L), p.centre[L], p.accessible_volume[L], p.count[L],
                 p.volume_fraction[L], p.pressure[L], p.vx[L], p.vy[L], p.vz[L]});
  }
  ensure_directory(directory_);
  csv_.flush();
}

}  // namespace domel::platform::io
