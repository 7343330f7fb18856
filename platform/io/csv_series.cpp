// SPDX-License-Identifier: MIT
// CsvSeries: header built once, rows formatted with std::to_chars (shortest
// round-trippable, locale independent) into an in-memory text, the file
// rewritten with write_file_atomically() on flush.
#include "io/csv_series.hpp"

#include <charconv>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

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

}  // namespace

CsvSeries::CsvSeries(std::filesystem::path path, std::vector<std::string> columns,
                     std::size_t flush_every)
    : path_(std::move(path)), columns_(columns.size()), flush_every_(flush_every) {
  if (columns.empty()) throw std::invalid_argument("CsvSeries: no columns for '" + path_.string() + "'");
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (c > 0) text_ += ',';
    text_ += csv_field(columns[c]);
  }
  text_ += '\n';
}

CsvSeries::CsvSeries(CsvSeries&& other) noexcept
    : path_(std::move(other.path_)),
      columns_(other.columns_),
      flush_every_(other.flush_every_),
      text_(std::move(other.text_)),
      pending_(std::exchange(other.pending_, 0)),
      dirty_(std::exchange(other.dirty_, false)) {}

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
    if (c > 0) text_ += ',';
    const auto res = std::to_chars(buf, buf + sizeof buf, row[c]);
    text_.append(buf, res.ptr);
  }
  text_ += '\n';
  ++pending_;
  dirty_ = true;
  if (pending_ >= flush_every_) flush();
}

void CsvSeries::resume(std::size_t bytes) {
  std::ifstream in(path_, std::ios::binary);
  if (!in) throw RuntimeError("cannot continue '" + path_.string() + "': it cannot be read");
  std::string old((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (old.size() < bytes)
    throw RuntimeError("cannot continue '" + path_.string() + "': it holds " + std::to_string(old.size()) +
                       " bytes, fewer than the " + std::to_string(bytes) + " it had at the checkpoint");
  if (old.compare(0, text_.size(), text_) != 0)
    throw RuntimeError("cannot continue '" + path_.string() + "': its header is not this run's (" +
                       std::to_string(columns_) + " columns)");
  old.resize(bytes);
  text_ = std::move(old);
  pending_ = 0;
  dirty_ = true;
  flush();
}

void CsvSeries::flush() {
  write_file_atomically(path_, text_);
  pending_ = 0;
  dirty_ = false;
}

CsvSeries::~CsvSeries() {
  if (!dirty_) return;
  try {
    flush();
  } catch (...) {
    // A destructor must not throw; the data of a failed final flush is lost.
  }
}

}  // namespace domel::platform::io
