// EXT_meshopt_compression through libmeshoptimizer. Its decoders check the stream against the
// output size they are given and return an error for data that does not fit; their parameter
// preconditions (asserted, not checked) are the extension's rules, which Document checked.
#include <meshoptimizer.h>

#include "gltf_meshopt.h"

namespace softdeca::avatar_import::gltf {

bool meshopt_supported() { return true; }

void decode_meshopt(const MeshoptView& view, std::string_view compressed, unsigned char* out, const std::string& where) {
  const auto* data = reinterpret_cast<const unsigned char*>(compressed.data());
  const auto count = static_cast<std::size_t>(view.count), stride = static_cast<std::size_t>(view.stride);
  int status = 0;
  switch (view.mode) {
    case MeshoptView::Mode::attributes: status = meshopt_decodeVertexBuffer(out, count, stride, data, compressed.size()); break;
    case MeshoptView::Mode::triangles: status = meshopt_decodeIndexBuffer(out, count, stride, data, compressed.size()); break;
    case MeshoptView::Mode::indices: status = meshopt_decodeIndexSequence(out, count, stride, data, compressed.size()); break;
  }
  if (status != 0)
    throw Problem(where, "its EXT_meshopt_compression data does not decode (meshoptimizer error " + std::to_string(status) + ")");
  switch (view.filter) {
    case MeshoptView::Filter::none: break;
    case MeshoptView::Filter::octahedral: meshopt_decodeFilterOct(out, count, stride); break;
    case MeshoptView::Filter::quaternion: meshopt_decodeFilterQuat(out, count, stride); break;
    case MeshoptView::Filter::exponential: meshopt_decodeFilterExp(out, count, stride); break;
  }
}

}  // namespace softdeca::avatar_import::gltf
