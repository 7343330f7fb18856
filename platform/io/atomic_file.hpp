// SPDX-License-Identifier: MIT
// Whole-file writes for output that other programs may read while a run is
// still going (ParaView, a plotting script tailing a CSV): the contents go to a
// temporary file next to the target, which is then renamed over it, so a
// reader sees either the previous complete file or the new complete file,
// never a partly written one.
#pragma once

#include <filesystem>
#include <string>

namespace domel::platform::io {

/// Write `contents` to `path` so that readers only ever see the whole file:
/// write to "<path>.tmp-<pid>" in the same directory, flush/close, then
/// std::filesystem::rename. Throws RuntimeError naming the path on failure
/// (and removes the temp file). The parent directory must already exist.
/// Not meant for two threads of one process writing the same path at once
/// (they would share the temporary name).
void write_file_atomically(const std::filesystem::path& path, const std::string& contents);

/// The reason for a failed write (errno `err`) in the user's words: a full
/// disk (ENOSPC) and a file size limit (EFBIG: ulimit -f, a batch system's
/// quota) say so.
std::string disk_full_reason(int err);

}  // namespace domel::platform::io
