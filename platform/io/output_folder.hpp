// SPDX-License-Identifier: MIT
// What a run's output folder holds and how a new run treats an old one
// (docs/checkpoint.md, "Output folders"): every file domel writes is listed
// in <folder>/domel_manifest.txt the moment it is first written (before its
// contents land, so that a killed run leaves no file unlisted), and a new run
// into a folder that holds an earlier run's output is refused unless asked to
// overwrite it, which removes exactly the listed files; a restart continues
// the folder and its manifest.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace domel::platform::io {

inline constexpr const char* kManifestFile = "domel_manifest.txt";

/// Record that `file` is being written. When a manifest is open (below) and
/// `file` lies in its folder, the file's relative name is appended to the
/// manifest once. Called by write_file_atomically() and VtkFrames; cheap for
/// files already listed. Thread-safe.
void record_output(const std::filesystem::path& file);

/// Keeps <folder>/domel_manifest.txt open for a run: files already listed
/// there (a restart, or an overwrite that cleaned the folder) stay listed.
/// One at a time per process; the destructor closes it. Throws RuntimeError
/// when the manifest cannot be written.
class ManifestScope {
 public:
  explicit ManifestScope(const std::filesystem::path& folder);
  ~ManifestScope();
  ManifestScope(const ManifestScope&) = delete;
  ManifestScope& operator=(const ManifestScope&) = delete;
};

/// The files a manifest lists (relative to its folder), in the order written.
/// Empty when there is no manifest.
std::vector<std::string> manifest_entries(const std::filesystem::path& folder);

enum class OutputPolicy {
  fresh,      ///< refuse a folder that holds an earlier run's output
  overwrite,  ///< remove the files an earlier run listed, then write
  restart,    ///< continue the folder (checkpoint restart)
};

/// Before a run writes into `folder`: with `fresh`, throws ConfigError when
/// it holds an earlier run's output (a manifest, or files with the names a
/// run writes); with `overwrite`, removes every file the manifest lists (and
/// the manifest) or, for a folder written by a domel older than the manifest,
/// the fixed names, the files its summary.json lists under "outputs" and the
/// frames of those .pvd collections; with `restart`, keeps them. With
/// `overwrite` and `restart`, first removes the temporary files
/// (`NAME.tmp-PID`) that a process killed while writing a listed file left.
void prepare_output_folder(const std::filesystem::path& folder, OutputPolicy policy);

}  // namespace domel::platform::io
