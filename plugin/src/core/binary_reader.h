// Reads a little-endian binary file's arrays in order, every read bounds-checked against the
// bytes left: a short or long file is an Error(FORMAT) naming the file and the array, never a
// read past the end. Bundle files and saved fits are read this way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace softdeca {

class BinaryReader {
 public:
  BinaryReader(const std::uint8_t* data, std::size_t size, std::string name)
      : data_(data), size_(size), name_(std::move(name)) {}

  template <class T>
  void read(T* out, std::size_t count, const char* what) {
    const std::size_t size = count * sizeof(T);
    if (size / sizeof(T) != count || size > size_ - at_)
      throw Error(SOFTDECA_ERROR_FORMAT, name_ + ": shorter than declared (reading " + what + ")");
    if (size == 0) return;  // an empty array: no bytes, and `out` may be null
    std::memcpy(out, data_ + at_, size);  // little-endian hosts only, like every file of the product
    at_ += size;
  }
  template <class T>
  std::vector<T> vector(std::size_t count, const char* what) {
    std::vector<T> v(count);
    read(v.data(), count, what);
    return v;
  }
  template <class T>
  T value(const char* what) {
    T v{};
    read(&v, 1, what);
    return v;
  }
  std::size_t left() const { return size_ - at_; }
  void finish() const {
    if (at_ != size_)
      throw Error(SOFTDECA_ERROR_FORMAT, name_ + ": " + std::to_string(size_ - at_) + " bytes more than declared");
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::string name_;
  std::size_t at_ = 0;
};

}  // namespace softdeca
