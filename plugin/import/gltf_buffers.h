// The bytes behind a glTF's buffers and buffer views, loaded when a mesh first needs them: the
// GLB's BIN chunk, base64 data: URIs, and files named by relative URIs, read through the
// avatar's folder only (input_files.h: no absolute path, no "..", no link, no FIFO). A view
// compressed with EXT_meshopt_compression is decoded once, within the decode budget; a buffer
// that holds only a fallback placeholder is never required.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gltf_container.h"
#include "gltf_document.h"
#include "import_limits.h"
#include "input_files.h"

namespace softdeca::avatar_import::gltf {

class BinaryData {
 public:
  // `file` is the whole file (its BIN chunk is used in place); relative URIs are resolved in
  // `folder`, opened on first use. `read_so_far`: bytes already read for this import (the file).
  BinaryData(Document& doc, const Container& container, const std::string& file, std::string folder, const ImportLimits& limits,
             DecodeBudget& budget, std::uint64_t read_so_far);
  ~BinaryData();

  // buffers[index]'s byteLength bytes.
  std::string_view buffer(std::size_t index);
  // bufferViews[index]'s byteLength bytes, decompressed when the view is compressed.
  std::string_view view(std::size_t index);

 private:
  bool has_data(std::size_t buffer) const;
  std::string load(std::size_t index, const Buffer& b);

  Document& doc_;
  const Container& container_;
  const std::string& file_;
  std::string folder_path_;
  std::unique_ptr<InputFolder> folder_;
  const ImportLimits& limits_;
  DecodeBudget& budget_;
  std::uint64_t read_;
  std::vector<std::optional<std::string>> buffers_;
  std::vector<std::optional<std::vector<unsigned char>>> decoded_;
};

// The bytes of a base64 text (RFC 4648, '=' padding optional); nullopt when it is not base64.
std::optional<std::string> decode_base64(std::string_view text);
// A URI's percent escapes decoded (RFC 3986); nullopt at a malformed escape.
std::optional<std::string> percent_decoded(std::string_view uri);

}  // namespace softdeca::avatar_import::gltf
