// SPDX-License-Identifier: MIT
// CsvSeries: header built once, rows formatted with std::to_chars (shortest
// round-trippable, locale independent); the first flush writes the header
// with write_file_atomically(), later ones append whole rows with one
// write(2) on a descriptor opened with O_APPEND.
#include "io/csv_series.hpp"

#include <charconv>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace domel::platform::io {

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

/// Append `text` to `path` in one write (whole rows; the kernel may split a
/// very large write, which a reader can only see as a late last row).
void append_to(const std::filesystem::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd < 0) throw RuntimeError("cannot append to '" + path.string() + "': " + std::strerror(errno));
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = disk_full_reason(errno);
      ::close(fd);
      // the part written stays; cut it off so that the file ends with a whole row
      std::error_code ec;
      std::filesystem::resize_file(path, std::filesystem::file_size(path, ec) - done, ec);
      throw RuntimeError("cannot append to '" + path.string() + "': " + why);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) throw RuntimeError("cannot append to '" + path.string() + "': " + std::strerror(errno));
}

}  // namespace

CsvSeries::CsvSeries(std::filesystem::path path, std::vector<std::string> columns,
                     std::size_t flush_every)
    : path_(std::move(path)), columns_(columns.size()), flush_every_(flush_every) {
  if (columns.empty()) throw std::invalid_argument("CsvSeries: no columns for '" + path_.string() + "'");
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (c > 0) header_ += ',';
    header_ += csv_field(columns[c]);
  }
  header_ += '\n';
}

CsvSeries::CsvSeries(CsvSeries&& other) noexcept
    : path_(std::move(other.path_)),
      columns_(other.columns_),
      flush_every_(other.flush_every_),
      header_(std::move(other.header_)),
      pending_text_(std::move(other.pending_text_)),
      pending_(std::exchange(other.pending_, 0)),
      written_(other.written_),
      created_(other.created_),
      active_(std::exchange(other.active_, false)) {}

void CsvSeries::append(const std::vector<double>& row) {
  if (row.size() != columns_) {
    throw std::invalid_argument("CsvSeries '" + path_.string() + "': row has " +
                                std::to_string(row.size()) + " values, expected " +
                                std::to_string(columns_));
  }
  // Shortest text that reads back to the identical double (std::to_chars):
  // exact and compact, unlike "%.10g", which loses digits; inf/nan come out
  // as "inf"/"nan", which numpy and pandas read.
  char buf[64];
  for (std::size_t c = 0; c < row.size(); ++c) {
    if (c > 0) pending_text_ += ',';
    const auto res = std::to_chars(buf, buf + sizeof buf, row[c]);
    pending_text_.append(buf, res.ptr);
  }
  pending_text_ += '\n';
  ++pending_;
  if (pending_ >= flush_every_) flush();
}

void CsvSeries::flush() {
  if (!active_) return;
  if (!created_) {
    write_file_atomically(path_, header_ + pending_text_);
    created_ = true;
    written_ = header_.size() + pending_text_.size();
  } else if (!pending_text_.empty()) {
    append_to(path_, pending_text_);
    written_ += pending_text_.size();
  }
  pending_text_.clear();
  pending_ = 0;
}

void CsvSeries::resume(std::size_t bytes) {
  std::ifstream in(path_, std::ios::binary);
  if (!in) throw RuntimeError("cannot continue '" + path_.string() + "': it cannot be read");
  std::string head(header_.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  if (!in || head != header_)
    throw RuntimeError("cannot continue '" + path_.string() + "': its header is not this run's (" +
                       std::to_string(columns_) + " columns)");
  std::error_code ec;
  const auto size = std::filesystem::file_size(path_, ec);
  if (ec || size < bytes)
    throw RuntimeError("cannot continue '" + path_.string() + "': it holds " + std::to_string(size) +
                       " bytes, fewer than the " + std::to_string(bytes) + " it had at the checkpoint");
  std::filesystem::resize_file(path_, bytes, ec);
  if (ec) throw RuntimeError("cannot continue '" + path_.string() + "': " + ec.message());
  created_ = true;
  written_ = bytes;
  pending_text_.clear();
  pending_ = 0;
}

CsvSeries::~CsvSeries() {
  if (!active_ || (created_ && pending_text_.empty())) return;
  try {
    flush();
  } catch (...) {
    // A destructor must not throw; the data of a failed final flush is lost.
  }
}

}  // namespace domel::platform::io
