#include "bundle/onnx_constant_sizes.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace softdeca::runtime {
namespace {

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
constexpr std::size_t kMaxShapeValues = 16;  // longer vectors are not shapes

std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) { return a != 0 && b > kMax / a ? kMax : a * b; }

// A dimension from a shape value: negative (infer, or nonsense) counts as 1, huge saturates.
std::uint64_t dim_of(double v) {
  if (!(v >= 1)) return 1;
  return v >= 1.8e19 ? kMax : static_cast<std::uint64_t>(v);
}

std::uint64_t elements(const std::vector<std::uint64_t>& dims) {
  std::uint64_t n = 1;
  for (std::uint64_t d : dims) n = mul_sat(n, d);
  return n;
}

std::vector<std::uint64_t> dims_from(const std::vector<double>& v) {
  std::vector<std::uint64_t> dims;
  for (double x : v) dims.push_back(dim_of(x));
  return dims;
}

// Numpy broadcasting of two shapes.
std::vector<std::uint64_t> broadcast(std::vector<std::uint64_t> a, std::vector<std::uint64_t> b) {
  if (a.size() < b.size()) std::swap(a, b);
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::uint64_t& d = a[a.size() - b.size() + i];
    d = std::max(d, b[i]);
  }
  return a;
}

}  // namespace

void ConstantSizes::shape(const std::string& name, std::vector<std::uint64_t> dims, std::uint64_t element_bytes) {
  shapes_[name] = {std::move(dims), element_bytes};
}

const std::vector<double>* ConstantSizes::values_of(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() ? nullptr : &it->second;
}

const ConstantSizes::Shape* ConstantSizes::shape_of(const std::string& name) const {
  const auto it = shapes_.find(name);
  return it == shapes_.end() ? nullptr : &it->second;
}

void ConstantSizes::output(const std::string& name, std::vector<std::uint64_t> dims, std::uint64_t element_bytes,
                           const std::function<void(const std::string&, std::uint64_t)>& produced) {
  produced(name, mul_sat(elements(dims), element_bytes));
  shape(name, std::move(dims), element_bytes);
}

void ConstantSizes::evaluate(const std::function<void(const std::string&, std::uint64_t)>& produced) {
  for (const FoldNode& n : nodes_) step(n, produced);
}

void ConstantSizes::step(const FoldNode& n, const std::function<void(const std::string&, std::uint64_t)>& produced) {
  if (n.outputs.empty()) return;
  const std::string& out = n.outputs[0];
  const auto input_values = [&](std::size_t i) { return i < n.inputs.size() ? values_of(n.inputs[i]) : nullptr; };
  const auto input_shape = [&](std::size_t i) { return i < n.inputs.size() ? shape_of(n.inputs[i]) : nullptr; };
  if (n.op == "Constant") {
    if (n.has_value && n.value.size() <= kMaxShapeValues) values(out, n.value);
    shape(out, n.value_dims, n.value_element_bytes);
  } else if (n.op == "Shape") {
    // The dims of a tensor of static shape: a constant (start and end slice it).
    if (const Shape* s = input_shape(0)) {
      const auto r = static_cast<std::int64_t>(s->dims.size());
      const auto clampi = [&](std::int64_t v) { return std::clamp(v < 0 ? v + r : v, std::int64_t{0}, r); };
      const auto start = n.ints.count("start") ? clampi(n.ints.at("start")) : 0;
      const auto end = n.ints.count("end") ? clampi(n.ints.at("end")) : r;
      std::vector<double> v;
      for (std::int64_t i = start; i < end; ++i) v.push_back(static_cast<double>(s->dims[static_cast<std::size_t>(i)]));
      values(out, v);
      shape(out, {v.size()}, 8);
    }
  } else if (n.op == "Concat") {
    // Shape vectors put together (axis 0 of 1-D constants).
    std::vector<double> v;
    for (std::size_t i = 0; i < n.inputs.size(); ++i) {
      const std::vector<double>* part = input_values(i);
      if (!part || v.size() + part->size() > kMaxShapeValues) return;
      v.insert(v.end(), part->begin(), part->end());
    }
    values(out, v);
    shape(out, {v.size()}, 8);
  } else if (n.op == "ConstantOfShape") {
    if (const std::vector<double>* s = input_values(0)) output(out, dims_from(*s), n.value_element_bytes, produced);
  } else if (n.op == "Expand") {
    const std::vector<double>* s = input_values(1);
    const Shape* x = input_shape(0);
    if (s) output(out, broadcast(x ? x->dims : std::vector<std::uint64_t>{}, dims_from(*s)), x ? x->element_bytes : 4, produced);
  } else if (n.op == "Tile") {
    const std::vector<double>* repeats = input_values(1);
    const Shape* x = input_shape(0);
    if (repeats) {
      std::vector<std::uint64_t> dims = dims_from(*repeats);
      if (x && x->dims.size() == dims.size())
        for (std::size_t i = 0; i < dims.size(); ++i) dims[i] = mul_sat(dims[i], x->dims[i]);
      output(out, dims, x ? x->element_bytes : 4, produced);
    }
  } else if (n.op == "Range") {
    const std::vector<double>*start = input_values(0), *limit = input_values(1), *delta = input_values(2);
    if (start && limit && delta && start->size() == 1 && limit->size() == 1 && delta->size() == 1 && (*delta)[0] != 0) {
      const double count = std::ceil(((*limit)[0] - (*start)[0]) / (*delta)[0]);
      output(out, {count >= 1 ? dim_of(count) : 0}, 8, produced);
    }
  } else if (n.op == "Resize" || n.op == "Upsample") {
    // Resize's sizes input (3), when constant; scales depend on the input's shape as well.
    if (n.op == "Resize" && input_values(3)) {
      const Shape* x = input_shape(0);
      output(out, dims_from(*input_values(3)), x ? x->element_bytes : 4, produced);
    } else if (const Shape* x = input_shape(0)) {
      const std::vector<double>* scales = input_values(n.op == "Resize" ? 2 : 1);
      if (scales && scales->size() == x->dims.size()) {
        std::vector<std::uint64_t> dims = x->dims;
        for (std::size_t i = 0; i < dims.size(); ++i) dims[i] = dim_of(std::floor(double(dims[i]) * (*scales)[i]));
        output(out, dims, x->element_bytes, produced);
      }
    }
  } else if (n.op == "Identity" || n.op == "Cast") {
    if (const std::vector<double>* v = input_values(0)) values(out, *v);
  }
}

}  // namespace softdeca::runtime
