// A glTF's JSON as the reader uses it: the top-level arrays, and the buffers, buffer views and
// accessors the meshes refer to, each checked against the specification the first time it is
// used (and only then: a malformed texture view does not stop an avatar) and kept, so a file
// that refers to one accessor many times costs its JSON once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "gltf_json.h"

namespace softdeca::avatar_import::gltf {

enum Component : std::uint32_t {
  kByte = 5120,
  kUnsignedByte = 5121,
  kShort = 5122,
  kUnsignedShort = 5123,
  kUnsignedInt = 5125,
  kFloat = 5126,
};
std::uint32_t component_size(std::uint32_t component);

struct Buffer {
  std::uint64_t length = 0;        // byteLength
  std::optional<std::string> uri;  // as the file spells it (percent-encoded)
  bool fallback = false;           // EXT_meshopt_compression "fallback": placeholder data nobody reads
};

// EXT_meshopt_compression on a buffer view: where the compressed bytes are and how they decode.
struct MeshoptView {
  enum class Mode { attributes, triangles, indices };
  enum class Filter { none, octahedral, quaternion, exponential };
  std::size_t buffer = 0;
  std::uint64_t offset = 0, length = 0, stride = 0, count = 0;
  Mode mode = Mode::attributes;
  Filter filter = Filter::none;
};

struct BufferView {
  std::size_t buffer = 0;
  std::uint64_t offset = 0, length = 0;
  std::uint32_t stride = 0;  // byteStride, 0 when not given (tightly packed)
  std::optional<MeshoptView> meshopt;
};

// The bytes of one accessor element: column-major matrices pad each column to 4 bytes, and the
// last column's padding may be left out of the last element.
struct ElementLayout {
  std::uint32_t component_size = 0, components = 0;
  std::uint32_t rows = 0, columns = 0;  // a vector is one column
  std::uint64_t size = 0;               // with padding: the stride of tightly packed elements
  std::uint64_t last_size = 0;          // the bytes the last element needs
  std::uint64_t column_stride = 0;
};

struct Sparse {
  std::uint64_t count = 0;
  std::size_t indices_view = 0, values_view = 0;
  std::uint64_t indices_offset = 0, values_offset = 0;
  std::uint32_t indices_component = 0;
};

struct Accessor {
  std::optional<std::size_t> view;  // none: zeros (then sparse values, or data an extension gives)
  std::uint64_t offset = 0;
  std::uint64_t stride = 0;  // between elements in the view
  std::uint32_t component = 0;
  bool normalized = false;
  std::uint64_t count = 0;
  std::string type;  // "SCALAR", "VEC3", "MAT4", ...
  ElementLayout layout;
  std::optional<Sparse> sparse;
};

class Document {
 public:
  explicit Document(Json json);  // throws Problem unless the JSON is an object
  Document(const Document&) = delete;  // its objects point into its JSON
  Document& operator=(const Document&) = delete;

  const Object& root() const { return root_; }
  // The items of a top-level array ("accessors"); 0 when the file has none.
  std::size_t count(const char* array) const;
  Object item(const char* array, std::size_t index) const;  // "accessors[3]"

  const Buffer& buffer(std::size_t index);
  const BufferView& view(std::size_t index);
  const Accessor& accessor(std::size_t index);

 private:
  const std::vector<Json>* top(const char* array) const;

  Json json_;
  Object root_;
  std::map<std::string, const std::vector<Json>*> arrays_;
  std::vector<std::optional<Buffer>> buffers_;
  std::vector<std::optional<BufferView>> views_;
  std::vector<std::optional<Accessor>> accessors_;
};

}  // namespace softdeca::avatar_import::gltf
