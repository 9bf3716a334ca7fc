// An accessor's values as the glTF 2.0 specification defines them: elements at the view's
// stride (or tightly packed), each component converted from its type (normalized integers as
// max(c / 127, -1), c / 255, max(c / 32767, -1), c / 65535; other integers as their value, which
// KHR_mesh_quantization allows for positions and morph target deltas), zeros where there is no
// buffer view, and sparse substitutions on top. Each read takes its decoded size from the budget
// before allocating it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gltf_buffers.h"
#include "gltf_document.h"

namespace softdeca::avatar_import::gltf {

class AccessorReader {
 public:
  AccessorReader(Document& doc, BinaryData& data, DecodeBudget& budget) : doc_(doc), data_(data), budget_(budget) {}

  // accessors[index] as floats, count x components (matrices column-major). `type` is the type
  // the use needs ("VEC3"); `float_only` refuses integer components; `use` says what reads it
  // ("POSITION of meshes[0].primitives[1]") for the errors.
  std::vector<float> floats(std::size_t index, const char* type, bool float_only, const std::string& use);
  // A SCALAR accessor of unsigned byte, short or int components (not normalized).
  std::vector<std::uint32_t> indices(std::size_t index, const std::string& use);

  Document& document() { return doc_; }
  BinaryData& data() { return data_; }
  DecodeBudget& budget() { return budget_; }

 private:
  template <class T>
  std::vector<T> decode(const Accessor& a, const std::string& where);

  Document& doc_;
  BinaryData& data_;
  DecodeBudget& budget_;
};

}  // namespace softdeca::avatar_import::gltf
