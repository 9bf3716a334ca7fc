#include "bundle/onnx_model_scan.h"

#include <cstring>
#include <map>

#include "bundle/onnx_graph.h"
#include "bundle/onnx_operators.h"
#include "bundle/onnx_static_sizes.h"
#include "core/error.h"

namespace softdeca::bundle {
namespace {

using namespace onnx;

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
  explicit Message(const Field& f) : Message(f.data, f.size) {}

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
  const std::uint8_t* p = f.data;
  const std::uint8_t* end = f.data + f.size;
  while (p != end) {
    std::uint64_t v = 0;
    for (int shift = 0;; shift += 7) {
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

// A message field that protobuf would merge when given twice: refused instead (a tensor or a
// type split over two fields would read differently here and in ONNX Runtime).
void once(bool& seen, const char* what) {
  if (seen) bad(std::string(what) + " is given twice");
  seen = true;
}

// Little-endian integers of `width` bytes, sign-extended for signed types.
std::vector<std::int64_t> little_endian(const Field& raw, std::int64_t dtype) {
  const std::size_t width = static_cast<std::size_t>(element_size(dtype));
  std::vector<std::int64_t> out;
  if (raw.size % width != 0 || raw.size / width > kMaxValues) return out;
  const bool is_signed = dtype == kInt8 || dtype == kInt16 || dtype == kInt32 || dtype == kInt64;
  for (std::size_t i = 0; i < raw.size; i += width) {
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < width; ++k) v |= std::uint64_t{raw.data[i + k]} << (8 * k);
    if (is_signed && width < 8 && (v >> (8 * width - 1)) & 1) v |= ~std::uint64_t{0} << (8 * width);
    if (!is_signed && width == 8 && v >> 63) return {};  // a uint64 past int64: not carried
    out.push_back(static_cast<std::int64_t>(v));
  }
  return out;
}

class Reader {
 public:
  Graph graph;
  std::vector<std::string> external;  // tensors with external data (initializers or attributes)

  void model(const std::uint8_t* data, std::size_t size) {
    Message m(data, size);
    Field f;
    bool opset = false;
    while (m.next(f)) {
      if (f.wire != 2) continue;
      switch (f.number) {
        case 7: read_graph(f); break;  // given twice, protobuf merges the graphs: so does this
        case 8: opset = opset_import(f) || opset; break;
        case 20: bad("the model holds training information; a bundle's networks hold inference graphs only");
        case 25: bad("the model defines functions; a bundle's networks use the listed operators only (docs/bundle.md)");
        default: break;
      }
    }
    if (!opset) bad("the model imports no version of the ONNX operator set (a bundle's networks use opset " +
                    std::to_string(kOpsetVersion) + ")");
  }

 private:
  static bool default_domain(const std::string& d) { return d.empty() || d == "ai.onnx"; }

  // OperatorSetIdProto: domain (1), version (2). True for the default domain.
  static bool opset_import(const Field& f) {
    std::string domain;
    std::int64_t version = 0;
    Message m(f);
    Field x;
    while (m.next(x)) {
      if (x.number == 1) domain = text(x);
      else if (x.number == 2 && x.wire == 0) version = static_cast<std::int64_t>(x.varint);
    }
    if (!default_domain(domain))
      bad("the model imports the operator set '" + printable(domain) + "'; a bundle's networks use ONNX's own only");
    if (version != kOpsetVersion)
      bad("the model imports ONNX opset " + std::to_string(version) + "; a bundle's networks use opset " +
          std::to_string(kOpsetVersion));
    return true;
  }

  void read_graph(const Field& f) {
    Message m(f);
    Field g;
    while (m.next(g)) {
      if (g.wire != 2) continue;
      switch (g.number) {
        case 1: node(g); break;
        case 5: {
          Initializer i;
          i.tensor = tensor(g, i.name);
          graph.initializers.push_back(std::move(i));
          break;
        }
        case 11: input(g); break;
        case 15: bad("the graph has a sparse initializer; a bundle's networks store dense tensors only");
        default: break;  // outputs, value_info, annotations: the shapes are inferred instead
      }
    }
  }

  // TensorProto: its type and dims, and the values of a short integer tensor; its name.
  Tensor tensor(const Field& f, std::string& name) {
    Tensor t;
    bool outside = false;
    t.dtype = 0;
    std::vector<std::int64_t> listed;
    bool too_many = false;
    Field raw;
    Message m(f);
    Field x;
    while (m.next(x)) {
      switch (x.number) {
        case 1:
          repeated_varints(x, [&](std::uint64_t d) {
            if (static_cast<std::int64_t>(d) < 0) bad("a tensor with a negative dimension");
            if (t.dims.size() == kMaxRank) bad("a tensor of more than " + std::to_string(kMaxRank) + " dimensions");
            t.dims.push_back(d);
          });
          break;
        case 2: if (x.wire == 0) t.dtype = static_cast<std::int64_t>(x.varint); break;
        case 3: bad("a tensor in segments");
        case 5: case 7: case 11:  // int32_data, int64_data, uint64_data
          repeated_varints(x, [&](std::uint64_t v) {
            if (listed.size() == kMaxValues) too_many = true;
            else listed.push_back(x.number == 5 ? static_cast<std::int32_t>(v) : static_cast<std::int64_t>(v));
          });
          break;
        case 8: name = text(x); break;
        case 9: if (x.wire == 2) raw = x; break;
        case 13: outside = true; break;                      // external_data entries
        case 14: if (x.varint == 1) outside = true; break;   // data_location = EXTERNAL
        default: break;
      }
    }
    if (outside) external.push_back(name.empty() ? std::string("(unnamed)") : name);
    const std::string id = name.empty() ? "" : " '" + printable(name) + "'";
    if (element_size(t.dtype) == 0)
      bad("tensor" + id + " has element type " + std::to_string(t.dtype) + ", which no network uses");
    if (is_integer(t.dtype) && t.elements() <= kMaxValues) {
      std::vector<std::int64_t> values = raw.data ? little_endian(raw, t.dtype) : too_many ? std::vector<std::int64_t>{} : listed;
      if (values.size() == t.elements()) {
        if (t.dtype == kUint64) {
          for (const std::int64_t v : values)
            if (v < 0) values.clear();  // past int64: not carried
        }
        t.values = std::move(values);
        t.known = t.values.size() == t.elements();
        for (const std::int64_t v : t.values) t.known = t.known && holds(t.dtype, v);
        if (!t.known) t.values.clear();
      }
    }
    return t;
  }

  // ValueInfoProto of a graph input: its name and, for a tensor type, the element type (its
  // dimensions are the contract's, as the runtime feeds them).
  void input(const Field& f) {
    GraphInput in;
    bool typed = false;
    Message m(f);
    Field v;
    while (m.next(v)) {
      if (v.number == 1) in.name = text(v);
      if (v.number != 2 || v.wire != 2) continue;
      once(typed, "an input's type");
      Message type(v);
      Field t;
      bool tensor_type = false;
      while (type.next(t)) {
        if (t.wire != 2) continue;
        if (t.number != 1) {  // sequence, map, sparse, optional...
          in.dtype = 0;
          continue;
        }
        once(tensor_type, "an input's tensor type");
        Message tt(t);
        Field e;
        while (tt.next(e))
          if (e.number == 1 && e.wire == 0) in.dtype = static_cast<std::int64_t>(e.varint);
      }
    }
    graph.inputs.push_back(std::move(in));
  }

  void node(const Field& f) {
    Node n;
    std::string overload;
    std::vector<Field> attributes;  // read once the operator is known to be listed
    Message m(f);
    Field x;
    while (m.next(x)) {
      switch (x.number) {
        case 1: n.inputs.push_back(text(x)); break;
        case 2: n.outputs.push_back(text(x)); break;
        case 3: n.name = text(x); break;
        case 4: n.op = text(x); break;
        case 5: if (x.wire == 2) attributes.push_back(x); break;
        case 7: n.domain = text(x); break;
        case 8: overload = text(x); break;
        default: break;
      }
    }
    if (!default_domain(n.domain))
      bad("operator '" + printable(n.op) + "' of domain '" + printable(n.domain) + "' (" + n.label() +
          ") is not one a bundle's networks may use (docs/bundle.md, \"Operators\")");
    if (!is_allowed_operator(n.op))
      bad("operator '" + printable(n.op) + "' (" + n.label() +
          ") is not one a bundle's networks may use (docs/bundle.md, \"Operators\")");
    if (!overload.empty()) bad(n.label() + " names a function overload");
    for (const Field& a : attributes) attribute(a, n);
    graph.nodes.push_back(std::move(n));
  }

  // AttributeProto: name (1), f (2), i (3), s (4), t (5), floats (7), ints (8), type (20). The
  // other kinds (graphs, tensor lists, sparse tensors, type protos, references to a
  // function's attributes) are not taken by any listed operator.
  void attribute(const Field& f, Node& node) {
    std::string name, tensor_name;
    Attribute a;
    std::uint64_t declared = 0;  // AttributeType, when given
    int present = -1;            // the kind its fields say, the last one given
    bool has_t = false;
    Message m(f);
    Field x;
    while (m.next(x)) {
      switch (x.number) {
        case 1: name = text(x); break;
        case 2: if (x.wire == 5) present = Attribute::kFloat; break;
        case 3: if (x.wire == 0) { a.i = static_cast<std::int64_t>(x.varint); present = Attribute::kInt; } break;
        case 4: a.s = text(x); present = Attribute::kString; break;
        case 5:
          if (x.wire != 2) break;
          once(has_t, "an attribute's tensor");
          a.t = tensor(x, tensor_name);
          present = Attribute::kTensor;
          break;
        case 7:
          if (x.wire == 2) a.floats += x.size / 4;
          else if (x.wire == 5) ++a.floats;
          present = Attribute::kFloats;
          break;
        case 8:
          repeated_varints(x, [&](std::uint64_t v) {
            if (a.ints.size() == kMaxValues) bad("attribute '" + printable(name) + "' lists over " + std::to_string(kMaxValues) + " integers");
            a.ints.push_back(static_cast<std::int64_t>(v));
          });
          present = Attribute::kInts;
          break;
        case 20: if (x.wire == 0) declared = x.varint; break;
        case 6: case 11: bad(node.label() + " holds a subgraph; a bundle's networks have none");
        case 9: case 10: case 14: case 15: case 21: case 22: case 23:
          bad("attribute '" + printable(name) + "' of " + node.label() + " is of a kind no listed operator takes");
        default: break;
      }
    }
    switch (declared) {  // AttributeProto.AttributeType
      case 0: break;
      case 1: present = Attribute::kFloat; break;
      case 2: present = Attribute::kInt; break;
      case 3: present = Attribute::kString; break;
      case 4: present = Attribute::kTensor; break;
      case 6: present = Attribute::kFloats; break;
      case 7: present = Attribute::kInts; break;
      default: bad("attribute '" + printable(name) + "' of " + node.label() + " is of a kind no listed operator takes");
    }
    if (present < 0) bad("attribute '" + printable(name) + "' of " + node.label() + " has no value");
    if (present == Attribute::kTensor && !has_t) bad("attribute '" + printable(name) + "' of " + node.label() + " has no tensor");
    a.kind = static_cast<Attribute::Kind>(present);
    if (!node.attributes.emplace(name, std::move(a)).second)
      bad(node.label() + " has attribute '" + printable(name) + "' twice");
  }
};

}  // namespace

OnnxModelScan scan_onnx_model(const std::uint8_t* data, std::size_t size, const std::vector<TensorSpec>& inputs) {
  Reader r;
  r.model(data, size);
  OnnxModelScan scan;
  scan.external_tensors = r.external;
  if (!scan.external_tensors.empty()) return scan;
  std::map<std::string, std::vector<std::uint64_t>> fed;
  for (const TensorSpec& t : inputs) {
    std::vector<std::uint64_t>& dims = fed[t.name];
    for (const std::int64_t d : t.shape) dims.push_back(static_cast<std::uint64_t>(d < 0 ? kFedBatch : d));
  }
  for (const Initializer& i : r.graph.initializers) scan.weight_bytes = add_sat(scan.weight_bytes, i.tensor.bytes());
  for (const Node& node : r.graph.nodes)
    for (const auto& [name, a] : node.attributes)
      if (a.kind == Attribute::kTensor) scan.weight_bytes = add_sat(scan.weight_bytes, a.t.bytes());
  try {
    const StaticSizes s = static_sizes(r.graph, fed);
    scan.bytes = s.bytes;
    scan.largest_tensor = s.largest;
    scan.largest_bytes = s.largest_bytes;
    scan.tensors = s.tensors;
  } catch (const Error& e) {
    bad(e.what());
  }
  return scan;
}

}  // namespace softdeca::bundle
