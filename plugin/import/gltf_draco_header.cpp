// Draco's layout up to the connectivity counts (bitstream 2.2): the header ("DRACO", version,
// geometry type, method, flags), the optional metadata section, the edgebreaker traversal type,
// then the counts. Every read is checked against the end of the stream, and the metadata walk
// keeps a count instead of recursing, so neither a short stream nor deep sub-metadata can take
// it past its bytes or its stack.
#include "gltf_draco_header.h"

#include <cstring>

#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {
namespace {

constexpr std::uint16_t kMetadataFlag = 0x8000;
constexpr std::uint8_t kTriangularMesh = 1;
constexpr std::uint8_t kSequential = 0, kEdgebreaker = 1;

class Cursor {
 public:
  Cursor(std::string_view bytes, const std::string& where) : bytes_(bytes), where_(where) {}

  std::uint8_t byte() {
    need(1);
    return static_cast<std::uint8_t>(bytes_[at_++]);
  }
  std::uint16_t u16() {
    const std::uint16_t lo = byte();
    return static_cast<std::uint16_t>(lo | (std::uint16_t{byte()} << 8));
  }
  // An unsigned LEB128 value of at most 32 bits, as Draco writes its counts.
  std::uint32_t varint() {
    std::uint64_t value = 0;
    for (int shift = 0; shift < 35; shift += 7) {
      const std::uint8_t b = byte();
      value |= std::uint64_t{b & 0x7Fu} << shift;
      if (!(b & 0x80u)) {
        if (value > 0xFFFFFFFFu) break;
        return static_cast<std::uint32_t>(value);
      }
    }
    throw Problem(where_, "its Draco stream holds a count longer than 32 bits at byte " + std::to_string(at_));
  }
  void skip(std::uint64_t n) {
    need(n);
    at_ += static_cast<std::size_t>(n);
  }
  std::uint64_t remaining() const { return bytes_.size() - at_; }

 private:
  void need(std::uint64_t n) const {
    if (n > remaining()) throw Problem(where_, "its Draco stream ends at byte " + std::to_string(bytes_.size()) + " inside its header");
  }
  std::string_view bytes_;
  const std::string& where_;
  std::size_t at_ = 0;
};

void skip_name(Cursor& c) { c.skip(c.byte()); }

// One metadata block and its sub-blocks: a block is its entries (a name, a size, that many
// bytes) and a count of sub-blocks, each of which starts with its name. The sub-blocks are all
// alike, so a count of those still to read replaces the decoder's stack; each costs at least a
// byte, so the count stays below the stream's size.
void skip_metadata(Cursor& c, const std::string& where) {
  std::uint64_t pending = 1;
  for (bool root = true; pending > 0; root = false) {
    --pending;
    if (!root) skip_name(c);
    const std::uint32_t entries = c.varint();
    for (std::uint32_t i = 0; i < entries; ++i) {
      skip_name(c);
      const std::uint32_t size = c.varint();
      if (size == 0) throw Problem(where, "its Draco metadata holds an entry of no bytes");
      c.skip(size);
    }
    const std::uint32_t children = c.varint();
    if (children > c.remaining()) throw Problem(where, "its Draco metadata declares more sub-blocks than it has bytes");
    pending += children;
  }
}

}  // namespace

DracoCounts read_draco_counts(std::string_view bytes, const std::string& where) {
  Cursor c(bytes, where);
  char magic[5];
  for (char& m : magic) m = static_cast<char>(c.byte());
  if (std::memcmp(magic, "DRACO", 5) != 0) throw Problem(where, "its KHR_draco_mesh_compression data is not a Draco stream");
  const unsigned major = c.byte(), minor = c.byte();
  if (major != 2 || minor != 2)
    throw Problem(where, "its Draco stream is of bitstream version " + std::to_string(major) + "." + std::to_string(minor) +
                             ", not the 2.2 that KHR_draco_mesh_compression names");
  if (c.byte() != kTriangularMesh) throw Problem(where, "its Draco stream is not a triangle mesh");
  const std::uint8_t method = c.byte();
  if (method != kSequential && method != kEdgebreaker)
    throw Problem(where, "its Draco stream names an unknown encoding method " + std::to_string(method));
  const std::uint16_t flags = c.u16();
  if (flags & kMetadataFlag) {
    const std::uint32_t attribute_blocks = c.varint();
    if (attribute_blocks > c.remaining()) throw Problem(where, "its Draco metadata declares more blocks than it has bytes");
    for (std::uint32_t i = 0; i < attribute_blocks; ++i) {
      c.varint();  // the attribute's unique id
      skip_metadata(c, where);
    }
    skip_metadata(c, where);  // the geometry's own
  }
  DracoCounts counts;
  counts.edgebreaker = method == kEdgebreaker;
  if (counts.edgebreaker) {
    c.byte();  // the traversal decoder's type
    counts.vertices = c.varint();
    counts.faces = c.varint();
  } else {
    counts.faces = c.varint();
    counts.vertices = c.varint();
  }
  return counts;
}

}  // namespace softdeca::avatar_import::gltf
