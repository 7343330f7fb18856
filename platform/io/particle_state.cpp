// SPDX-License-Identifier: MIT
#include "io/particle_state.hpp"

#include "io/atomic_file.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace domel::platform::io {

namespace {

constexpr const char* kHeader = "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed";
constexpr const char* kHeaderV2 = "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed,material";
constexpr int kColumns = 12;
constexpr const char* kColumnNames[kColumns] = {"id", "x", "y", "z", "radius", "vx", "vy", "vz", "wx", "wy", "wz",
                                                "fixed"};

std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r')) --b;
  return s.substr(a, b - a);
}

[[noreturn]] void fail(const std::filesystem::path& file, std::size_t line, const std::string& what,
                       const std::string& found) {
  std::string f = found.size() > 80 ? found.substr(0, 77) + "..." : found;
  for (char& c : f)  // a binary file's bytes would garble the terminal
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  throw std::runtime_error(file.string() + ":" + std::to_string(line) + ": " + what + ", found '" + f + "'");
}

}  // namespace

std::string format_particle_state(const ParticleStore& st, const std::string& subdomain, double time,
                                  double coarse_grain, const std::vector<std::string>& materials) {
  const bool v2 = materials.size() > 1;
  std::string s;
  s.reserve(64 + st.size() * 230);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "# domel particle state v%d: subdomain '%s', %zu particles, t = %.17g s, coarse_grain %.17g\n"
                "# SI units; radius is the parcel radius (coarse grain applied); contact history is not stored\n",
                v2 ? 2 : 1, subdomain.c_str(), st.size(), time, coarse_grain);
  s += buf;
  s += v2 ? kHeaderV2 : kHeader;
  s += '\n';
  for (std::size_t k = 0; k < st.size(); ++k) {
    const int n = std::snprintf(buf, sizeof buf,
                                "%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d\n",
                                static_cast<unsigned long long>(st.id[k]), st.x[k], st.y[k], st.z[k], st.radius[k],
                                st.vx[k], st.vy[k], st.vz[k], st.wx[k], st.wy[k], st.wz[k], st.fixed(k) ? 1 : 0);
    s.append(buf, static_cast<std::size_t>(n));
    if (v2) {  // the material's name replaces the newline's place
      s.back() = ',';
      s += materials.at(st.material[k]);
      s += '\n';
    }
  }
  return s;
}

void write_particle_state(const std::filesystem::path& path, const ParticleStore& store,
                          const std::string& subdomain, double time, double coarse_grain,
                          const std::vector<std::string>& materials) {
  write_file_atomically(path, format_particle_state(store, subdomain, time, coarse_grain, materials));
}

namespace {
/// A folder opens as a stream on Linux and fails only when read, with an
/// error of the C++ library that names no file: refuse it by name first.
void refuse_folder(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw std::runtime_error(path.string() + ": is a folder, not a particle state file");
}
}  // namespace

std::size_t count_lines(const std::filesystem::path& path) {
  refuse_folder(path);
  std::ifstream in(path, std::ios::binary);
  std::size_t lines = 0;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    const auto got = static_cast<std::size_t>(in.gcount());
    for (std::size_t k = 0; k < got; ++k) lines += buf[k] == '\n' ? 1 : 0;
  }
  return lines + 1;  // a last line without a newline
}

std::vector<ParticleStateRow> read_particle_state(const std::filesystem::path& path) {
  std::vector<ParticleStateRow> rows;
  for_each_particle_state_row(path, [&rows](const ParticleStateRow& p) { rows.push_back(p); });
  return rows;
}

std::size_t for_each_particle_state_row(const std::filesystem::path& path,
                                        const std::function<void(const ParticleStateRow&)>& visit) {
  refuse_folder(path);
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open the particle state file");
  std::size_t rows = 0;
  std::string raw;
  std::size_t line = 0;
  bool header = false, v2 = false;
  while (std::getline(in, raw)) {
    ++line;
    std::string text = trim(raw);
    if (text.empty() || text[0] == '#') continue;
    if (!header) {
      if (text != kHeader && text != kHeaderV2)
        fail(path, line, std::string("expected the header '") + kHeader + "' (or '" + kHeaderV2 + "')", text);
      header = true;
      v2 = text == kHeaderV2;
      continue;
    }
    std::string material;
    if (v2) {  // the last column is a name
      const std::size_t comma = text.rfind(',');
      material = comma == std::string::npos ? std::string() : trim(text.substr(comma + 1));
      if (material.empty()) fail(path, line, "expected a material name in column 13", text);
      text.resize(comma);
    }
    double v[kColumns];
    int col = 0;
    std::size_t pos = 0;
    while (true) {
      const std::size_t comma = text.find(',', pos);
      const std::string field = trim(text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
      if (col >= kColumns)
        fail(path, line, "expected " + std::to_string(kColumns) + " comma-separated columns", text);
      const char* b = field.data();
      const char* e = b + field.size();
      const auto r = std::from_chars(b, e, v[col]);
      if (field.empty() || r.ec != std::errc() || r.ptr != e || !std::isfinite(v[col]))
        fail(path, line, std::string("expected a finite number in column ") + std::to_string(col + 1) + " (" +
                             kColumnNames[col] + ")", field);
      ++col;
      if (comma == std::string::npos) break;
      pos = comma + 1;
    }
    if (col != kColumns)
      fail(path, line, "expected " + std::to_string(kColumns) + " comma-separated columns, " + std::to_string(col) +
                           " given", text);
    ParticleStateRow p;
    if (!(v[0] >= 0) || v[0] != std::floor(v[0])) fail(path, line, "expected an integer id >= 0", text);
    p.id = static_cast<std::uint64_t>(v[0]);
    p.x = v[1]; p.y = v[2]; p.z = v[3]; p.radius = v[4];
    p.vx = v[5]; p.vy = v[6]; p.vz = v[7]; p.wx = v[8]; p.wy = v[9]; p.wz = v[10];
    if (!(p.radius > 0)) fail(path, line, "expected a radius > 0 in column 5", text);
    if (v[11] != 0 && v[11] != 1) fail(path, line, "expected fixed = 0 or 1 in column 12", text);
    p.fixed = v[11] == 1;
    p.material = std::move(material);
    visit(p);
    ++rows;
  }
  if (in.bad()) throw std::runtime_error(path.string() + ": read error");
  if (!header) fail(path, line, std::string("expected the header '") + kHeader + "'", "end of file");
  return rows;
}

}  // namespace domel::platform::io
