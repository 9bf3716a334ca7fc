#include "fbx_bounds.h"

#include <cstring>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace softdeca::avatar_import {

namespace {
constexpr char kMagic[] = "Kaydara FBX Binary  ";
constexpr std::size_t kHeaderBytes = 27;  // magic, NUL, 0x1A, 0x00, version
constexpr std::uint64_t kTokenBytes = 64;  // what assimp holds per value, about

std::string mib(std::uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

// Object-to-object connections (child -> parent): the chains assimp walks recursively.
class Connections {
 public:
  void add(std::int64_t child, std::int64_t parent) { parent_[child] = parent; }
  // The longest chain; throws on a cycle or a chain over `max`.
  std::size_t depth(const std::string& path, std::size_t max) const {
    std::unordered_map<std::int64_t, std::size_t> known;  // object -> its chain's length
    std::size_t deepest = 0;
    std::vector<std::int64_t> chain;
    for (const auto& [start, unused] : parent_) {
      chain.clear();
      std::int64_t at = start;
      std::size_t base = 0;
      while (true) {
        if (const auto k = known.find(at); k != known.end()) {
          base = k->second;
          break;
        }
        const auto p = parent_.find(at);
        if (p == parent_.end()) break;
        chain.push_back(at);
        if (chain.size() > max)
          throw std::runtime_error(path + ": objects connected more than " + std::to_string(max) + " deep (or in a cycle)");
        at = p->second;
      }
      for (std::size_t i = chain.size(); i-- > 0;) known[chain[i]] = ++base;
      deepest = std::max(deepest, base);
      if (deepest > max) throw std::runtime_error(path + ": objects connected more than " + std::to_string(max) + " deep");
    }
    return deepest;
  }

 private:
  std::unordered_map<std::int64_t, std::int64_t> parent_;
};

class BinaryScan {
 public:
  BinaryScan(const std::string& bytes, const std::string& path, const ImportLimits& limits)
      : b_(bytes), path_(path), limits_(limits) {}

  FbxScan run() {
    if (b_.size() < kHeaderBytes) fail("shorter than an FBX header");
    scan_.binary = true;
    scan_.version = u32(23);
    wide_ = scan_.version >= 7500;
    const std::uint64_t decoded_budget = fbx_decoded_budget(b_.size(), limits_);
    std::vector<std::uint64_t> ends;  // the end offsets of the open records
    std::vector<bool> in_connections;
    std::uint64_t pos = kHeaderBytes;
    while (true) {
      while (!ends.empty() && pos == ends.back()) ends.pop_back(), in_connections.pop_back();  // no NUL record
      const std::uint64_t limit = ends.empty() ? b_.size() : ends.back();
      if (pos + record_header() > limit) {
        if (ends.empty()) break;  // the top level may end without its NUL record
        fail("a record is cut short at byte " + std::to_string(pos));
      }
      const std::uint64_t end = word(pos), count = word(pos + word_bytes()), list = word(pos + 2 * word_bytes());
      const std::uint64_t name_len = byte(pos + 3 * word_bytes());
      if (end == 0 && count == 0 && list == 0 && name_len == 0) {  // the NUL record closing a list
        pos += record_header();
        if (ends.empty()) break;
        pos = ends.back();
        ends.pop_back(), in_connections.pop_back();
        continue;
      }
      const std::uint64_t props = pos + record_header() + name_len;
      if (end > limit || end <= pos || props > end || list > end - props)
        fail("a record at byte " + std::to_string(pos) + " ends beyond what holds it");
      const std::string name(b_.data() + pos + record_header(), name_len);
      ++scan_.values;
      properties(props, count, list, name == "C" && !in_connections.empty() && in_connections.back());
      if (scan_.decoded_bytes > decoded_budget)
        fail("its arrays would expand to more than " + mib(decoded_budget) + ", more than a file of " + mib(b_.size()) +
             " may (a compressed array far larger than its file)");
      if (scan_.values > fbx_value_budget(b_.size())) fail("more values than a file of its size may hold");
      const std::uint64_t children = props + list;
      if (children < end) {  // a nested list follows
        ends.push_back(end);
        in_connections.push_back(name == "Connections");
        scan_.depth = std::max(scan_.depth, static_cast<int>(ends.size()));
        if (ends.size() > kMaxFbxDepth) fail("records nested more than " + std::to_string(kMaxFbxDepth) + " deep");
        pos = children;
      } else {
        pos = end;
      }
    }
    scan_.connection_depth = connections_.depth(path_, static_cast<std::size_t>(limits_.max_node_depth));
    return scan_;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw std::runtime_error(path_ + ": not a readable FBX file: " + what); }
  std::uint64_t word_bytes() const { return wide_ ? 8 : 4; }
  std::uint64_t record_header() const { return 3 * word_bytes() + 1; }
  void need(std::uint64_t at, std::uint64_t n) const {
    if (at > b_.size() || n > b_.size() - at) fail("a value is cut short at byte " + std::to_string(at));
  }
  std::uint8_t byte(std::uint64_t at) const {
    need(at, 1);
    return static_cast<std::uint8_t>(b_[at]);
  }
  std::uint32_t u32(std::uint64_t at) const {
    need(at, 4);
    std::uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<std::uint8_t>(b_[at + static_cast<std::uint64_t>(k)]);
    return v;
  }
  std::uint64_t u64(std::uint64_t at) const { return u32(at) | (std::uint64_t{u32(at + 4)} << 32); }
  std::uint64_t word(std::uint64_t at) const { return wide_ ? u64(at) : u32(at); }

  // The properties of one record within [at, at + list); a connection's object ids are kept.
  void properties(std::uint64_t at, std::uint64_t count, std::uint64_t list, bool connection) {
    const std::uint64_t stop = at + list;
    std::string kind;
    std::int64_t ids[2] = {0, 0};
    int id_count = 0;
    for (std::uint64_t i = 0; i < count; ++i) {
      if (at >= stop) fail("a record has fewer properties than it says");
      const char type = static_cast<char>(byte(at++));
      ++scan_.values;
      std::uint64_t size = 0;
      switch (type) {
        case 'C': size = 1; break;
        case 'Y': size = 2; break;
        case 'I': case 'F': size = 4; break;
        case 'D': size = 8; break;
        case 'L':
          size = 8;
          if (connection && id_count < 2) {
            need(at, 8);
            ids[id_count++] = static_cast<std::int64_t>(u64(at));
          }
          break;
        case 'S': case 'R':
          size = u32(at) + std::uint64_t{4};
          if (connection && type == 'S' && i == 0) kind.assign(b_.data() + at + 4, std::min<std::uint64_t>(u32(at), 8));
          break;
        case 'f': case 'i': size = array(at, 4); break;
        case 'd': case 'l': size = array(at, 8); break;
        case 'b': size = array(at, 1); break;
        default: fail(std::string("a property of unknown type '") + type + "' at byte " + std::to_string(at - 1));
      }
      if (size > stop - at) fail("a property at byte " + std::to_string(at - 1) + " runs past its record");
      at += size;
    }
    if (connection && kind == "OO" && id_count == 2) connections_.add(ids[0], ids[1]);
  }

  // An array property's bytes in the file; its expanded size is counted.
  std::uint64_t array(std::uint64_t at, std::uint64_t element) {
    const std::uint64_t length = u32(at), encoding = u32(at + 4), stored = u32(at + 8);
    const std::uint64_t expanded = length * element;
    if (encoding == 0 && stored != expanded) fail("an array's size disagrees with its length at byte " + std::to_string(at));
    if (encoding > 1) fail("an array of unknown encoding " + std::to_string(encoding) + " at byte " + std::to_string(at));
    scan_.decoded_bytes += expanded;
    scan_.values += length;  // assimp converts every element
    return 12 + stored;
  }

  const std::string& b_;
  const std::string& path_;
  const ImportLimits& limits_;
  bool wide_ = false;
  FbxScan scan_;
  Connections connections_;
};

// ASCII FBX: nesting by braces outside quoted strings and comments, values as tokens, and
// the "C: "OO",child,parent" connections.
FbxScan scan_ascii(const std::string& b, const std::string& path, const ImportLimits& limits) {
  FbxScan scan;
  Connections connections;
  int depth = 0;
  bool token = false;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const char c = b[i];
    if (c == ';' && !token) {  // a comment to the end of the line
      while (i < b.size() && b[i] != '\n') ++i;
      continue;
    }
    if (c == '"') {
      const std::size_t close = b.find('"', i + 1);
      if (close == std::string::npos) throw std::runtime_error(path + ": not a readable FBX file: a string is never closed");
      i = close;
      ++scan.values;
      token = false;
      continue;
    }
    if (c == '{' || c == '}') {
      depth += c == '{' ? 1 : -1;
      if (depth < 0) throw std::runtime_error(path + ": not a readable FBX file: a '}' closes nothing");
      if (depth > kMaxFbxDepth)
        throw std::runtime_error(path + ": not a readable FBX file: records nested more than " + std::to_string(kMaxFbxDepth) + " deep");
      scan.depth = std::max(scan.depth, depth);
      ++scan.values;
      token = false;
      continue;
    }
    const bool separator = c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == ':';
    if (!separator && !token) ++scan.values;
    token = !separator;
    if (c == 'C' && (i == 0 || b[i - 1] == '\n' || b[i - 1] == '\t' || b[i - 1] == ' ') && b.compare(i, 7, "C: \"OO\"") == 0) {
      long long child = 0, parent = 0;
      if (std::sscanf(b.c_str() + i + 7, " , %lld , %lld", &child, &parent) == 2) connections.add(child, parent);
    }
  }
  if (scan.values > fbx_value_budget(b.size()))
    throw std::runtime_error(path + ": not a readable FBX file: more values than a file of its size may hold");
  scan.connection_depth = connections.depth(path, static_cast<std::size_t>(limits.max_node_depth));
  return scan;
}
}  // namespace

std::uint64_t fbx_decoded_budget(std::uint64_t file_bytes, const ImportLimits& limits) {
  return std::min<std::uint64_t>(limits.max_decoded_bytes, 2 * file_bytes + (std::uint64_t{200} << 20));
}

std::uint64_t fbx_value_budget(std::uint64_t file_bytes) { return (3 * file_bytes + (std::uint64_t{400} << 20)) / kTokenBytes; }

FbxScan scan_fbx(const std::string& bytes, const std::string& path, const ImportLimits& limits) {
  if (bytes.compare(0, std::strlen(kMagic), kMagic) == 0) return BinaryScan(bytes, path, limits).run();
  return scan_ascii(bytes, path, limits);
}

}  // namespace softdeca::avatar_import
