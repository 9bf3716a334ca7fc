#include "gltf_container.h"

#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {

namespace {
constexpr std::uint32_t kJsonChunk = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kBinChunk = 0x004E4942;   // "BIN\0"

std::uint32_t u32_at(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(k)]);
  return v;
}

std::string too_long(std::uint64_t length, std::uint64_t max_json_bytes) {
  return "its JSON has " + std::to_string(length) + " bytes, more than the " + std::to_string(max_json_bytes) +
         " a glTF's JSON may have";
}

std::string without_bom(std::string text) {
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  return text;
}
}  // namespace

Container split_container(const std::string& bytes, bool binary, std::uint64_t max_json_bytes) {
  Container out;
  if (!binary) {
    if (bytes.size() > max_json_bytes) throw Problem("", too_long(bytes.size(), max_json_bytes));
    out.json = without_bom(bytes);
    return out;
  }
  out.binary = true;
  const std::uint64_t file_size = bytes.size();
  if (file_size < 12) throw Problem("", "a binary glTF of " + std::to_string(file_size) + " bytes, shorter than its 12-byte header");
  const std::uint32_t version = u32_at(bytes, 4), length = u32_at(bytes, 8);
  if (version != 2) throw Problem("", "binary glTF version " + std::to_string(version) + "; only version 2 (glTF 2.0) is read");
  if (length > file_size)
    throw Problem("", "its header says " + std::to_string(length) + " bytes, but the file has " + std::to_string(file_size) +
                          " (truncated?)");
  const std::uint64_t end = length;  // bytes after the stated length are not part of the container
  std::uint64_t at = 12;
  bool has_json = false;
  for (int chunk = 0; at < end; ++chunk) {
    const std::string where = "chunk " + std::to_string(chunk);
    if (end - at < 8) throw Problem("", where + ": its 8-byte header runs past the end of the file");
    const std::uint64_t chunk_length = u32_at(bytes, static_cast<std::size_t>(at));
    const std::uint32_t type = u32_at(bytes, static_cast<std::size_t>(at + 4));
    const std::uint64_t data = at + 8;
    if (!range_within(data, chunk_length, end))
      throw Problem("", where + ": " + std::to_string(chunk_length) + " bytes from byte " + std::to_string(data) +
                            ", past the end of the file's " + std::to_string(end) + " (truncated?)");
    if (chunk == 0) {
      if (type != kJsonChunk) throw Problem("", "its first chunk is not JSON");
      if (chunk_length > max_json_bytes) throw Problem("", too_long(chunk_length, max_json_bytes));
      std::string json = bytes.substr(static_cast<std::size_t>(data), static_cast<std::size_t>(chunk_length));
      // Padding is spaces by the specification; some writers pad with zeros.
      while (!json.empty() && json.back() == '\0') json.pop_back();
      out.json = without_bom(std::move(json));
      has_json = true;
    } else if (type == kJsonChunk) {
      throw Problem("", where + ": a second JSON chunk");
    } else if (type == kBinChunk) {
      if (chunk != 1) throw Problem("", where + ": a BIN chunk that is not the second chunk");
      out.bin_offset = static_cast<std::size_t>(data);
      out.bin_length = static_cast<std::size_t>(chunk_length);
    }  // other chunk types belong to extensions: skipped
    // Chunks start on 4-byte boundaries; a last chunk may end the file unpadded.
    at = data + chunk_length;
    at += (4 - at % 4) % 4;
  }
  if (!has_json) throw Problem("", "a binary glTF with no JSON chunk");
  return out;
}

}  // namespace softdeca::avatar_import::gltf
