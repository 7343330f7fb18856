// SPDX-License-Identifier: MIT
// The checkpoint container (archive.hpp): serialised in memory and
// checksummed; read whole and verified before any section is handed out.
#include "core/archive.hpp"

#include "core/error.hpp"

#include <fstream>
#include <iterator>
#include <sstream>

namespace domel::platform {

namespace {

constexpr char kMagic[8] = {'D', 'O', 'M', 'E', 'L', 'C', 'K', 'P'};
constexpr std::uint32_t kByteOrderMark = 0x01020304u;

std::size_t element_size(ArchiveType t) {
  switch (t) {
    case ArchiveType::f64: case ArchiveType::u64: case ArchiveType::i64: return 8;
    case ArchiveType::u32: return 4;
    case ArchiveType::u8: case ArchiveType::bytes: return 1;
  }
  return 0;
}

const char* type_name(ArchiveType t) {
  switch (t) {
    case ArchiveType::f64: return "f64";
    case ArchiveType::u64: return "u64";
    case ArchiveType::u32: return "u32";
    case ArchiveType::u8: return "u8";
    case ArchiveType::i64: return "i64";
    case ArchiveType::bytes: return "bytes";
  }
  return "unknown";
}

/// FNV-1a, 64 bit: detects truncation and stray changes (not tampering).
std::uint64_t fnv1a(const char* p, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t k = 0; k < n; ++k) {
    h ^= static_cast<unsigned char>(p[k]);
    h *= 0x100000001b3ull;
  }
  return h;
}

template <class T>
void append_raw(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

}  // namespace

void ArchiveWriter::add(const std::string& key, ArchiveType type, std::uint64_t count, const void* data,
                        std::size_t bytes) {
  Section s{type, count, std::string(static_cast<const char*>(data), bytes)};
  const auto it = index_.find(key);
  if (it != index_.end()) {
    sections_[it->second].second = std::move(s);
    return;
  }
  index_[key] = sections_.size();
  sections_.emplace_back(key, std::move(s));
}

std::size_t ArchiveWriter::bytes() const {
  std::size_t b = 0;
  for (const auto& [key, s] : sections_) b += key.size() + s.data.size() + 13;
  return b;
}

std::string ArchiveWriter::serialize(const std::string& header_json) const {
  std::string out;
  out.reserve(bytes() + header_json.size() + 64);
  out.append(kMagic, sizeof kMagic);
  append_raw(out, kArchiveVersion);
  append_raw(out, kByteOrderMark);
  append_raw(out, static_cast<std::uint64_t>(header_json.size()));
  out += header_json;
  append_raw(out, static_cast<std::uint64_t>(sections_.size()));
  for (const auto& [key, s] : sections_) {
    append_raw(out, static_cast<std::uint32_t>(key.size()));
    out += key;
    append_raw(out, static_cast<std::uint8_t>(s.type));
    append_raw(out, s.count);
    out += s.data;
  }
  append_raw(out, fnv1a(out.data(), out.size()));
  return out;
}

void ArchiveReader::fail(const std::string& key, const std::string& what) const {
  throw ConfigError({Diagnostic{path_.string(), key.empty() ? "" : "section '" + key + "'",
                                "checkpoint " + what, ""}});
}

ArchiveReader::ArchiveReader(const std::filesystem::path& path) : path_(path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail("", "is a folder, not a checkpoint file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("", "cannot be opened");
  parse(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
}

ArchiveReader::ArchiveReader(const std::string& bytes, std::filesystem::path label) : path_(std::move(label)) {
  parse(bytes);
}

void ArchiveReader::parse(const std::string& buf) {
  std::size_t pos = 0;
  auto need = [&](std::size_t n, const char* what) {
    if (buf.size() - pos < n) fail("", std::string("is truncated (in ") + what + ")");
  };
  auto read_u = [&](auto& v, const char* what) {
    need(sizeof v, what);
    std::memcpy(&v, buf.data() + pos, sizeof v);
    pos += sizeof v;
  };
  if (buf.size() < sizeof kMagic || std::memcmp(buf.data(), kMagic, sizeof kMagic) != 0)
    fail("", "is not a domel checkpoint (its first bytes are not \"DOMELCKP\")");
  pos = sizeof kMagic;
  std::uint32_t version = 0, bom = 0;
  read_u(version, "the format version");
  read_u(bom, "the byte-order mark");
  if (bom != kByteOrderMark) fail("", "was written on a machine of the other byte order");
  if (version != kArchiveVersion)
    fail("", "has format version " + std::to_string(version) + "; this domel reads version " +
                 std::to_string(kArchiveVersion));
  if (buf.size() < pos + 8) fail("", "is truncated (before its checksum)");
  std::uint64_t stored = 0;
  std::memcpy(&stored, buf.data() + buf.size() - 8, 8);
  if (stored != fnv1a(buf.data(), buf.size() - 8)) fail("", "is corrupted or truncated (its checksum does not match)");
  const std::size_t end = buf.size() - 8;
  auto need_before_end = [&](std::size_t n, const char* what) {
    if (end - pos < n) fail("", std::string("is malformed (in ") + what + ")");
  };
  std::uint64_t header_size = 0;
  read_u(header_size, "the header length");
  need_before_end(header_size, "the header");
  header_.assign(buf.data() + pos, header_size);
  pos += header_size;
  std::uint64_t count = 0;
  read_u(count, "the section count");
  for (std::uint64_t k = 0; k < count; ++k) {
    std::uint32_t key_size = 0;
    read_u(key_size, "a section key");
    need_before_end(key_size, "a section key");
    std::string key(buf.data() + pos, key_size);
    pos += key_size;
    std::uint8_t type = 0;
    std::uint64_t n = 0;
    read_u(type, "a section type");
    read_u(n, "a section size");
    const auto t = static_cast<ArchiveType>(type);
    const std::size_t es = element_size(t);
    if (es == 0) fail(key, "has an unknown section type " + std::to_string(type));
    if (n > (end - pos) / es) fail(key, "is malformed (a section runs past the end)");
    sections_[key] = Section{t, n, std::string(buf.data() + pos, n * es)};
    pos += n * es;
  }
  if (pos != end) fail("", "is malformed (bytes after the last section)");
}

const ArchiveReader::Section& ArchiveReader::find(const std::string& key, ArchiveType type) const {
  const auto it = sections_.find(key);
  if (it == sections_.end()) fail(key, "lacks this section");
  if (it->second.type != type)
    fail(key, std::string("holds ") + type_name(it->second.type) + " values, expected " + type_name(type));
  return it->second;
}

CheckpointFields::CheckpointFields(const ArchiveReader& r, std::string prefix) : r_(&r), prefix_(std::move(prefix)) {
  const std::string key = prefix_ + ".fields";
  if (!r.has(key)) r.fail(key, "is missing: the checkpoint was written without the list of this part's fields");
  std::istringstream in(r.text(key));
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) stored_.push_back(line);
}

void CheckpointFields::field(const std::string& key, ArchiveType type, bool scalar) {
  const std::string entry = key + " " + type_name(type) + (scalar ? "" : "[]");
  if (r_) {
    const std::size_t k = listed_.size();
    if (k >= stored_.size())
      r_->fail(prefix_ + ".fields", "lists " + std::to_string(stored_.size()) + " fields; this build reads '" +
                                        entry + "' as field " + std::to_string(k + 1) +
                                        " (the checkpoint was written by another version of this part)");
    if (stored_[k] != entry)
      r_->fail(prefix_ + ".fields", "lists '" + stored_[k] + "' as field " + std::to_string(k + 1) +
                                        " where this build reads '" + entry +
                                        "' (the checkpoint was written by another version of this part)");
  }
  listed_.push_back(entry);
}

void CheckpointFields::finish() {
  if (w_) {
    std::string text;
    for (const auto& e : listed_) text += e + "\n";
    w_->put_text(prefix_ + ".fields", text);
    return;
  }
  if (stored_.size() > listed_.size())
    r_->fail(prefix_ + ".fields", "lists '" + stored_[listed_.size()] + "' as field " +
                                      std::to_string(listed_.size() + 1) + ", which this build does not read "
                                      "(the checkpoint was written by another version of this part)");
}

}  // namespace domel::platform
