#include "gltf_accessors.h"

#include <algorithm>
#include <cstring>

namespace softdeca::avatar_import::gltf {

namespace {
std::string text(std::uint64_t n) { return std::to_string(n); }

// One component's value, little-endian whatever the machine.
double raw_component(const unsigned char* p, std::uint32_t component) {
  switch (component) {
    case kByte: return static_cast<std::int8_t>(p[0]);
    case kUnsignedByte: return p[0];
    case kShort: return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] | (p[1] << 8)));
    case kUnsignedShort: return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
    case kUnsignedInt:
    case kFloat: {
      const std::uint32_t bits =
          std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) | (std::uint32_t{p[3]} << 24);
      if (component == kUnsignedInt) return bits;
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
    default: return 0;
  }
}

double normalized_component(double c, std::uint32_t component) {
  switch (component) {
    case kByte: return std::max(c / 127.0, -1.0);
    case kUnsignedByte: return c / 255.0;
    case kShort: return std::max(c / 32767.0, -1.0);
    case kUnsignedShort: return c / 65535.0;
    default: return c;
  }
}

// Reads `count` elements from `base` (`stride` apart) into out[first element ...].
template <class T>
void read_elements(const unsigned char* base, std::uint64_t stride, std::uint64_t count, const Accessor& a, T* out) {
  const ElementLayout& l = a.layout;
  for (std::uint64_t e = 0; e < count; ++e) {
    const unsigned char* element = base + e * stride;
    for (std::uint32_t c = 0; c < l.columns; ++c)
      for (std::uint32_t r = 0; r < l.rows; ++r) {
        const double v = raw_component(element + c * l.column_stride + r * l.component_size, a.component);
        out[e * l.components + c * l.rows + r] = static_cast<T>(a.normalized ? normalized_component(v, a.component) : v);
      }
  }
}

const char* component_name(std::uint32_t component) {
  switch (component) {
    case kByte: return "byte";
    case kUnsignedByte: return "unsigned byte";
    case kShort: return "short";
    case kUnsignedShort: return "unsigned short";
    case kUnsignedInt: return "unsigned int";
    case kFloat: return "float";
    default: return "?";
  }
}
}  // namespace

template <class T>
std::vector<T> AccessorReader::decode(const Accessor& a, const std::string& where) {
  const auto values = checked_product(a.count, a.layout.components);
  const auto bytes = values ? checked_product(*values, sizeof(T)) : std::nullopt;
  if (!bytes) throw Problem(where, "too many values");
  budget_.take(*bytes, where);
  std::vector<T> out(static_cast<std::size_t>(*values), T{});
  if (a.view) {
    const std::string_view view = data_.view(*a.view);
    read_elements(reinterpret_cast<const unsigned char*>(view.data()) + a.offset, a.stride, a.count, a, out.data());
  }
  if (a.sparse) {
    const Sparse& s = *a.sparse;
    const std::string_view index_view = data_.view(s.indices_view), value_view = data_.view(s.values_view);
    const auto* indices = reinterpret_cast<const unsigned char*>(index_view.data()) + s.indices_offset;
    const auto* values_at = reinterpret_cast<const unsigned char*>(value_view.data()) + s.values_offset;
    const std::uint32_t index_size = component_size(s.indices_component);
    std::uint64_t previous = 0;
    for (std::uint64_t i = 0; i < s.count; ++i) {
      const auto target = static_cast<std::uint64_t>(raw_component(indices + i * index_size, s.indices_component));
      if (target >= a.count)
        throw Problem(where, "its sparse index " + text(target) + " (number " + text(i) + ") is not below its count " + text(a.count));
      if (i > 0 && target <= previous)
        throw Problem(where, "its sparse indices are not increasing (" + text(target) + " after " + text(previous) + ")");
      previous = target;
      read_elements(values_at + i * a.layout.size, a.layout.size, 1, a, out.data() + target * a.layout.components);
    }
  }
  return out;
}

std::vector<float> AccessorReader::floats(std::size_t index, const char* type, bool float_only, const std::string& use) {
  const std::string where = "accessors[" + text(index) + "]" + (use.empty() ? "" : " (" + use + ")");
  const Accessor& a = doc_.accessor(index);
  if (a.type != type) throw Problem(where, "is " + a.type + ", not " + type);
  if (a.component == kUnsignedInt || (float_only && a.component != kFloat))
    throw Problem(where, std::string("has ") + component_name(a.component) + " components, which it may not have");
  return decode<float>(a, where);
}

std::vector<std::uint32_t> AccessorReader::indices(std::size_t index, const std::string& use) {
  const std::string where = "accessors[" + text(index) + "]" + (use.empty() ? "" : " (" + use + ")");
  const Accessor& a = doc_.accessor(index);
  if (a.type != "SCALAR") throw Problem(where, "is " + a.type + ", not SCALAR");
  if (a.normalized || (a.component != kUnsignedByte && a.component != kUnsignedShort && a.component != kUnsignedInt))
    throw Problem(where, std::string("has ") + (a.normalized ? "normalized " : "") + component_name(a.component) +
                             " components; indices are unsigned byte, short or int");
  return decode<std::uint32_t>(a, where);
}

}  // namespace softdeca::avatar_import::gltf
