// SPDX-License-Identifier: MIT
// The checkpoint file's container (docs/checkpoint.md): a header of JSON
// (what the run was: scenario, plugins, subdomains, time) and named sections
// of typed arrays, closed by a checksum, so that a checkpoint is read back
// bit for bit or refused with a message naming the file and the section.
// Every class whose state a restart needs writes its own sections, under a
// prefix ("sd0/", "flow/") chosen by its owner.
//
// Layout (little-endian, the only byte order this build runs on):
//   "DOMELCKP"  magic, 8 bytes
//   u32         format version (kArchiveVersion)
//   u32         0x01020304, the byte-order mark
//   u64 + bytes the header, JSON text
//   u64         section count
//   per section: u32 key length, key, u8 type (ArchiveType), u64 element
//                count, count x element size bytes
//   u64         FNV-1a 64 of every byte before it
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace domel::platform {

/// 2: every class's sections come with the list of its fields (CheckpointFields).
inline constexpr std::uint32_t kArchiveVersion = 2;

enum class ArchiveType : std::uint8_t { f64 = 1, u64 = 2, u32 = 3, u8 = 4, i64 = 5, bytes = 6 };

template <class T>
constexpr ArchiveType archive_type_of() {
  if constexpr (std::is_same_v<T, double>) return ArchiveType::f64;
  else if constexpr (std::is_same_v<T, std::uint64_t>) return ArchiveType::u64;
  else if constexpr (std::is_same_v<T, std::uint32_t>) return ArchiveType::u32;
  else if constexpr (std::is_same_v<T, std::uint8_t>) return ArchiveType::u8;
  else if constexpr (std::is_same_v<T, std::int64_t>) return ArchiveType::i64;
  else static_assert(sizeof(T) == 0, "no archive type for this element type");
}

/// Collects sections in memory; serialize() gives the file's bytes (the
/// caller writes them, atomically: io/atomic_file.hpp; core/ writes no files).
class ArchiveWriter {
 public:
  template <class T>
  void put(const std::string& key, const std::vector<T>& v) {
    add(key, archive_type_of<T>(), v.size(), v.data(), v.size() * sizeof(T));
  }
  template <class T>
  void put_scalar(const std::string& key, T value) {
    add(key, archive_type_of<T>(), 1, &value, sizeof(T));
  }
  void put_text(const std::string& key, const std::string& text) {
    add(key, ArchiveType::bytes, text.size(), text.data(), text.size());
  }
  /// The whole file: header, sections and checksum.
  std::string serialize(const std::string& header_json) const;
  std::size_t bytes() const;

 private:
  void add(const std::string& key, ArchiveType type, std::uint64_t count, const void* data, std::size_t bytes);
  struct Section {
    ArchiveType type;
    std::uint64_t count;
    std::string data;
  };
  std::vector<std::pair<std::string, Section>> sections_;
  std::map<std::string, std::size_t> index_;
};

/// Reads a whole archive; every failure (not an archive, another format
/// version, a truncated or corrupted file, a missing section, a section of
/// another type) throws ConfigError naming the file and the section.
class ArchiveReader {
 public:
  explicit ArchiveReader(const std::filesystem::path& path);
  /// An archive held in memory (one serialized into a section of another);
  /// `label` names it in the errors (the file and the section).
  ArchiveReader(const std::string& bytes, std::filesystem::path label);
  const std::string& header() const { return header_; }
  const std::filesystem::path& path() const { return path_; }
  bool has(const std::string& key) const { return sections_.count(key) != 0; }

  template <class T>
  std::vector<T> get(const std::string& key) const {
    const Section& s = find(key, archive_type_of<T>());
    std::vector<T> v(s.count);
    if (s.count) std::memcpy(v.data(), s.data.data(), s.count * sizeof(T));
    return v;
  }
  template <class T>
  void get_into(const std::string& key, std::vector<T>& v) const {
    v = get<T>(key);
  }
  template <class T>
  T scalar(const std::string& key) const {
    const Section& s = find(key, archive_type_of<T>());
    if (s.count != 1) fail(key, "holds " + std::to_string(s.count) + " values, expected 1");
    T value;
    std::memcpy(&value, s.data.data(), sizeof(T));
    return value;
  }
  std::string text(const std::string& key) const { return find(key, ArchiveType::bytes).data; }
  /// Throws ConfigError naming the file and the section.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  struct Section {
    ArchiveType type;
    std::uint64_t count;
    std::string data;
  };
  const Section& find(const std::string& key, ArchiveType type) const;
  void parse(const std::string& bytes);
  std::filesystem::path path_;
  std::string header_;
  std::map<std::string, Section> sections_;
};

/// One list of a class's checkpoint fields for both directions. A class
/// describes its state once, in one function that names each field,
///
///   void Mine::fields(CheckpointFields& f) { f("counts", counts_); f("time", time_); ... }
///
/// which save() calls with a writing CheckpointFields and load() with a
/// reading one, so that the two directions cannot drift apart. The writer
/// also stores the list itself, each field's key and element type in order,
/// under "<prefix>.fields"; the reader compares every field it is asked for
/// with the list before it reads the value, and finish() checks that none is
/// left over, so a checkpoint written by another version of the class (a
/// field added, dropped, renamed or moved) is refused naming the field,
/// whatever the values would have been. Scalars are arithmetic types or
/// bool; arrays std::vector of the archive's element types; text a string.
class CheckpointFields {
 public:
  CheckpointFields(ArchiveWriter& w, std::string prefix) : w_(&w), prefix_(std::move(prefix)) {}
  CheckpointFields(const ArchiveReader& r, std::string prefix);
  CheckpointFields(const CheckpointFields&) = delete;
  CheckpointFields& operator=(const CheckpointFields&) = delete;

  bool loading() const { return r_ != nullptr; }
  const std::string& prefix() const { return prefix_; }
  /// The archive read (loading() only), for a refusal naming its file.
  const ArchiveReader& reader() const { return *r_; }

  template <class T>
  void operator()(const std::string& key, std::vector<T>& v) {
    field(key, archive_type_of<T>(), false);
    if (w_) w_->put(prefix_ + key, v);
    else r_->get_into(prefix_ + key, v);
  }
  void operator()(const std::string& key, bool& b) {
    std::uint8_t u = b ? 1 : 0;
    (*this)(key, u);
    b = u != 0;
  }
  template <class T, class = std::enable_if_t<std::is_arithmetic_v<T>>>
  void operator()(const std::string& key, T& x) {
    field(key, archive_type_of<T>(), true);
    if (w_) w_->put_scalar(prefix_ + key, x);
    else x = r_->scalar<T>(prefix_ + key);
  }
  void operator()(const std::string& key, std::string& text) {
    field(key, ArchiveType::bytes, true);  // listed as "bytes": one text
    if (w_) w_->put_text(prefix_ + key, text);
    else text = r_->text(prefix_ + key);
  }
  /// The end of the list: the writer stores it, the reader refuses fields
  /// the checkpoint has beyond the ones read.
  void finish();

 private:
  void field(const std::string& key, ArchiveType type, bool scalar);
  ArchiveWriter* w_ = nullptr;
  const ArchiveReader* r_ = nullptr;
  std::string prefix_;
  std::vector<std::string> listed_;  ///< "key type", written or read so far
  std::vector<std::string> stored_;  ///< the checkpoint's list (loading)
};

/// A class's fields saved, or loaded and checked, through `describe` (a
/// callable taking CheckpointFields&), with the list finished.
template <class Describe>
void save_fields(ArchiveWriter& w, const std::string& prefix, Describe&& describe) {
  CheckpointFields f(w, prefix);
  describe(f);
  f.finish();
}
template <class Describe>
void load_fields(const ArchiveReader& r, const std::string& prefix, Describe&& describe) {
  CheckpointFields f(r, prefix);
  describe(f);
  f.finish();
}

}  // namespace domel::platform
