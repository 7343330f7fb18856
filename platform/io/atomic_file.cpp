// SPDX-License-Identifier: MIT
// write_file_atomically(): temporary file in the target's directory, checked
// write and close, then rename over the target. Uses stdio rather than
// iostreams so that failures carry an errno reason into the error message.
#include "io/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <system_error>

#include <unistd.h>

#include "core/error.hpp"
#include "io/output_folder.hpp"

namespace domel::platform::io {

namespace fs = std::filesystem;

namespace {

std::string reason(int err) { return disk_full_reason(err); }

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw RuntimeError("cannot write file '" + path.string() + "': " + what);
}

void remove_quietly(const fs::path& p) {
  std::error_code ignored;
  fs::remove(p, ignored);
}

fs::path temporary_path_for(const fs::path& path) {
  fs::path tmp = path;
  tmp += ".tmp-" + std::to_string(static_cast<long long>(::getpid()));
  return tmp;
}

}  // namespace

std::string disk_full_reason(int err) {
  const std::string text = std::error_code(err, std::generic_category()).message();
  if (err == ENOSPC) return text + " (the disk is full)";
  if (err == EFBIG) return text + " (the file size limit, ulimit -f, was reached)";
  return text;
}

void write_file_atomically(const fs::path& path, const std::string& contents) {
  if (path.empty() || !path.has_filename()) fail(path, "not a file path");
  record_output(path);
  const fs::path tmp = temporary_path_for(path);

  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) {
    const int err = errno;
    fail(path, "cannot create temporary file '" + tmp.string() + "': " + reason(err));
  }
  const std::size_t written =
      contents.empty() ? 0 : std::fwrite(contents.data(), 1, contents.size(), f);
  int err = 0;
  if (written != contents.size()) err = errno ? errno : EIO;
  if (std::fflush(f) != 0 && err == 0) err = errno ? errno : EIO;
  if (std::fclose(f) != 0 && err == 0) err = errno ? errno : EIO;
  if (err != 0) {
    remove_quietly(tmp);
    fail(path, "writing temporary file '" + tmp.string() + "' failed: " + reason(err));
  }

  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    remove_quietly(tmp);
    fail(path, "cannot rename '" + tmp.string() + "' onto it: " + ec.message());
  }
}

}  // namespace domel::platform::io
