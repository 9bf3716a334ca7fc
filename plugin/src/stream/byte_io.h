// Bounds-checked readers and writers of fixed-size little- and big-endian values. Parsers of
// untrusted bytes use ByteReader only: every read checks the remaining length first, so a lying
// length field can make a read fail but never read past the buffer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace softdeca::stream {

namespace detail {
inline bool host_is_big_endian() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 0;
}
// Puts n bytes (n <= 8) in host order into wire order, or back: a swap when they differ.
inline void reorder(uint8_t* b, std::size_t n, bool wire_big_endian) {
  if (wire_big_endian != host_is_big_endian())
    for (std::size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
}
}  // namespace detail

class ByteReader {
 public:
  ByteReader(const uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  std::size_t remaining() const { return size_ - pos_; }
  std::size_t position() const { return pos_; }

  bool skip(std::size_t n) {
    if (n > remaining()) return false;
    pos_ += n;
    return true;
  }
  // A reader of the next n bytes (the caller checked n <= remaining()); this one moves past them.
  ByteReader sub(std::size_t n) {
    ByteReader r(data_ + pos_, n);
    pos_ += n;
    return r;
  }
  bool u8(uint8_t& v) { return take(&v, 1, false); }
  bool u16le(uint16_t& v) { return take(&v, 2, false); }
  bool u32le(uint32_t& v) { return take(&v, 4, false); }
  bool i16le(int16_t& v) { return take(&v, 2, false); }
  bool f32le(float& v) { return take(&v, 4, false); }
  bool f64le(double& v) { return take(&v, 8, false); }
  bool i32be(int32_t& v) { return take(&v, 4, true); }
  bool f32be(float& v) { return take(&v, 4, true); }
  bool text(std::string& out, std::size_t n) {
    if (n > remaining()) return false;
    out.assign(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return true;
  }

 private:
  bool take(void* v, std::size_t n, bool big_endian) {
    if (n > remaining()) return false;
    uint8_t tmp[8];
    std::memcpy(tmp, data_ + pos_, n);
    detail::reorder(tmp, n, big_endian);
    std::memcpy(v, tmp, n);
    pos_ += n;
    return true;
  }

  const uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<uint8_t>& out) : out_(out) {}

  std::size_t size() const { return out_.size(); }
  void u8(uint8_t v) { out_.push_back(v); }
  void u16le(uint16_t v) { put(&v, 2, false); }
  void u32le(uint32_t v) { put(&v, 4, false); }
  void i16le(int16_t v) { put(&v, 2, false); }
  void f32le(float v) { put(&v, 4, false); }
  void f64le(double v) { put(&v, 8, false); }
  void i32be(int32_t v) { put(&v, 4, true); }
  void f32be(float v) { put(&v, 4, true); }
  void text(const std::string& s) { out_.insert(out_.end(), s.begin(), s.end()); }
  void bytes(const uint8_t* p, std::size_t n) { out_.insert(out_.end(), p, p + n); }
  // Overwrites a little-endian u16 written earlier (a length known only afterwards).
  void patch_u16le(std::size_t at, uint16_t v) {
    uint8_t tmp[2];
    std::memcpy(tmp, &v, 2);
    detail::reorder(tmp, 2, false);
    std::memcpy(out_.data() + at, tmp, 2);
  }

 private:
  void put(const void* v, std::size_t n, bool big_endian) {
    uint8_t tmp[8];
    std::memcpy(tmp, v, n);
    detail::reorder(tmp, n, big_endian);
    out_.insert(out_.end(), tmp, tmp + n);
  }

  std::vector<uint8_t>& out_;
};

}  // namespace softdeca::stream
