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

namespace {
/// A cell array of n tuples of `components`, named.
template <class Array>
vtkNew<Array> named(const char* name, vtkIdType n, int components = 1) {
  vtkNew<Array> a;
  a->SetName(name);
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(n);
  return a;
}
}  // namespace

ContactSeriesWriter::ContactSeriesWriter(fs::path directory, std::string basename)
    : frames_(std::move(directory), std::move(basename), "vtp") {}

fs::path ContactSeriesWriter::write(double time, const std::vector<ContactRow>& rows) {
  const auto n = static_cast<vtkIdType>(rows.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(2 * n);
  auto force = named<vtkDoubleArray>("force", n, 3);
  auto tangential = named<vtkDoubleArray>("tangential_force", n, 3);
  auto normal = named<vtkDoubleArray>("normal_force", n);
  auto overlap = named<vtkDoubleArray>("overlap", n);
  auto id_i = named<vtkTypeUInt64Array>("id_i", n);
  auto id_j = named<vtkTypeUInt64Array>("id_j", n);
  auto subdomain = named<vtkIntArray>("subdomain", n);
  auto wall = named<vtkIntArray>("wall", n);
  auto sliding = named<vtkIntArray>("sliding", n);
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
