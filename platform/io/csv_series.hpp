// SPDX-License-Identifier: MIT
// A CSV time series (energies, forces on walls, timings ...) that a plotting
// script can read at any moment during a run: the header is written with the
// first flush (atomically, so the file never exists without it), later rows
// are appended in whole lines, one write per flush, so a long run costs
// O(rows) and never rewrites what is on disk. Numbers are written in the
// shortest form that reads back to the identical double (std::to_chars), so
// nothing is lost and rows stay short.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace domel::platform::io {

/// A CSV time series (header line + one row per append): rows are buffered
/// and appended to the file by flush(), which append() calls automatically
/// when at least `flush_every` rows are pending; the destructor flushes and
/// never throws (a failure there is swallowed silently). The parent
/// directory of `path` must exist when the file is first flushed. Column
/// names containing ',', '"' or a line break are quoted as in RFC 4180.
class CsvSeries {
 public:
  /// Throws std::invalid_argument if `columns` is empty. Touches no file.
  CsvSeries(std::filesystem::path path, std::vector<std::string> columns,
            std::size_t flush_every = 50);

  CsvSeries(const CsvSeries&) = delete;
  CsvSeries& operator=(const CsvSeries&) = delete;
  /// The moved-from series no longer writes anything.
  CsvSeries(CsvSeries&& other) noexcept;
  CsvSeries& operator=(CsvSeries&&) = delete;

  /// Throws std::invalid_argument if row.size() != columns.size(); the row
  /// is not recorded then. May throw RuntimeError from an automatic flush.
  void append(const std::vector<double>& row);

  /// Put every pending row in the file (the first flush creates it with its
  /// header, even when no row is pending). Throws RuntimeError if it cannot
  /// be written; the rows stay pending and the next flush tries again.
  void flush();

  /// Bytes in the file after the last flush (checkpoints).
  std::size_t size() const { return written_; }
  /// Continue the series in `path` written by an earlier run (a restart):
  /// its first `bytes` bytes are kept, from the header on, and later rows
  /// cut off. Throws RuntimeError when the file is missing, shorter, or has
  /// another header.
  void resume(std::size_t bytes);

  /// Flushes if anything was never written (including a header-only file
  /// when no row was ever appended); never throws.
  ~CsvSeries();

 private:
  std::filesystem::path path_;
  std::size_t columns_;
  std::size_t flush_every_;
  std::string header_;         ///< the header line
  std::string pending_text_;   ///< rows appended since the last successful flush
  std::size_t pending_ = 0;    ///< their count
  std::size_t written_ = 0;    ///< bytes in the file
  bool created_ = false;       ///< the file exists with its header
  bool active_ = true;         ///< false once moved from
};

}  // namespace domel::platform::io
