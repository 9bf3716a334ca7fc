#include "gltf_buffers.h"

#include <algorithm>

#include "gltf_meshopt.h"

namespace softdeca::avatar_import::gltf {

namespace {
std::string text(std::uint64_t n) { return std::to_string(n); }

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }
}  // namespace

std::optional<std::string> decode_base64(std::string_view text) {
  while (!text.empty() && text.back() == '=') text.remove_suffix(1);
  if (text.size() % 4 == 1) return std::nullopt;
  std::string out;
  out.reserve(text.size() / 4 * 3 + 2);
  std::uint32_t bits = 0;
  int held = 0;
  for (const char c : text) {
    const int v = base64_value(c);
    if (v < 0) return std::nullopt;
    bits = (bits << 6) | static_cast<std::uint32_t>(v);
    held += 6;
    if (held >= 8) {
      held -= 8;
      out += static_cast<char>((bits >> held) & 0xFF);
    }
  }
  return out;
}

std::optional<std::string> percent_decoded(std::string_view uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      out += uri[i];
      continue;
    }
    if (i + 2 >= uri.size()) return std::nullopt;
    const int hi = hex_value(uri[i + 1]), lo = hex_value(uri[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return out;
}

BinaryData::BinaryData(Document& doc, const Container& container, const std::string& file, std::string folder, const ImportLimits& limits,
                       DecodeBudget& budget, std::uint64_t read_so_far)
    : doc_(doc),
      container_(container),
      file_(file),
      folder_path_(std::move(folder)),
      limits_(limits),
      budget_(budget),
      read_(read_so_far),
      buffers_(doc.count("buffers")),
      decoded_(doc.count("bufferViews")) {}

BinaryData::~BinaryData() = default;

bool BinaryData::has_data(std::size_t index) const {
  const Buffer& b = doc_.buffer(index);
  if (b.uri) return true;
  return container_.binary && index == 0 && container_.bin_offset.has_value();
}

std::string BinaryData::load(std::size_t index, const Buffer& b) {
  const std::string where = "buffers[" + text(index) + "]";
  const std::string& uri = *b.uri;
  if (starts_with(uri, "data:")) {
    // data:[<media type>];base64,<data> (RFC 2397); the media type is not checked.
    const std::size_t comma = uri.find(',');
    const std::string_view header = std::string_view(uri).substr(0, comma);
    if (comma == std::string::npos || header.size() < 12 || header.substr(header.size() - 7) != ";base64")
      throw Problem(where, "its data: URI is not base64 (data:<type>;base64,...)");
    std::optional<std::string> bytes = decode_base64(std::string_view(uri).substr(comma + 1));
    if (!bytes) throw Problem(where, "its data: URI holds characters that are not base64");
    return std::move(*bytes);
  }
  const std::optional<std::string> relative = percent_decoded(uri);
  if (!relative) throw Problem(where, "its uri '" + uri + "' has a malformed percent escape");
  const std::uint64_t room = limits_.max_total_bytes > read_ ? limits_.max_total_bytes - read_ : 0;
  try {
    if (!folder_) folder_ = std::make_unique<InputFolder>(folder_path_);
    return folder_->read(*relative, std::min(limits_.max_file_bytes, room), "a glTF buffer");
  } catch (const std::runtime_error& e) {  // the folder's reasons, in the user's words
    throw Problem(where, e.what());
  }
}

std::string_view BinaryData::buffer(std::size_t index) {
  const Buffer& b = doc_.buffer(index);
  const std::string where = "buffers[" + text(index) + "]";
  std::string_view bytes;
  if (!b.uri) {
    if (!(container_.binary && index == 0)) {
      const std::string placeholder = b.fallback ? "a fallback placeholder" : "a placeholder";
      throw Problem(where, "has no uri and no data (" + placeholder + " that only compressed views may name), but the file reads from it");
    }
    if (!container_.bin_offset) throw Problem(where, "has no uri, and the file has no BIN chunk to hold its data");
    bytes = std::string_view(file_).substr(*container_.bin_offset, container_.bin_length);
  } else {
    std::optional<std::string>& cached = buffers_.at(index);
    if (!cached) {
      std::string data = load(index, b);
      if (data.size() > limits_.max_total_bytes - std::min(read_, limits_.max_total_bytes))
        throw Problem(where, "reading it would take the avatar's files past the " + text(limits_.max_total_bytes) +
                                 " bytes an import may read");
      read_ += data.size();
      budget_.add_input(data.size());
      cached = std::move(data);
    }
    bytes = *cached;
  }
  if (bytes.size() < b.length)
    throw Problem(where, "byteLength " + text(b.length) + ", but its data has " + text(bytes.size()) + " bytes");
  return bytes.substr(0, static_cast<std::size_t>(b.length));
}

std::string_view BinaryData::view(std::size_t index) {
  const BufferView& v = doc_.view(index);
  const std::string where = "bufferViews[" + text(index) + "]";
  if (v.meshopt && (meshopt_supported() || !has_data(v.buffer))) {
    std::optional<std::vector<unsigned char>>& cached = decoded_.at(index);
    if (!cached) {
      if (!meshopt_supported())
        throw Problem(where, "this build cannot decode EXT_meshopt_compression (built without meshoptimizer), and the file has no "
                             "uncompressed copy");
      const MeshoptView& m = *v.meshopt;
      const std::string_view source = buffer(m.buffer).substr(static_cast<std::size_t>(m.offset), static_cast<std::size_t>(m.length));
      budget_.take(v.length, where);
      std::vector<unsigned char> out(static_cast<std::size_t>(v.length));
      decode_meshopt(m, source, out.data(), where);
      cached = std::move(out);
    }
    return std::string_view(reinterpret_cast<const char*>(cached->data()), cached->size());
  }
  return buffer(v.buffer).substr(static_cast<std::size_t>(v.offset), static_cast<std::size_t>(v.length));
}

}  // namespace softdeca::avatar_import::gltf
