// SPDX-License-Identifier: MIT
// The manifest of a run's output folder and the policy for an old one
// (output_folder.hpp).
#include "io/output_folder.hpp"

#include "core/error.hpp"
#include "io/atomic_file.hpp"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

namespace domel::platform::io {

namespace fs = std::filesystem;

namespace {

struct Manifest {
  std::mutex mutex;
  bool open = false;
  fs::path folder;  ///< absolute, lexically normal
  fs::path file;
  std::set<std::string> listed;
};

Manifest& manifest() {
  static Manifest m;
  return m;
}

fs::path normal(const fs::path& p) {
  std::error_code ec;
  const fs::path a = fs::absolute(p, ec);
  return (ec ? p : a).lexically_normal();
}

void append_line(const fs::path& file, const std::string& line) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw RuntimeError("cannot write file '" + file.string() + "': " + std::strerror(errno));
  const std::string text = line + "\n";
  const ssize_t n = ::write(fd, text.data(), text.size());
  const int err = errno;
  ::close(fd);
  if (n != static_cast<ssize_t>(text.size()))
    throw RuntimeError("cannot write file '" + file.string() + "': " + disk_full_reason(err ? err : EIO));
}

/// A manifest line that names a file inside the folder (no absolute path,
/// no "..": a hand-edited manifest must not make --overwrite remove files
/// elsewhere).
bool safe_entry(const std::string& e) {
  if (e.empty() || e[0] == '#') return false;
  const fs::path p(e);
  if (p.is_absolute()) return false;
  for (const auto& part : p)
    if (part == "..") return false;
  return true;
}

/// Files with the fixed names a run writes (an older domel wrote no manifest).
std::vector<std::string> known_outputs(const fs::path& folder) {
  std::vector<std::string> found;
  for (const char* f : {"summary.json", "probes.csv", "particles.pvd", "checkpoint.ckpt"})
    if (fs::exists(folder / f)) found.push_back(f);
  return found;
}

/// The files a run of a domel older than the manifest left: the fixed names,
/// every file its summary.json lists under "outputs", and the frames each of
/// those .pvd collections lists (their file="..." attributes).
std::vector<std::string> legacy_outputs(const fs::path& folder) {
  std::set<std::string> files;
  for (const auto& f : known_outputs(folder)) files.insert(f);
  std::ifstream in(folder / "summary.json");
  if (in) {
    try {
      const nlohmann::json s = nlohmann::json::parse(in);
      std::vector<const nlohmann::json*> todo = {&s["outputs"]};
      while (!todo.empty()) {
        const nlohmann::json* j = todo.back();
        todo.pop_back();
        if (j->is_string() && safe_entry(j->get<std::string>())) files.insert(j->get<std::string>());
        if (j->is_structured())
          for (const auto& v : *j) todo.push_back(&v);
      }
    } catch (const nlohmann::json::exception&) {
      // not a summary of ours: only the fixed names
    }
  }
  std::vector<std::string> frames;
  for (const auto& f : files) {
    if (fs::path(f).extension() != ".pvd") continue;
    std::ifstream pvd(folder / f);
    const std::string text((std::istreambuf_iterator<char>(pvd)), std::istreambuf_iterator<char>());
    const fs::path dir = fs::path(f).parent_path();
    for (std::size_t at = text.find("file=\""); at != std::string::npos; at = text.find("file=\"", at + 1)) {
      const std::size_t end = text.find('"', at + 6);
      if (end == std::string::npos) break;
      const std::string frame = (dir / text.substr(at + 6, end - at - 6)).string();
      if (safe_entry(frame)) frames.push_back(frame);
    }
  }
  files.insert(frames.begin(), frames.end());
  return {files.begin(), files.end()};
}

std::string some(const std::vector<std::string>& files) {
  std::string s;
  for (std::size_t k = 0; k < files.size() && k < 4; ++k) s += (k ? ", " : "") + files[k];
  if (files.size() > 4) s += ", ... (" + std::to_string(files.size()) + " files)";
  return s;
}

}  // namespace

void record_output(const fs::path& file) {
  Manifest& m = manifest();
  std::lock_guard<std::mutex> lock(m.mutex);
  if (!m.open) return;
  const fs::path f = normal(file);
  const fs::path rel = f.lexically_relative(m.folder);
  if (rel.empty() || !safe_entry(rel.string())) return;  // not in the folder
  if (!m.listed.insert(rel.string()).second) return;
  append_line(m.file, rel.string());
}

ManifestScope::ManifestScope(const fs::path& folder) {
  Manifest& m = manifest();
  std::lock_guard<std::mutex> lock(m.mutex);
  m.folder = normal(folder);
  m.file = m.folder / kManifestFile;
  m.listed.clear();
  for (const auto& e : manifest_entries(m.folder)) m.listed.insert(e);
  if (!fs::exists(m.file))
    append_line(m.file, "# files written by domel into this folder; `domel run --overwrite` removes exactly these");
  m.listed.insert(kManifestFile);
  m.open = true;
}

ManifestScope::~ManifestScope() {
  Manifest& m = manifest();
  std::lock_guard<std::mutex> lock(m.mutex);
  m.open = false;
  m.listed.clear();
}

std::vector<std::string> manifest_entries(const fs::path& folder) {
  std::vector<std::string> entries;
  std::ifstream in(folder / kManifestFile);
  std::string line;
  while (std::getline(in, line))
    if (safe_entry(line)) entries.push_back(line);
  return entries;
}

namespace {

/// The temporary files a process killed in the middle of writing left
/// (`NAME.tmp-PID`, io/atomic_file.hpp and io/vtk_frames.hpp) for the files
/// the manifest lists, the writing process gone. Returns how many.
std::size_t remove_orphaned_temporaries(const fs::path& folder, const std::vector<std::string>& listed) {
  std::set<fs::path> dirs;
  for (const auto& e : listed) dirs.insert((folder / e).parent_path());
  const std::set<std::string> names(listed.begin(), listed.end());
  std::size_t removed = 0;
  for (const auto& dir : dirs) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string file = it->path().filename().string();
      const std::size_t at = file.rfind(".tmp-");
      if (at == std::string::npos || at + 5 == file.size() ||
          file.find_first_not_of("0123456789", at + 5) != std::string::npos)
        continue;
      const fs::path target = it->path().parent_path() / file.substr(0, at);
      if (!names.count(target.lexically_relative(folder).string())) continue;
      const long pid = std::stol(file.substr(at + 5));
      if (pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH)) continue;  // still writing
      std::error_code rm;
      if (fs::remove(it->path(), rm)) ++removed;
    }
  }
  return removed;
}

}  // namespace

void prepare_output_folder(const fs::path& folder, OutputPolicy policy) {
  if (!fs::is_directory(folder)) return;
  const bool has_manifest = fs::exists(folder / kManifestFile);
  const std::vector<std::string> listed = manifest_entries(folder);
  if (policy != OutputPolicy::fresh) remove_orphaned_temporaries(folder, listed);
  if (policy == OutputPolicy::restart) return;
  const std::vector<std::string> known = known_outputs(folder);
  if (!has_manifest && known.empty()) return;  // nothing of a run's there
  auto refuse = [&](const std::string& what) {
    throw ConfigError({Diagnostic{folder.string(), "", what, ""}});
  };
  if (policy == OutputPolicy::fresh)
    refuse("the output folder holds an earlier run's output (" + some(has_manifest ? listed : known) +
           "); pass --overwrite to replace it (only the files that run wrote are removed) or choose another "
           "folder with --out");
  // without a manifest (a domel older than it): what that run's summary and
  // ParaView collections name
  for (const auto& e : has_manifest ? listed : legacy_outputs(folder)) {
    std::error_code ec;
    const fs::path p = folder / e;
    if (fs::is_regular_file(fs::symlink_status(p, ec))) fs::remove(p, ec);
  }
  std::error_code ec;
  fs::remove(folder / kManifestFile, ec);
}

}  // namespace domel::platform::io
