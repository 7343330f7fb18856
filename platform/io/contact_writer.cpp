// SPDX-License-Identifier: MIT
// ContactSeriesWriter: the contact rows as line cells of a vtkPolyData.
#include "io/contact_writer.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTypeUInt64Array.h>
#include <vtkXMLPolyDataWriter.h>



namespace domel::platform::io {

namespace fs = std::filesystem;

ContactSeriesWriter::ContactSeriesWriter(fs::path directory, std::string basename)
    : frames_(std::move(directory), std::move(basename), "vtp") {}

fs::path ContactSeriesWriter::write(double time, const std::vector<ContactRow>& rows) {
  const auto n = static_cast<vtkIdType>(rows.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(2 * n);
  auto vec = [n](const char* name) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(3);
    a->SetNumberOfTuples(n);
    return a;
  };
  auto scalar = [n](const char* name) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfTuples(n);
    return a;
  };
  auto integer = [n](const char* name) {
    vtkNew<vtkIntArray> a;
    a->SetName(name);
    a->SetNumberOfTuples(n);
    return a;
  };
  auto id = [n](const char* name) {
    vtkNew<vtkTypeUInt64Array> a;
    a->SetName(name);
    a->SetNumberOfTuples(n);
    return a;
  };
  auto force = vec("force");
  auto tangential = vec("tangential_force");
  auto normal = scalar("normal_force");
  auto overlap = scalar("overlap");
  auto id_i = id("id_i");
  auto id_j = id("id_j");
  auto subdomain = integer("subdomain");
  auto wall = integer("wall");
  auto sliding = integer("sliding");
  vtkNew<vtkIdTypeArray> offsets;
  offsets->SetNumberOfTuples(n + 1);
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfTuples(2 * n);

  auto* pos = static_cast<double*>(points->GetData()->GetVoidPointer(0));
  for (vtkIdType k = 0; k < n; ++k) {
    const ContactRow& r = rows[static_cast<std::size_t>(k)];
    for (int a = 0; a < 3; ++a) {
      pos[6 * k + a] = r.a[a];
      pos[6 * k + 3 + a] = r.b[a];
    }
    force->SetTypedTuple(k, r.force);
    tangential->SetTypedTuple(k, r.tangential);
    normal->SetValue(k, r.normal_force);
    overlap->SetValue(k, r.overlap);
    id_i->SetValue(k, r.id_i);
    id_j->SetValue(k, r.id_j);
    subdomain->SetValue(k, r.subdomain);
    wall->SetValue(k, r.wall);
    sliding->SetValue(k, r.sliding);
    offsets->SetValue(k, 2 * k);
    connectivity->SetValue(2 * k, 2 * k);
    connectivity->SetValue(2 * k + 1, 2 * k + 1);
  }
  offsets->SetValue(n, 2 * n);
  vtkNew<vtkCellArray> lines;
  lines->SetData(offsets, connectivity);

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetLines(lines);
  vtkCellData* cd = poly->GetCellData();
  cd->AddArray(force);
  cd->AddArray(tangential);
  cd->AddArray(normal);
  cd->AddArray(overlap);
  cd->AddArray(id_i);
  cd->AddArray(id_j);
  cd->AddArray(subdomain);
  cd->AddArray(wall);
  cd->AddArray(sliding);

  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(poly);
  return frames_.write(*writer, time);
}

}  // namespace domel::platform::io
