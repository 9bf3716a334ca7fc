#include "bundle/onnx_model_scan.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>

#include "bundle/onnx_constant_sizes.h"
#include "core/error.h"

namespace softdeca::runtime {
namespace {

constexpr int kMaxDepth = 32;
constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
constexpr std::size_t kMaxShapeValues = 16;  // shape tensors longer than this are not shapes

std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; }
std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) { return a != 0 && b > kMax / a ? kMax : a * b; }

[[noreturn]] void bad(const std::string& why) { throw Error(SOFTDECA_ERROR_FORMAT, "ONNX model: " + why); }

// One protobuf message's fields, in order (wire format only; field meaning is the caller's).
struct Field {
  std::uint32_t number = 0;
  int wire = 0;
  std::uint64_t varint = 0;  // wire 0 (and fixed 1/5 values)
  const std::uint8_t* data = nullptr;  // wire 2
  std::size_t size = 0;
};

class Message {
 public:
  Message(const std::uint8_t* data, std::size_t size) : p_(data), end_(data + size) {}

  bool next(Field& f) {
    if (p_ == end_) return false;
    const std::uint64_t key = varint();
    f.number = static_cast<std::uint32_t>(key >> 3);
    f.wire = static_cast<int>(key & 7);
    if (f.number == 0 || key >> 32) bad("bad field key");
    switch (f.wire) {
      case 0: f.varint = varint(); break;
      case 1: f.varint = fixed(8); break;
      case 5: f.varint = fixed(4); break;
      case 2: {
        const std::uint64_t n = varint();
        if (n > static_cast<std::uint64_t>(end_ - p_)) bad("a field runs past the end");
        f.data = p_;
        f.size = static_cast<std::size_t>(n);
        p_ += n;
        break;
      }
      default: bad("unsupported wire type " + std::to_string(f.wire));
    }
    return true;
  }

 private:
  std::uint64_t varint() {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 70; shift += 7) {
      if (p_ == end_) bad("truncated varint");
      const std::uint8_t b = *p_++;
      if (shift == 63 && b > 1) bad("varint overflows 64 bits");
      v |= std::uint64_t{b & 0x7Fu} << shift;
      if (!(b & 0x80)) return v;
    }
    bad("varint longer than 10 bytes");
  }
  std::uint64_t fixed(int n) {
    if (end_ - p_ < n) bad("truncated fixed-width field");
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t{p_[i]} << (8 * i);
    p_ += n;
    return v;
  }
  const std::uint8_t* p_;
  const std::uint8_t* end_;
};

// Integers of a repeated int64 field, packed (wire 2) or one per field (wire 0).
template <class Sink>
void repeated_varints(const Field& f, Sink&& sink) {
  if (f.wire == 0) {
    sink(f.varint);
    return;
  }
  if (f.wire != 2) bad("a repeated integer field has the wrong wire type");
  // Packed: a message of consecutive varints; reuse the reader with key-less parsing.
  const std::uint8_t* p = f.data;
  const std::uint8_t* end = f.data + f.size;
  while (p != end) {
    std::uint64_t v = 0;
    int shift = 0;
    for (;; shift += 7) {
      if (p == end || shift >= 70) bad("bad packed varint");
      const std::uint8_t b = *p++;
      v |= std::uint64_t{b & 0x7Fu} << shift;
      if (!(b & 0x80)) break;
    }
    sink(v);
  }
}

std::string text(const Field& f) {
  if (f.wire != 2) bad("a string field has the wrong wire type");
  return std::string(reinterpret_cast<const char*>(f.data), f.size);
}

std::uint64_t element_size(std::uint64_t dtype) {
  switch (dtype) {
    case 2: case 3: case 9: case 17: case 18: case 19: case 20: case 21: case 22: return 1;  // 8-bit, bool, fp8, int4
    case 4: case 5: case 10: case 16: return 2;                                          // 16-bit
    case 1: case 6: case 12: return 4;                                                   // float, int32, uint32
    case 7: case 11: case 13: case 14: return 8;                                         // 64-bit, complex64
    case 15: return 16;                                                                  // complex128
    default: return 32;                                                                  // strings, unknown
  }
}

struct Tensor {
  std::string name;
  std::uint64_t dtype = 1;
  std::uint64_t elements = 1;
  std::vector<std::uint64_t> dims;
  bool external = false;
  std::vector<double> values;  // short numeric tensors (float, double, int32, int64): possible shapes
};

// Little-endian numbers of `width` bytes as the tensor's type says (raw_data, packed fields).
void little_endian_values(const std::uint8_t* p, std::size_t size, std::uint64_t dtype, std::vector<double>& out) {
  const std::size_t width = dtype == 7 || dtype == 11 ? 8 : 4;
  if (size % width != 0 || size / width > kMaxShapeValues) return;
  out.clear();
  for (std::size_t i = 0; i < size; i += width) {
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < width; ++k) v |= std::uint64_t{p[i + k]} << (8 * k);
    if (dtype == 1) {
      float f;
      const auto u = static_cast<std::uint32_t>(v);
      std::memcpy(&f, &u, 4);
      out.push_back(f);
    } else if (dtype == 11) {
      double d;
      std::memcpy(&d, &v, 8);
      out.push_back(d);
    } else if (dtype == 6) {
      out.push_back(static_cast<double>(static_cast<std::int32_t>(static_cast<std::uint32_t>(v))));
    } else {
      out.push_back(static_cast<double>(static_cast<std::int64_t>(v)));
    }
  }
}

class Scanner {
 public:
  OnnxModelScan result;

  void model(const std::uint8_t* data, std::size_t size) {
    Message m(data, size);
    Field f;
    while (m.next(f)) {
      if (f.wire != 2) continue;
      if (f.number == 7) graph(f, 1);
      else if (f.number == 20) training_info(f, 1);
      else if (f.number == 25) function(f, 1);
    }
    // Outputs whose size follows from constants (computed at run time otherwise: ONNX
    // Runtime's own checks).
    folding_.evaluate([&](const std::string& name, std::uint64_t bytes) {
      result.shaped_bytes = add_sat(result.shaped_bytes, bytes);
      note(name, bytes);
    });
  }

 private:
  ConstantSizes folding_;

  static void depth_check(int depth) {
    if (depth > kMaxDepth) bad("messages nested deeper than " + std::to_string(kMaxDepth));
  }
  void note(const std::string& name, std::uint64_t bytes) {
    ++result.tensors;
    if (bytes > result.largest_bytes || result.largest_tensor.empty()) {
      result.largest_bytes = bytes;
      result.largest_tensor = name;
    }
  }

  void training_info(const Field& f, int depth) {
    depth_check(depth);
    Message m(f.data, f.size);
    Field g;
    while (m.next(g))
      if (g.wire == 2 && (g.number == 1 || g.number == 2)) graph(g, depth + 1);
  }

  void function(const Field& f, int depth) {
    depth_check(depth);
    Message m(f.data, f.size);
    Field n;
    while (m.next(n))
      if (n.wire == 2 && n.number == 7) node(n, depth + 1);
  }

  void graph(const Field& f, int depth) {
    depth_check(depth);
    Message m(f.data, f.size);
    Field g;
    while (m.next(g)) {
      if (g.wire != 2) continue;
      switch (g.number) {
        case 1: node(g, depth + 1); break;
        case 5: initializer(tensor(g, depth + 1)); break;
        case 15: sparse_tensor(g, depth + 1); break;
        case 11: case 12: case 13: value_info(g, depth + 1); break;
        default: break;
      }
    }
  }

  void initializer(const Tensor& t) {
    if (t.external) result.external_tensors.push_back(t.name.empty() ? std::string("(unnamed)") : t.name);
    const std::uint64_t bytes = mul_sat(t.elements, element_size(t.dtype));
    result.initializer_bytes = add_sat(result.initializer_bytes, bytes);
    note(t.name, bytes);
    if (t.name.empty()) return;
    if (!t.values.empty()) folding_.values(t.name, t.values);
    folding_.shape(t.name, t.dims, element_size(t.dtype));
  }

  void sparse_tensor(const Field& f, int depth) {
    depth_check(depth);
    Message m(f.data, f.size);
    Field s;
    while (m.next(s))
      if (s.wire == 2 && (s.number == 1 || s.number == 2)) initializer(tensor(s, depth + 1));
  }

  Tensor tensor(const Field& f, int depth) {
    depth_check(depth);
    Tensor t;
    bool has_dims = false;
    std::vector<double> numbers;
    Field raw;
    Message m(f.data, f.size);
    Field x;
    while (m.next(x)) {
      switch (x.number) {
        case 1:
          has_dims = true;
          repeated_varints(x, [&](std::uint64_t d) {
            if (static_cast<std::int64_t>(d) < 0) bad("tensor with a negative dimension");
            t.elements = mul_sat(t.elements, d);
            if (t.dims.size() < kMaxShapeValues) t.dims.push_back(d);
          });
          break;
        case 2: if (x.wire == 0) t.dtype = x.varint; break;
        case 5: case 7:  // int32_data, int64_data: varints
          repeated_varints(x, [&](std::uint64_t v) {
            if (numbers.size() <= kMaxShapeValues)
              numbers.push_back(x.number == 5 ? double(static_cast<std::int32_t>(v)) : double(static_cast<std::int64_t>(v)));
          });
          break;
        case 4: case 10:  // float_data, double_data: packed fixed-width
          if (x.wire == 2) little_endian_values(x.data, x.size, x.number == 4 ? 1 : 11, numbers);
          break;
        case 8: t.name = text(x); break;
        case 9:
          if (x.wire == 2) raw = x;  // decoded once the type is known
          break;
        case 13: t.external = true; break;                      // external_data entries
        case 14: if (x.varint == 1) t.external = true; break;   // data_location = EXTERNAL
        default: break;
      }
    }
    if (!has_dims) t.elements = 1;  // a scalar
    if (raw.data) little_endian_values(raw.data, raw.size, t.dtype, numbers);
    const bool numeric = t.dtype == 1 || t.dtype == 6 || t.dtype == 7 || t.dtype == 11;
    if (numeric && numbers.size() <= kMaxShapeValues && numbers.size() == t.elements) t.values = std::move(numbers);
    return t;
  }

  void value_info(const Field& f, int depth) {
    depth_check(depth);
    std::string name;
    std::uint64_t bytes = 0;
    StaticShape shape;
    Message m(f.data, f.size);
    Field v;
    while (m.next(v)) {
      if (v.number == 1) name = text(v);
      else if (v.number == 2 && v.wire == 2) bytes = type_bytes(v, depth + 1, shape);
    }
    result.declared_bytes = add_sat(result.declared_bytes, bytes);
    note(name, bytes);
    if (shape.is_static && !name.empty()) folding_.shape(name, shape.dims, shape.element_bytes);
  }

  struct StaticShape {
    bool is_static = false;  // a tensor type whose every dimension is a number
    std::vector<std::uint64_t> dims;
    std::uint64_t element_bytes = 4;
  };

  // TypeProto: tensor_type (1) and sparse_tensor_type (8) have elem_type (1) and shape (2).
  std::uint64_t type_bytes(const Field& f, int depth, StaticShape& static_shape) {
    depth_check(depth);
    Message m(f.data, f.size);
    Field t;
    std::uint64_t bytes = 0;
    while (m.next(t)) {
      if (t.wire != 2 || (t.number != 1 && t.number != 8)) continue;
      std::uint64_t dtype = 1, elements = 1;
      bool has_shape = false, all_numbers = true;
      std::vector<std::uint64_t> dims;
      Message tensor_type(t.data, t.size);
      Field x;
      while (tensor_type.next(x)) {
        if (x.number == 1 && x.wire == 0) dtype = x.varint;
        if (x.number != 2 || x.wire != 2) continue;
        has_shape = true;
        Message shape(x.data, x.size);
        Field dim;
        while (shape.next(dim)) {
          if (dim.number != 1 || dim.wire != 2) continue;
          std::uint64_t value = 1;  // dim_param (a named free dimension): counted as 1
          bool number = false;
          Message d(dim.data, dim.size);
          Field dv;
          while (d.next(dv))
            if (dv.number == 1 && dv.wire == 0 && static_cast<std::int64_t>(dv.varint) >= 0) {
              value = std::max<std::uint64_t>(dv.varint, 1);
              number = true;
            }
          all_numbers = all_numbers && number;
          elements = mul_sat(elements, value);
          if (dims.size() < kMaxShapeValues) dims.push_back(value);
          else all_numbers = false;
        }
      }
      bytes = add_sat(bytes, mul_sat(elements, element_size(dtype)));
      if (t.number == 1 && has_shape && all_numbers) static_shape = {true, std::move(dims), element_size(dtype)};
    }
    return bytes;
  }

  // Nodes go to the constant folding (onnx_constant_sizes.h), evaluated in order at the end.
  void node(const Field& f, int depth) {
    depth_check(depth);
    FoldNode n;
    Message m(f.data, f.size);
    Field x;
    while (m.next(x)) {
      switch (x.number) {
        case 1: n.inputs.push_back(text(x)); break;
        case 2: n.outputs.push_back(text(x)); break;
        case 4: n.op = text(x); break;
        case 5:
          if (x.wire == 2) attribute(x, depth + 1, n);
          break;
        default: break;
      }
    }
    folding_.node(std::move(n));
  }

  // AttributeProto: name (1), ints (8), t (5), g (6), tensors (10), graphs (11),
  // sparse_tensor (22), sparse_tensors (23). Every tensor counts as an initializer.
  // A node's integer attributes (i: 3), and a Constant's value however it is given: value
  // (a tensor), value_int(s), value_float(s) (f: 2, floats: 7).
  void attribute(const Field& f, int depth, FoldNode& node) {
    depth_check(depth);
    std::string name;
    std::vector<double> ints, floats;
    bool value_tensor = false, has_int = false, has_float = false;
    std::int64_t i = 0;
    Tensor t;
    Message m(f.data, f.size);
    Field x;
    while (m.next(x)) {
      switch (x.number) {
        case 1: name = text(x); break;
        case 2:
          if (x.wire == 5) {
            const auto u = static_cast<std::uint32_t>(x.varint);
            float v;
            std::memcpy(&v, &u, 4);
            floats.assign(1, v);
            has_float = true;
          }
          break;
        case 3:
          if (x.wire == 0) {
            i = static_cast<std::int64_t>(x.varint);
            has_int = true;
          }
          break;
        case 7:
          if (x.wire == 2) little_endian_values(x.data, x.size, 1, floats);
          break;
        case 8:
          repeated_varints(x, [&](std::uint64_t v) {
            if (ints.size() <= kMaxShapeValues) ints.push_back(double(static_cast<std::int64_t>(v)));
          });
          break;
        case 5:
          if (x.wire == 2) {
            t = tensor(x, depth + 1);
            initializer(t);
            value_tensor = true;
          }
          break;
        case 10: if (x.wire == 2) initializer(tensor(x, depth + 1)); break;
        case 6: case 11: if (x.wire == 2) graph(x, depth + 1); break;
        case 22: case 23: if (x.wire == 2) sparse_tensor(x, depth + 1); break;
        default: break;
      }
    }
    if (has_int) node.ints[name] = i;
    const auto constant = [&](std::vector<double> v, std::vector<std::uint64_t> dims, std::uint64_t bytes) {
      node.has_value = v.size() <= kMaxShapeValues;
      node.value = std::move(v);
      node.value_dims = std::move(dims);
      node.value_element_bytes = bytes;
    };
    if (name == "value" && value_tensor) {
      node.value_element_bytes = element_size(t.dtype);
      node.value_dims = t.dims;
      if (!t.values.empty()) constant(t.values, t.dims, element_size(t.dtype));
    }
    if (name == "value_int" && has_int) constant({double(i)}, {}, 8);
    if (name == "value_ints" && ints.size() <= kMaxShapeValues) constant(ints, {ints.size()}, 8);
    if (name == "value_float" && has_float) constant(floats, {}, 4);
    if (name == "value_floats" && !floats.empty()) constant(floats, {floats.size()}, 4);
  }
};

}  // namespace

std::uint64_t OnnxModelScan::total_bytes() const {
  return add_sat(add_sat(initializer_bytes, declared_bytes), shaped_bytes);
}

OnnxModelScan scan_onnx_model(const std::uint8_t* data, std::size_t size) {
  Scanner s;
  s.model(data, size);
  return std::move(s.result);
}

}  // namespace softdeca::runtime
