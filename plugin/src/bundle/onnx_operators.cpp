// The operator allow-list and each operator's static shape rule (onnx_operators.h).
// Kept whole: one table, each operator beside its rule, so none is allowed without one.
#include "bundle/onnx_operators.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <set>

#include "core/error.h"

namespace softdeca::bundle::onnx {
namespace {

using Dims = std::vector<std::uint64_t>;
using Inputs = std::vector<const Tensor*>;
using Values = std::vector<std::int64_t>;
constexpr std::int64_t kMin64 = std::numeric_limits<std::int64_t>::min();
constexpr std::int64_t kMax64 = std::numeric_limits<std::int64_t>::max();

[[noreturn]] void refuse(const std::string& why) { throw Error(SOFTDECA_ERROR_FORMAT, why); }

std::string text(const Dims& dims) {
  std::string t = "[";
  for (std::size_t i = 0; i < dims.size(); ++i) t += (i ? ", " : "") + std::to_string(dims[i]);
  return t + "]";
}

// ---- attributes ----------------------------------------------------------------------------

const Attribute* attribute(const Node& n, const std::string& name, Attribute::Kind kind) {
  const auto it = n.attributes.find(name);
  if (it == n.attributes.end()) return nullptr;
  if (it->second.kind != kind) refuse("attribute '" + name + "' is of the wrong kind");
  return &it->second;
}
std::int64_t int_attribute(const Node& n, const std::string& name, std::int64_t fallback) {
  const Attribute* a = attribute(n, name, Attribute::kInt);
  return a ? a->i : fallback;
}

// ---- values ---------------------------------------------------------------------------------

// The values of an input that decides the output's shape: they must be known at load.
const Values& deciding_values(const Tensor* t, const std::string& what) {
  if (!t->known)
    refuse(what + " is computed from values not known at load (every shape of a bundle's network must be static)");
  if (t->dims.size() > 1) refuse(what + " is not a vector");
  return t->values;
}

// Sets `t`'s values where they are short, of an integer type and held by it.
void set_values(Tensor& t, Values v) {
  t.known = false;
  t.values.clear();
  if (!is_integer(t.dtype) || v.size() > kMaxValues || v.size() != t.elements()) return;
  for (const std::int64_t x : v)
    if (!holds(t.dtype, x)) return;
  t.values = std::move(v);
  t.known = true;
}

bool add(std::int64_t a, std::int64_t b, std::int64_t& r) {
  if ((b > 0 && a > kMax64 - b) || (b < 0 && a < kMin64 - b)) return false;
  r = a + b;
  return true;
}
bool sub(std::int64_t a, std::int64_t b, std::int64_t& r) {
  if ((b < 0 && a > kMax64 + b) || (b > 0 && a < kMin64 + b)) return false;
  r = a - b;
  return true;
}
bool mul(std::int64_t a, std::int64_t b, std::int64_t& r) {
  if (a != 0 && b != 0) {
    const bool over = a > 0 ? (b > 0 ? a > kMax64 / b : b < kMin64 / a) : (b > 0 ? a < kMin64 / b : b < kMax64 / a);
    if (over) return false;
  }
  r = a * b;
  return true;
}
bool div(std::int64_t a, std::int64_t b, std::int64_t& r) {
  if (b == 0 || (a == kMin64 && b == -1)) return false;
  r = a / b;  // truncated, as ONNX Runtime divides integers
  return true;
}

// Row-major strides of `dims`, for index arithmetic on short tensors.
std::vector<std::uint64_t> strides(const Dims& dims) {
  std::vector<std::uint64_t> s(dims.size(), 1);
  for (std::size_t i = dims.size(); i-- > 1;) s[i - 1] = s[i] * dims[i];
  return s;
}
// For every element of `out`, the element of `in` that broadcasting reads.
std::vector<std::size_t> broadcast_sources(const Dims& out, const Dims& in) {
  const std::vector<std::uint64_t> out_strides = strides(out), in_strides = strides(in);
  const std::size_t lead = out.size() - in.size();
  const std::uint64_t n = Tensor{kInt64, out}.elements();
  std::vector<std::size_t> src(static_cast<std::size_t>(n));
  for (std::uint64_t flat = 0; flat < n; ++flat) {
    std::uint64_t rest = flat, at = 0;
    for (std::size_t d = 0; d < out.size(); ++d) {
      const std::uint64_t i = rest / out_strides[d];
      rest %= out_strides[d];
      if (d >= lead && in[d - lead] != 1) at += i * in_strides[d - lead];
    }
    src[static_cast<std::size_t>(flat)] = static_cast<std::size_t>(at);
  }
  return src;
}

// ---- shapes ---------------------------------------------------------------------------------

Dims broadcast(const Dims& a, const Dims& b) {
  Dims out = a.size() >= b.size() ? a : b;
  const Dims& shorter = a.size() >= b.size() ? b : a;
  for (std::size_t i = 0; i < shorter.size(); ++i) {
    std::uint64_t& d = out[out.size() - shorter.size() + i];
    const std::uint64_t s = shorter[i];
    if (d == s || s == 1) continue;
    if (d != 1) refuse("shapes " + text(a) + " and " + text(b) + " do not broadcast");
    d = s;
  }
  return out;
}

std::size_t axis_of(std::int64_t axis, std::size_t rank, const std::string& what) {
  const auto r = static_cast<std::int64_t>(rank);
  if (axis < -r || axis >= r) refuse(what + " " + std::to_string(axis) + " is outside a tensor of rank " + std::to_string(rank));
  return static_cast<std::size_t>(axis < 0 ? axis + r : axis);
}
// Distinct axes of a tensor of rank `rank`.
std::vector<bool> axes_of(const Values& axes, std::size_t rank) {
  std::vector<bool> on(rank, false);
  for (const std::int64_t a : axes) {
    const std::size_t i = axis_of(a, rank, "axis");
    if (on[i]) refuse("axis " + std::to_string(a) + " is given twice");
    on[i] = true;
  }
  return on;
}
Dims dims_of(const Values& v, const std::string& what) {
  if (v.size() > kMaxRank) refuse(what + " has more than " + std::to_string(kMaxRank) + " dimensions");
  Dims dims;
  for (const std::int64_t x : v) {
    if (x < 0) refuse(what + " has a negative dimension " + std::to_string(x));
    dims.push_back(static_cast<std::uint64_t>(x));
  }
  return dims;
}

// ---- the rules --------------------------------------------------------------------------------

Tensor like_input(const Node&, const Inputs& in) {
  Tensor t{in[0]->dtype, in[0]->dims};
  return t;
}

Tensor identity(const Node&, const Inputs& in) { return *in[0]; }

Tensor negate(const Node&, const Inputs& in) {
  Tensor t{in[0]->dtype, in[0]->dims};
  if (!in[0]->known) return t;
  Values v;
  for (const std::int64_t x : in[0]->values) {
    std::int64_t r;
    if (!sub(0, x, r)) return t;
    v.push_back(r);
  }
  set_values(t, std::move(v));
  return t;
}

Tensor cast(const Node& n, const Inputs& in) {
  const Attribute* to = attribute(n, "to", Attribute::kInt);
  if (!to) refuse("no attribute 'to'");
  if (element_size(to->i) == 0) refuse("a cast to element type " + std::to_string(to->i) + ", which no network uses");
  Tensor t{to->i, in[0]->dims};
  if (in[0]->known && is_integer(in[0]->dtype)) {
    Values v = in[0]->values;
    if (to->i == kBool)
      for (std::int64_t& x : v) x = x != 0;
    set_values(t, std::move(v));  // values the type does not hold stay unknown
  }
  return t;
}

// Element-wise over broadcast inputs; `f` returns false where the result is not carried.
Tensor elementwise(const Inputs& in, std::int64_t dtype,
                   const std::function<bool(const std::vector<std::int64_t>&, std::int64_t&)>& f) {
  Dims dims = in[0]->dims;
  for (std::size_t i = 1; i < in.size(); ++i) dims = broadcast(dims, in[i]->dims);
  Tensor t{dtype, dims};
  const bool all_known = std::all_of(in.begin(), in.end(), [](const Tensor* x) { return x->known; });
  if (!all_known || !is_integer(dtype) || t.elements() > kMaxValues) return t;
  std::vector<std::vector<std::size_t>> sources;
  for (const Tensor* x : in) sources.push_back(broadcast_sources(dims, x->dims));
  Values v(static_cast<std::size_t>(t.elements()));
  std::vector<std::int64_t> args(in.size());
  for (std::size_t e = 0; e < v.size(); ++e) {
    for (std::size_t i = 0; i < in.size(); ++i) args[i] = in[i]->values[sources[i][e]];
    if (!f(args, v[e])) return t;
  }
  set_values(t, std::move(v));
  return t;
}

Tensor arithmetic(const Inputs& in, bool (*op)(std::int64_t, std::int64_t, std::int64_t&)) {
  return elementwise(in, in[0]->dtype, [op](const std::vector<std::int64_t>& a, std::int64_t& r) { return op(a[0], a[1], r); });
}
Tensor add_rule(const Node&, const Inputs& in) { return arithmetic(in, add); }
Tensor sub_rule(const Node&, const Inputs& in) { return arithmetic(in, sub); }
Tensor mul_rule(const Node&, const Inputs& in) { return arithmetic(in, mul); }
Tensor div_rule(const Node&, const Inputs& in) { return arithmetic(in, div); }
Tensor equal(const Node&, const Inputs& in) {
  return elementwise(in, kBool, [](const std::vector<std::int64_t>& a, std::int64_t& r) {
    r = a[0] == a[1];
    return true;
  });
}
Tensor where(const Node&, const Inputs& in) {
  return elementwise(in, in[1]->dtype, [](const std::vector<std::int64_t>& a, std::int64_t& r) {
    r = a[0] ? a[1] : a[2];
    return true;
  });
}

Tensor gemm(const Node& n, const Inputs& in) {
  const Dims &a = in[0]->dims, &b = in[1]->dims;
  if (a.size() != 2 || b.size() != 2) refuse("Gemm of " + text(a) + " and " + text(b) + ": both must be matrices");
  const bool ta = int_attribute(n, "transA", 0) != 0, tb = int_attribute(n, "transB", 0) != 0;
  const std::uint64_t m = a[ta ? 1 : 0], k = a[ta ? 0 : 1], k2 = b[tb ? 1 : 0], cols = b[tb ? 0 : 1];
  if (k != k2) refuse("Gemm of " + text(a) + " and " + text(b) + ": the inner dimensions differ");
  const Dims out{m, cols};
  if (in.size() > 2 && in[2] && broadcast(out, in[2]->dims) != out)
    refuse("Gemm's C " + text(in[2]->dims) + " does not broadcast to " + text(out));
  return Tensor{in[0]->dtype, out};
}

Tensor matmul(const Node&, const Inputs& in) {
  Dims a = in[0]->dims, b = in[1]->dims;
  if (a.empty() || b.empty()) refuse("MatMul of a scalar");
  const bool vector_a = a.size() == 1, vector_b = b.size() == 1;
  if (vector_a) a.insert(a.begin(), 1);
  if (vector_b) b.push_back(1);
  if (a.back() != b[b.size() - 2])
    refuse("MatMul of " + text(in[0]->dims) + " and " + text(in[1]->dims) + ": the inner dimensions differ");
  Dims out = broadcast(Dims(a.begin(), a.end() - 2), Dims(b.begin(), b.end() - 2));
  if (!vector_a) out.push_back(a[a.size() - 2]);
  if (!vector_b) out.push_back(b.back());
  return Tensor{in[0]->dtype, out};
}

// Einsum with an explicit output and letters only (the exporter writes no "...").
Tensor einsum(const Node& n, const Inputs& in) {
  const Attribute* eq = attribute(n, "equation", Attribute::kString);
  if (!eq) refuse("no attribute 'equation'");
  std::string e;
  for (const char c : eq->s)
    if (c != ' ') e += c;
  const std::size_t arrow = e.find("->");
  const std::string lhs = e.substr(0, arrow);
  std::vector<std::string> terms(1);
  for (const char c : lhs) {
    if (c == ',') terms.emplace_back();
    else terms.back() += c;
  }
  if (terms.size() != in.size()) refuse("the equation names " + std::to_string(terms.size()) + " inputs, the node has " + std::to_string(in.size()));
  std::map<char, std::uint64_t> size;
  const auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); };
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const std::string& t = terms[i];
    if (t.size() != in[i]->dims.size()) refuse("the equation's term '" + printable(t) + "' does not match an input of shape " + text(in[i]->dims));
    for (std::size_t k = 0; k < t.size(); ++k) {
      if (!letter(t[k])) refuse("the equation '" + printable(eq->s) + "' has other than letters ('...' is not supported)");
      const auto [it, inserted] = size.emplace(t[k], in[i]->dims[k]);
      if (!inserted && it->second != in[i]->dims[k]) refuse(std::string("the equation's index '") + t[k] + "' has two sizes");
    }
  }
  if (arrow == std::string::npos) refuse("the equation '" + printable(eq->s) + "' names no output ('->')");
  const std::string rhs = e.substr(arrow + 2);
  Dims out;
  std::set<char> seen;
  for (const char c : rhs) {
    if (!size.count(c) || !seen.insert(c).second) refuse("the equation '" + printable(eq->s) + "' has a bad output");
    out.push_back(size[c]);
  }
  return Tensor{in[0]->dtype, out};
}

Tensor gather(const Node& n, const Inputs& in) {
  const Tensor &data = *in[0], &indices = *in[1];
  if (data.dims.empty()) refuse("Gather from a scalar");
  const std::size_t axis = axis_of(int_attribute(n, "axis", 0), data.dims.size(), "axis");
  Dims out(data.dims.begin(), data.dims.begin() + static_cast<std::ptrdiff_t>(axis));
  out.insert(out.end(), indices.dims.begin(), indices.dims.end());
  out.insert(out.end(), data.dims.begin() + static_cast<std::ptrdiff_t>(axis) + 1, data.dims.end());
  if (out.size() > kMaxRank) refuse("more than " + std::to_string(kMaxRank) + " dimensions");
  Tensor t{data.dtype, out};
  const std::uint64_t extent = data.dims[axis];
  if (indices.known)
    for (const std::int64_t k : indices.values)
      if ((k < 0 && static_cast<std::uint64_t>(-(k + 1)) >= extent) || (k >= 0 && static_cast<std::uint64_t>(k) >= extent))
        refuse("index " + std::to_string(k) + " is outside a dimension of " + std::to_string(extent));
  if (!data.known || !indices.known || t.elements() > kMaxValues) return t;
  std::uint64_t inner = 1;
  for (std::size_t d = axis + 1; d < data.dims.size(); ++d) inner *= data.dims[d];
  const std::uint64_t count = indices.values.size();
  Values v;
  for (std::uint64_t e = 0; e < t.elements(); ++e) {
    const std::uint64_t outer = e / (count * inner), at = e / inner % count, within = e % inner;
    const std::int64_t k = indices.values[static_cast<std::size_t>(at)];
    const std::uint64_t row = k < 0 ? extent - static_cast<std::uint64_t>(-k) : static_cast<std::uint64_t>(k);
    v.push_back(data.values[static_cast<std::size_t>((outer * extent + row) * inner + within)]);
  }
  set_values(t, std::move(v));
  return t;
}

// The same elements in new dims (Reshape, Unsqueeze): the values carry over.
Tensor rearranged(const Tensor& data, Dims dims) {
  Tensor t{data.dtype, std::move(dims)};
  if (data.known) set_values(t, data.values);
  return t;
}

Tensor reshape(const Node& n, const Inputs& in) {
  const Tensor& data = *in[0];
  const Values& shape = deciding_values(in[1], "its shape");
  const bool allowzero = int_attribute(n, "allowzero", 0) != 0;
  if (shape.size() > kMaxRank) refuse("a shape of more than " + std::to_string(kMaxRank) + " dimensions");
  Dims out;
  std::ptrdiff_t inferred = -1;
  std::uint64_t product = 1;
  for (std::size_t i = 0; i < shape.size(); ++i) {
    std::uint64_t d;
    if (shape[i] == -1) {
      if (inferred >= 0) refuse("the shape has two -1");
      inferred = static_cast<std::ptrdiff_t>(i);
      d = 1;
    } else if (shape[i] == 0 && !allowzero) {
      if (i >= data.dims.size()) refuse("the shape copies dimension " + std::to_string(i) + " of a tensor of rank " + std::to_string(data.dims.size()));
      d = data.dims[i];
    } else if (shape[i] < 0) {
      refuse("the shape has a dimension " + std::to_string(shape[i]));
    } else {
      d = static_cast<std::uint64_t>(shape[i]);
    }
    out.push_back(d);
    product = mul_sat(product, d);
  }
  const std::uint64_t total = data.elements();
  if (inferred >= 0) {
    if (allowzero && std::count(shape.begin(), shape.end(), 0)) refuse("the shape has both 0 and -1 under allowzero");
    if (product == 0 || total % product != 0) refuse("no dimension in place of -1 makes " + std::to_string(total) + " elements");
    out[static_cast<std::size_t>(inferred)] = total / product;
    product = total;
  }
  if (product != total) refuse(std::to_string(total) + " elements do not fit the shape " + text(out));
  return rearranged(data, out);
}

Tensor unsqueeze(const Node&, const Inputs& in) {
  const Tensor& data = *in[0];
  const Values& axes = deciding_values(in[1], "its axes");
  const std::size_t rank = data.dims.size() + axes.size();
  if (rank > kMaxRank) refuse("more than " + std::to_string(kMaxRank) + " dimensions");
  const std::vector<bool> added = axes_of(axes, rank);
  Dims out;
  for (std::size_t i = 0, from = 0; i < rank; ++i) out.push_back(added[i] ? 1 : data.dims[from++]);
  return rearranged(data, out);
}

Tensor slice(const Node&, const Inputs& in) {
  const Tensor& data = *in[0];
  const Values& starts = deciding_values(in[1], "its starts");
  const Values& ends = deciding_values(in[2], "its ends");
  Values axes, steps(starts.size(), 1);
  if (in.size() > 3 && in[3]) axes = deciding_values(in[3], "its axes");
  else
    for (std::size_t i = 0; i < starts.size(); ++i) axes.push_back(static_cast<std::int64_t>(i));
  if (in.size() > 4 && in[4]) steps = deciding_values(in[4], "its steps");
  if (ends.size() != starts.size() || axes.size() != starts.size() || steps.size() != starts.size())
    refuse("starts, ends, axes and steps differ in length");
  axes_of(axes, data.dims.size());  // distinct and in range
  const std::size_t rank = data.dims.size();
  Dims out = data.dims;
  std::vector<std::int64_t> first(rank, 0), step(rank, 1);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t a = axis_of(axes[k], rank, "axis");
    if (steps[k] == 0) refuse("a step of 0");
    const std::int64_t d = static_cast<std::int64_t>(std::min<std::uint64_t>(data.dims[a], static_cast<std::uint64_t>(kMax64)));
    std::int64_t s = starts[k], e = ends[k];
    if (s < 0) s += d;  // counted from the end (a negative plus d cannot overflow)
    if (e < 0) e += d;
    std::uint64_t count = 0;
    if (d == 0) {
      s = 0;
    } else if (steps[k] > 0) {
      s = std::clamp<std::int64_t>(s, 0, d);
      e = std::clamp<std::int64_t>(e, 0, d);
      if (e > s) count = (static_cast<std::uint64_t>(e - s) - 1) / static_cast<std::uint64_t>(steps[k]) + 1;
    } else {
      s = std::clamp<std::int64_t>(s, 0, d - 1);
      e = std::clamp<std::int64_t>(e, -1, d - 1);
      const std::uint64_t magnitude = 0 - static_cast<std::uint64_t>(steps[k]);
      if (s > e) count = (static_cast<std::uint64_t>(s - e) - 1) / magnitude + 1;
    }
    out[a] = count;
    first[a] = s;
    step[a] = steps[k];
  }
  Tensor t{data.dtype, out};
  if (!data.known || t.elements() > kMaxValues) return t;
  const std::vector<std::uint64_t> out_strides = strides(out), in_strides = strides(data.dims);
  Values v;
  for (std::uint64_t e = 0; e < t.elements(); ++e) {
    std::uint64_t rest = e, at = 0;
    for (std::size_t d = 0; d < rank; ++d) {
      const auto i = static_cast<std::int64_t>(rest / out_strides[d]);
      rest %= out_strides[d];
      at += static_cast<std::uint64_t>(first[d] + i * step[d]) * in_strides[d];
    }
    v.push_back(data.values[static_cast<std::size_t>(at)]);
  }
  set_values(t, std::move(v));
  return t;
}

Tensor concat(const Node& n, const Inputs& in) {
  const Dims& first = in[0]->dims;
  if (first.empty()) refuse("Concat of scalars");
  const std::size_t axis = axis_of(int_attribute(n, "axis", 0), first.size(), "axis");
  Dims out = first;
  out[axis] = 0;
  for (const Tensor* x : in) {
    bool fits = x->dims.size() == first.size();
    for (std::size_t d = 0; fits && d < first.size(); ++d) fits = d == axis || x->dims[d] == first[d];
    if (!fits) refuse("inputs of shapes " + text(first) + " and " + text(x->dims) + " do not join on axis " + std::to_string(axis));
    out[axis] = add_sat(out[axis], x->dims[axis]);
  }
  Tensor t{in[0]->dtype, out};
  if (t.elements() > kMaxValues || !std::all_of(in.begin(), in.end(), [](const Tensor* x) { return x->known; })) return t;
  std::uint64_t outer = 1, inner = 1;
  for (std::size_t d = 0; d < axis; ++d) outer *= first[d];
  for (std::size_t d = axis + 1; d < first.size(); ++d) inner *= first[d];
  Values v;
  for (std::uint64_t o = 0; o < outer; ++o)
    for (const Tensor* x : in) {
      const std::uint64_t block = x->dims[axis] * inner;
      v.insert(v.end(), x->values.begin() + static_cast<std::ptrdiff_t>(o * block),
               x->values.begin() + static_cast<std::ptrdiff_t>((o + 1) * block));
    }
  set_values(t, std::move(v));
  return t;
}

Tensor shape(const Node& n, const Inputs& in) {
  const auto rank = static_cast<std::int64_t>(in[0]->dims.size());
  const auto bound = [&](std::int64_t v) { return std::clamp<std::int64_t>(v < 0 ? v + rank : v, 0, rank); };
  const std::int64_t start = bound(int_attribute(n, "start", 0)), end = bound(int_attribute(n, "end", rank));
  Values v;
  for (std::int64_t i = start; i < end; ++i) {
    const std::uint64_t d = in[0]->dims[static_cast<std::size_t>(i)];
    v.push_back(d > static_cast<std::uint64_t>(kMax64) ? -1 : static_cast<std::int64_t>(d));
  }
  Tensor t{kInt64, {v.size()}};
  if (std::find(v.begin(), v.end(), -1) == v.end()) set_values(t, std::move(v));
  return t;
}

Tensor constant_of_shape(const Node& n, const Inputs& in) {
  const Values& shape = deciding_values(in[0], "its shape");
  Tensor t{kFloat, dims_of(shape, "the shape")};
  const Attribute* value = attribute(n, "value", Attribute::kTensor);
  if (!value) return t;  // float zeros
  if (value->t.elements() != 1) refuse("its value is not one element");
  t.dtype = value->t.dtype;
  if (value->t.known && t.elements() <= kMaxValues) set_values(t, Values(static_cast<std::size_t>(t.elements()), value->t.values[0]));
  return t;
}

Tensor expand(const Node&, const Inputs& in) {
  const Tensor& data = *in[0];
  Tensor t{data.dtype, broadcast(data.dims, dims_of(deciding_values(in[1], "its shape"), "the shape"))};
  if (data.known && t.elements() <= kMaxValues) {
    Values v;
    for (const std::size_t s : broadcast_sources(t.dims, data.dims)) v.push_back(data.values[s]);
    set_values(t, std::move(v));
  }
  return t;
}

Tensor reduce(const Tensor& data, const Values& axes, bool keepdims, bool noop_without_axes) {
  if (axes.empty() && noop_without_axes) return Tensor{data.dtype, data.dims};
  std::vector<bool> reduced = axes_of(axes, data.dims.size());
  if (axes.empty()) reduced.assign(data.dims.size(), true);
  Dims out;
  for (std::size_t d = 0; d < data.dims.size(); ++d) {
    if (!reduced[d]) out.push_back(data.dims[d]);
    else if (keepdims) out.push_back(1);
  }
  return Tensor{data.dtype, out};
}
Tensor reduce_sum(const Node& n, const Inputs& in) {  // axes as an input (opset 13)
  const Values none;
  const Values& axes = in.size() > 1 && in[1] ? deciding_values(in[1], "its axes") : none;
  return reduce(*in[0], axes, int_attribute(n, "keepdims", 1) != 0, int_attribute(n, "noop_with_empty_axes", 0) != 0);
}
Tensor reduce_mean(const Node& n, const Inputs& in) {  // axes as an attribute (opset 17)
  const Attribute* axes = attribute(n, "axes", Attribute::kInts);
  return reduce(*in[0], axes ? axes->ints : Values{}, int_attribute(n, "keepdims", 1) != 0, false);
}

Tensor constant(const Node& n, const Inputs&) {
  if (n.attributes.size() != 1) refuse("a Constant has exactly one value attribute");
  const auto& [name, a] = *n.attributes.begin();
  if (name == "value" && a.kind == Attribute::kTensor) return a.t;
  Tensor t{a.kind == Attribute::kInt || a.kind == Attribute::kInts ? kInt64 : kFloat, {}};
  if (name == "value_int" && a.kind == Attribute::kInt) {
    set_values(t, {a.i});
  } else if (name == "value_ints" && a.kind == Attribute::kInts) {
    t.dims = {a.ints.size()};
    set_values(t, a.ints);
  } else if (name == "value_float" && a.kind == Attribute::kFloat) {
  } else if (name == "value_floats" && a.kind == Attribute::kFloats) {
    t.dims = {a.floats};
  } else {
    refuse("a Constant's value attribute '" + printable(name) + "' is not one a network uses (value, value_int(s), value_float(s))");
  }
  return t;
}

struct Operator {
  const char* name;
  std::size_t min_inputs, max_inputs;
  Tensor (*infer)(const Node&, const Inputs&);
};
constexpr std::size_t kAny = 1024;  // variadic (Concat, Einsum)

// The allow-list: what torch.onnx writes at opset 17 for the bundle's networks (every
// configuration of training/softdeca_train/models/networks.py and residual.py), sorted.
const Operator kOperators[] = {
    {"Add", 2, 2, add_rule},
    {"Cast", 1, 1, cast},
    {"Clip", 1, 3, like_input},
    {"Concat", 1, kAny, concat},
    {"Constant", 0, 0, constant},
    {"ConstantOfShape", 1, 1, constant_of_shape},
    {"Cos", 1, 1, like_input},
    {"Div", 2, 2, div_rule},
    {"Einsum", 1, kAny, einsum},
    {"Elu", 1, 1, like_input},
    {"Equal", 2, 2, equal},
    {"Expand", 2, 2, expand},
    {"Gather", 2, 2, gather},
    {"Gemm", 2, 3, gemm},
    {"Identity", 1, 1, identity},
    {"Log", 1, 1, like_input},
    {"MatMul", 2, 2, matmul},
    {"Mul", 2, 2, mul_rule},
    {"Neg", 1, 1, negate},
    {"ReduceMean", 1, 1, reduce_mean},
    {"ReduceSum", 1, 2, reduce_sum},
    {"Reshape", 2, 2, reshape},
    {"Shape", 1, 1, shape},
    {"Sigmoid", 1, 1, like_input},
    {"Sin", 1, 1, like_input},
    {"Slice", 3, 5, slice},
    {"Sub", 2, 2, sub_rule},
    {"Unsqueeze", 2, 2, unsqueeze},
    {"Where", 3, 3, where},
};

const Operator* find(const std::string& op) {
  for (const Operator& o : kOperators)
    if (op == o.name) return &o;
  return nullptr;
}

// Inputs an operator may leave out (""): Clip's bounds, Gemm's C, Slice's axes and steps,
// ReduceSum's axes. Every other input is required.
bool optional_input(const std::string& op, std::size_t i) {
  return (op == "Clip" && i >= 1) || (op == "Gemm" && i == 2) || (op == "Slice" && i >= 3) || (op == "ReduceSum" && i == 1);
}

}  // namespace

bool is_allowed_operator(const std::string& op) { return find(op) != nullptr; }

std::vector<std::string> allowed_operators() {
  std::vector<std::string> names;
  for (const Operator& o : kOperators) names.emplace_back(o.name);
  return names;
}

Tensor infer_output(const Node& node, const std::vector<const Tensor*>& inputs) {
  const Operator* o = find(node.op);
  if (!o) refuse("operator '" + printable(node.op) + "' is not one a bundle's networks may use");
  if (inputs.size() < o->min_inputs || inputs.size() > o->max_inputs)
    refuse(std::to_string(inputs.size()) + " inputs, the operator takes " +
           (o->min_inputs == o->max_inputs ? std::to_string(o->min_inputs)
                                           : std::to_string(o->min_inputs) + " or more"));
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (!inputs[i] && !optional_input(node.op, i)) refuse("input " + std::to_string(i) + " is required");
  Tensor out = o->infer(node, inputs);
  if (out.dims.size() > kMaxRank) refuse("an output of more than " + std::to_string(kMaxRank) + " dimensions");
  if (element_size(out.dtype) == 0) refuse("an output of element type " + std::to_string(out.dtype) + ", which no network uses");
  return out;
}

}  // namespace softdeca::bundle::onnx
