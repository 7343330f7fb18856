// SPDX-License-Identifier: MIT
// ParaView frame series and .pvd collection (see vtk_frames.hpp).
#include "io/vtk_frames.hpp"

#include "io/output_folder.hpp"

#include "core/error.hpp"
#include "io/atomic_file.hpp"

#include <vtkErrorCode.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkStringOutputWindow.h>
#include <vtkXMLWriter.h>

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <system_error>

namespace domel::platform::io {

namespace fs = std::filesystem;

namespace {

/// Shortest text that reads back as the same double (locale independent).
std::string format_double(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

/// Escape the characters that may not appear verbatim in an XML attribute.
std::string xml_attribute(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// Why a VTK writer failed, in the user's words (its error code is an errno
/// below vtkErrorCode::FirstVTKErrorCode, else VTK's own).
std::string vtk_reason(unsigned long code) {
  if (code == vtkErrorCode::OutOfDiskSpaceError)  // VTK's name for any failed write of its stream
    return "the disk is full or the file size limit (ulimit -f) was reached";
  if (code > 0 && code < vtkErrorCode::FirstVTKErrorCode) return disk_full_reason(static_cast<int>(code));
  if (code == vtkErrorCode::NoError) return "the writer failed";
  const char* name = vtkErrorCode::GetStringFromErrorCode(code);
  return std::string("VTK's ") + (name ? name : "unknown error");
}

/// Runs the writer with VTK's own report of a failure silenced (a dozen
/// lines from its pipeline on stderr; the caller reports it in one line);
/// returns Write()'s result.
int quietly(vtkXMLWriter& writer) {
  const vtkLogger::Verbosity before = vtkLogger::GetCurrentVerbosityCutoff();
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  vtkSmartPointer<vtkOutputWindow> previous = vtkOutputWindow::GetInstance();
  vtkNew<vtkStringOutputWindow> capture;
  vtkOutputWindow::SetInstance(capture);
  const int ok = writer.Write();
  vtkOutputWindow::SetInstance(previous);
  vtkLogger::SetStderrVerbosity(before);
  return ok;
}

}  // namespace

VtkFrames::VtkFrames(fs::path directory, std::string basename, std::string extension)
    : directory_(std::move(directory)), basename_(std::move(basename)), extension_(std::move(extension)) {}

std::string VtkFrames::frame_name(std::size_t k) const {
  char index[32];
  std::snprintf(index, sizeof index, "%06zu", k);
  return basename_ + "_" + index + "." + extension_;
}

std::vector<double> VtkFrames::times() const {
  std::vector<double> t;
  for (const Frame& f : frames_) t.push_back(f.time);
  return t;
}

void VtkFrames::resume(const std::vector<double>& times) {
  frames_.clear();
  for (std::size_t k = 0; k < times.size(); ++k) frames_.push_back(Frame{times[k], frame_name(k)});
  std::error_code ec;
  for (std::size_t k = times.size();; ++k) {
    if (!fs::remove(directory_ / frame_name(k), ec)) break;
  }
  write_collection();
}

fs::path VtkFrames::write(vtkXMLWriter& writer, double time) {
  std::error_code ec;
  fs::create_directories(directory_, ec);
  if (ec) throw RuntimeError("cannot create output directory '" + directory_.string() + "': " + ec.message());
  const std::string file = frame_name(frames_.size());
  const fs::path target = directory_ / file;
  record_output(target);
  fs::path tmp = target;
  tmp += ".tmp-" + std::to_string(static_cast<long long>(::getpid()));

  writer.SetFileName(tmp.c_str());
  writer.SetDataModeToAppended();
  writer.EncodeAppendedDataOff();  // raw binary, not base64
  writer.SetCompressorTypeToZLib();
  writer.SetHeaderTypeToUInt64();
  const int ok = quietly(writer);
  if (ok != 1 || writer.GetErrorCode() != 0) {
    fs::remove(tmp, ec);
    throw RuntimeError("cannot write file '" + target.string() + "': " + vtk_reason(writer.GetErrorCode()));
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(tmp, ec);
    throw RuntimeError("cannot write file '" + target.string() + "': cannot rename '" + tmp.string() +
                       "' onto it: " + why);
  }
  frames_.push_back(Frame{time, file});
  write_collection();
  return target;
}

void VtkFrames::write_collection() const {
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\">\n"
      "  <Collection>\n";
  for (const Frame& f : frames_)
    xml += "    <DataSet timestep=\"" + format_double(f.time) + "\" group=\"\" part=\"0\" file=\"" +
           xml_attribute(f.file) + "\"/>\n";
  xml +=
      "  </Collection>\n"
      "</VTKFile>\n";
  write_file_atomically(directory_ / (basename_ + ".pvd"), xml);
}

}  // namespace domel::platform::io
