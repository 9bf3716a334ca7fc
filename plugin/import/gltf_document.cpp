#include "gltf_document.h"

namespace softdeca::avatar_import::gltf {

namespace {
constexpr const char* kArrays[] = {"buffers", "bufferViews", "accessors", "meshes", "nodes", "skins", "scenes"};

std::string text(std::uint64_t n) { return std::to_string(n); }

ElementLayout layout_of(const std::string& type, std::uint32_t component, const std::string& where) {
  ElementLayout l;
  l.component_size = component_size(component);
  if (type == "SCALAR" || type == "VEC2" || type == "VEC3" || type == "VEC4") {
    l.rows = type == "SCALAR" ? 1 : static_cast<std::uint32_t>(type[3] - '0');
    l.columns = 1;
  } else if (type == "MAT2" || type == "MAT3" || type == "MAT4") {
    l.rows = l.columns = static_cast<std::uint32_t>(type[3] - '0');
  } else {
    throw Problem(where + ".type", "'" + type + "' is not one of SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3, MAT4");
  }
  l.components = l.rows * l.columns;
  const std::uint64_t column = std::uint64_t{l.rows} * l.component_size;
  l.column_stride = l.columns > 1 ? (column + 3) / 4 * 4 : column;
  l.size = l.column_stride * l.columns;
  l.last_size = l.column_stride * (l.columns - 1) + column;
  return l;
}

MeshoptView meshopt_of(const Object& ext, Document& doc, const BufferView& parent) {
  MeshoptView m;
  m.buffer = ext.index("buffer", doc.count("buffers"), "buffers");
  m.offset = ext.size_or("byteOffset", 0);
  m.length = ext.size("byteLength");
  m.stride = ext.size("byteStride");
  m.count = ext.size("count");
  const std::string mode = ext.string_or("mode", ""), filter = ext.string_or("filter", "NONE");
  if (mode == "ATTRIBUTES") m.mode = MeshoptView::Mode::attributes;
  else if (mode == "TRIANGLES") m.mode = MeshoptView::Mode::triangles;
  else if (mode == "INDICES") m.mode = MeshoptView::Mode::indices;
  else ext.fail("mode '" + mode + "' is not one of ATTRIBUTES, TRIANGLES, INDICES");
  if (filter == "NONE") m.filter = MeshoptView::Filter::none;
  else if (filter == "OCTAHEDRAL") m.filter = MeshoptView::Filter::octahedral;
  else if (filter == "QUATERNION") m.filter = MeshoptView::Filter::quaternion;
  else if (filter == "EXPONENTIAL") m.filter = MeshoptView::Filter::exponential;
  else ext.fail("filter '" + filter + "' is not one of NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL");
  const Buffer& source = doc.buffer(m.buffer);
  if (!range_within(m.offset, m.length, source.length))
    ext.fail(text(m.length) + " bytes from byteOffset " + text(m.offset) + " run past the " + text(source.length) + " of buffers[" +
             text(m.buffer) + "]");
  if (source.fallback) ext.fail("its compressed data lies in a buffer marked as a fallback");
  // The conditions the extension states for a valid view, so the decoder is only ever asked
  // for what it can do.
  const std::optional<std::uint64_t> decoded = checked_product(m.stride, m.count);
  if (m.count == 0) ext.fail("count is 0");
  if (!decoded || *decoded != parent.length)
    ext.fail(text(m.count) + " elements of " + text(m.stride) + " bytes are not the bufferView's byteLength " + text(parent.length));
  if (parent.stride != 0 && parent.stride != m.stride)
    ext.fail("byteStride " + text(m.stride) + " is not the bufferView's byteStride " + text(parent.stride));
  if (m.mode == MeshoptView::Mode::attributes) {
    if (m.stride % 4 != 0 || m.stride == 0 || m.stride > 256)
      ext.fail("byteStride " + text(m.stride) + " of ATTRIBUTES is not a multiple of 4 up to 256");
  } else {
    if (m.stride != 2 && m.stride != 4) ext.fail("byteStride " + text(m.stride) + " of indices is not 2 or 4");
    if (m.mode == MeshoptView::Mode::triangles && m.count % 3 != 0)
      ext.fail("count " + text(m.count) + " of TRIANGLES is not a multiple of 3");
    if (m.filter != MeshoptView::Filter::none) ext.fail("indices take no filter");
  }
  if (m.filter == MeshoptView::Filter::octahedral && m.stride != 4 && m.stride != 8) ext.fail("OCTAHEDRAL needs byteStride 4 or 8");
  if (m.filter == MeshoptView::Filter::quaternion && m.stride != 8) ext.fail("QUATERNION needs byteStride 8");
  if (m.filter == MeshoptView::Filter::exponential && m.stride % 4 != 0) ext.fail("EXPONENTIAL needs a byteStride that is a multiple of 4");
  return m;
}
}  // namespace

std::uint32_t component_size(std::uint32_t component) {
  switch (component) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0;
  }
}

Document::Document(Json json) : json_(std::move(json)), root_(json_, "") {
  for (const char* name : kArrays) arrays_[name] = root_.optional_array(name);
  buffers_.resize(count("buffers"));
  views_.resize(count("bufferViews"));
  accessors_.resize(count("accessors"));
}

const std::vector<Json>* Document::top(const char* array) const {
  const auto it = arrays_.find(array);
  return it == arrays_.end() ? nullptr : it->second;
}

std::size_t Document::count(const char* array) const {
  const std::vector<Json>* a = top(array);
  return a ? a->size() : 0;
}

Object Document::item(const char* array, std::size_t index) const {
  return Object(top(array)->at(index), std::string(array) + "[" + std::to_string(index) + "]");
}

const Buffer& Document::buffer(std::size_t index) {
  std::optional<Buffer>& cached = buffers_.at(index);
  if (cached) return *cached;
  const Object o = item("buffers", index);
  Buffer b;
  b.length = o.size("byteLength");
  if (b.length == 0) o.fail("byteLength is 0");
  if (o.has("uri")) b.uri = o.string_or("uri", "");
  if (const auto ext = o.optional_object("extensions"))
    if (const auto meshopt = ext->optional_object("EXT_meshopt_compression")) b.fallback = meshopt->boolean_or("fallback", false);
  return *(cached = std::move(b));
}

const BufferView& Document::view(std::size_t index) {
  std::optional<BufferView>& cached = views_.at(index);
  if (cached) return *cached;
  const Object o = item("bufferViews", index);
  BufferView v;
  v.buffer = o.index("buffer", count("buffers"), "buffers");
  v.offset = o.size_or("byteOffset", 0);
  v.length = o.size("byteLength");
  if (v.length == 0) o.fail("byteLength is 0");
  const std::uint64_t stride = o.size_or("byteStride", 0);
  if (o.has("byteStride") && (stride < 4 || stride > 252 || stride % 4 != 0))
    o.fail("byteStride " + text(stride) + " is not a multiple of 4 from 4 to 252");
  v.stride = static_cast<std::uint32_t>(stride);
  const Buffer& b = buffer(v.buffer);
  if (!range_within(v.offset, v.length, b.length))
    o.fail(text(v.length) + " bytes from byteOffset " + text(v.offset) + " run past the " + text(b.length) + " bytes of buffers[" +
           text(v.buffer) + "]");
  if (const auto ext = o.optional_object("extensions"))
    if (const auto meshopt = ext->optional_object("EXT_meshopt_compression")) v.meshopt = meshopt_of(*meshopt, *this, v);
  return *(cached = std::move(v));
}

const Accessor& Document::accessor(std::size_t index) {
  std::optional<Accessor>& cached = accessors_.at(index);
  if (cached) return *cached;
  const Object o = item("accessors", index);
  Accessor a;
  const std::uint64_t component = o.size("componentType");
  if (component > 0xFFFF || component_size(static_cast<std::uint32_t>(component)) == 0)
    o.fail("componentType " + text(component) + " is not one of 5120, 5121, 5122, 5123, 5125, 5126");
  a.component = static_cast<std::uint32_t>(component);
  a.normalized = o.boolean_or("normalized", false);
  if (a.normalized && (a.component == kFloat || a.component == kUnsignedInt))
    o.fail("normalized is true for a componentType (" + text(a.component) + ") that cannot be normalized");
  a.count = o.size("count");
  if (a.count == 0) o.fail("count is 0");
  if (!o.has("type")) o.fail("has no type");
  a.type = o.string_or("type", "");
  a.layout = layout_of(a.type, a.component, o.where());
  a.view = o.optional_index("bufferView", count("bufferViews"), "bufferViews");
  a.offset = o.size_or("byteOffset", 0);
  a.stride = a.layout.size;
  if (a.view) {
    const BufferView& v = view(*a.view);
    if (v.stride != 0) {
      if (v.stride < a.layout.size)
        o.fail("its bufferView's byteStride " + text(v.stride) + " is less than its " + text(a.layout.size) + "-byte elements (" +
               a.type + " of componentType " + text(a.component) + ")");
      a.stride = v.stride;
    }
    const auto span = checked_product(a.stride, a.count - 1);
    const auto end = span ? checked_sum(*span, a.layout.last_size) : std::nullopt;
    if (!end || !range_within(a.offset, *end, v.length))
      o.fail(text(a.count) + " elements from byteOffset " + text(a.offset) + " do not fit the " + text(v.length) +
             " bytes of bufferViews[" + text(*a.view) + "]");
  }
  if (const auto s = o.optional_object("sparse")) {
    Sparse sp;
    sp.count = s->size("count");
    if (sp.count == 0 || sp.count > a.count)
      s->fail("count " + text(sp.count) + " is not from 1 to the accessor's count " + text(a.count));
    const Object indices = s->object("indices"), values = s->object("values");
    sp.indices_view = indices.index("bufferView", count("bufferViews"), "bufferViews");
    sp.indices_offset = indices.size_or("byteOffset", 0);
    const std::uint64_t index_component = indices.size("componentType");
    if (index_component != kUnsignedByte && index_component != kUnsignedShort && index_component != kUnsignedInt)
      indices.fail("componentType " + text(index_component) + " is not one of 5121, 5123, 5125");
    sp.indices_component = static_cast<std::uint32_t>(index_component);
    sp.values_view = values.index("bufferView", count("bufferViews"), "bufferViews");
    sp.values_offset = values.size_or("byteOffset", 0);
    const auto fits = [&](const Object& at, std::size_t view_index, std::uint64_t offset, std::uint64_t element, std::uint64_t last) {
      const BufferView& v = view(view_index);
      if (v.stride != 0) at.fail("its bufferView " + text(view_index) + " has a byteStride; sparse data is tightly packed");
      const auto span = checked_product(element, sp.count - 1);
      const auto end = span ? checked_sum(*span, last) : std::nullopt;
      if (!end || !range_within(offset, *end, v.length))
        at.fail(text(sp.count) + " elements from byteOffset " + text(offset) + " do not fit the " + text(v.length) +
                " bytes of bufferViews[" + text(view_index) + "]");
    };
    const std::uint32_t index_size = component_size(sp.indices_component);
    fits(indices, sp.indices_view, sp.indices_offset, index_size, index_size);
    fits(values, sp.values_view, sp.values_offset, a.layout.size, a.layout.last_size);
    a.sparse = sp;
  }
  return *(cached = std::move(a));
}

}  // namespace softdeca::avatar_import::gltf
