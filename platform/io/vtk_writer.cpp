// SPDX-License-Identifier: MIT
// VtkSeriesWriter: builds a vtkPolyData of vertices from the particle stores
// and writes it as the next frame of a VtkFrames series (vtkXMLPolyDataWriter,
// appended raw binary, zlib; temporary name then rename; .pvd rewritten).
#include "io/vtk_writer.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cstdio>
#include <cstdint>
#include <stdexcept>
#include <system_error>

#include <unistd.h>

#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkFieldData.h>
#include <vtkStringArray.h>
#include <vtkTypeUInt64Array.h>
#include <vtkXMLPolyDataWriter.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace domel::platform::io {

namespace fs = std::filesystem;

namespace {

void check_store(const ParticleSet& set) {
  if (set.store == nullptr) {
    throw std::invalid_argument("VtkSeriesWriter::write: null particle store for subdomain " +
                                std::to_string(set.subdomain));
  }
  const ParticleStore& s = *set.store;
  const std::size_t n = s.size();
  const bool consistent = s.x.size() == n && s.y.size() == n && s.z.size() == n &&
                          s.vx.size() == n && s.vy.size() == n && s.vz.size() == n &&
                          s.wx.size() == n && s.wy.size() == n && s.wz.size() == n &&
                          s.fx.size() == n && s.fy.size() == n && s.fz.size() == n && s.tx.size() == n &&
                          s.ty.size() == n && s.tz.size() == n && s.radius.size() == n && s.mass.size() == n &&
                          s.contacts.size() == n && s.material.size() == n;
  if (!consistent) {
    throw RuntimeError("VtkSeriesWriter::write: particle store of subdomain " +
                       std::to_string(set.subdomain) + " has arrays of different lengths");
  }
}

vtkNew<vtkDoubleArray> vector_array(const char* name, vtkIdType n) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(3);
  a->SetNumberOfTuples(n);
  return a;
}

}  // namespace

VtkSeriesWriter::VtkSeriesWriter(fs::path directory, std::string basename)
    : directory_(directory), basename_(basename), frames_(std::move(directory), std::move(basename), "vtp") {
  if (basename_.empty() || basename_.find('/') != std::string::npos) {
    throw std::invalid_argument("VtkSeriesWriter: basename must be a non-empty file name, got '" +
                                basename_ + "'");
  }
}

fs::path VtkSeriesWriter::write(double time, const std::vector<ParticleSet>& sets) {
  std::size_t total = 0;
  for (const ParticleSet& set : sets) {
    check_store(set);
    total += set.store->size();
  }
  const auto n = static_cast<vtkIdType>(total);

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  auto velocity = vector_array("velocity", n);
  auto angular_velocity = vector_array("angular_velocity", n);
  auto force = vector_array("force", n);
  auto torque = vector_array("torque", n);
  vtkNew<vtkDoubleArray> radius;
  radius->SetName("radius");
  radius->SetNumberOfTuples(n);
  vtkNew<vtkDoubleArray> mass;
  mass->SetName("mass");
  mass->SetNumberOfTuples(n);
  vtkNew<vtkTypeUInt64Array> id;
  id->SetName("id");
  id->SetNumberOfTuples(n);
  vtkNew<vtkIntArray> subdomain;
  subdomain->SetName("subdomain");
  subdomain->SetNumberOfTuples(n);
  vtkNew<vtkIntArray> material;
  material->SetName("material");
  material->SetNumberOfTuples(n);
  vtkNew<vtkIntArray> contacts;
  contacts->SetName("contacts");
  contacts->SetNumberOfTuples(n);
  vtkNew<vtkIdTypeArray> connectivity;  // vertex k uses point k
  connectivity->SetNumberOfTuples(n);

  // Fill through the raw AOS pointers: every array was sized above.
  auto* pos = static_cast<double*>(points->GetData()->GetVoidPointer(0));
  double* vel = velocity->GetPointer(0);
  double* ang = angular_velocity->GetPointer(0);
  double* frc = force->GetPointer(0);
  double* trq = torque->GetPointer(0);
  double* rad = radius->GetPointer(0);
  double* mas = mass->GetPointer(0);
  auto* ids = static_cast<std::uint64_t*>(id->GetVoidPointer(0));
  int* sub = subdomain->GetPointer(0);
  int* mat = material->GetPointer(0);
  int* con = contacts->GetPointer(0);
  vtkIdType* conn = connectivity->GetPointer(0);

  std::size_t k = 0;
  for (const ParticleSet& set : sets) {
    const ParticleStore& s = *set.store;
    for (std::size_t i = 0; i < s.size(); ++i, ++k) {
      pos[3 * k] = s.x[i]; pos[3 * k + 1] = s.y[i]; pos[3 * k + 2] = s.z[i];
      vel[3 * k] = s.vx[i]; vel[3 * k + 1] = s.vy[i]; vel[3 * k + 2] = s.vz[i];
      ang[3 * k] = s.wx[i]; ang[3 * k + 1] = s.wy[i]; ang[3 * k + 2] = s.wz[i];
      frc[3 * k] = s.fx[i]; frc[3 * k + 1] = s.fy[i]; frc[3 * k + 2] = s.fz[i];
      trq[3 * k] = s.tx[i]; trq[3 * k + 1] = s.ty[i]; trq[3 * k + 2] = s.tz[i];
      rad[k] = s.radius[i];
      mas[k] = s.mass[i];
      ids[k] = s.id[i];
      sub[k] = set.subdomain;
      mat[k] = set.materials ? static_cast<int>((*set.materials)[s.material[i]]) : 0;
      // Int32 is what ParaView filters handle best; a count never gets near INT_MAX.
      con[k] = static_cast<int>(std::min<std::uint32_t>(s.contacts[i], INT_MAX));
      conn[k] = static_cast<vtkIdType>(k);
    }
  }

  vtkNew<vtkCellArray> verts;
  verts->SetData(1, connectivity);  // one point per cell: VTK_VERTEX

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetVerts(verts);
  vtkPointData* pd = poly->GetPointData();
  pd->AddArray(velocity);
  pd->AddArray(angular_velocity);
  pd->AddArray(force);
  pd->AddArray(torque);
  pd->AddArray(radius);
  pd->AddArray(mass);
  pd->AddArray(id);
  pd->AddArray(subdomain);
  pd->AddArray(material);
  if (!material_names_.empty()) {
    vtkNew<vtkStringArray> names;
    names->SetName("material_names");
    names->SetNumberOfValues(static_cast<vtkIdType>(material_names_.size()));
    for (std::size_t m = 0; m < material_names_.size(); ++m)
      names->SetValue(static_cast<vtkIdType>(m), material_names_[m]);
    poly->GetFieldData()->AddArray(names);
  }
  pd->AddArray(contacts);

  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(poly);
  return frames_.write(*writer, time);
}

}  // namespace domel::platform::io
