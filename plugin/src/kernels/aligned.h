// A fixed-size, 64-byte aligned array: the hot-path buffers (cache-line aligned, never resized
// after creation, so frames never allocate). Arrays of 2 MB or more (hyper-tensors, blendshape
// deltas, the DT factor) are aligned to 2 MB and advised as transparent huge pages where Linux
// offers them (madvise mode): a frame streams them whole, and with 4 KB pages that costs a TLB
// miss every 4 KB (measured: the DG kernel with a cold cache 1.0 -> 0.85 ms, half storage).
#pragma once

#include <cstddef>
#include <cstring>
#include <new>
#include <utility>

#include "kernels/aligned_memory.h"

namespace softdeca::kernels {

constexpr std::size_t kHugePage = std::size_t{2} << 20;

template <class T>
class AlignedArray {
 public:
  AlignedArray() = default;
  explicit AlignedArray(std::size_t n) { resize(n); }
  AlignedArray(const AlignedArray&) = delete;
  AlignedArray& operator=(const AlignedArray&) = delete;
  AlignedArray(AlignedArray&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)), allocated_(std::exchange(o.allocated_, 0)) {}
  AlignedArray& operator=(AlignedArray&& o) noexcept {
    if (this != &o) {
      aligned_release(data_);
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      allocated_ = std::exchange(o.allocated_, 0);
    }
    return *this;
  }
  ~AlignedArray() { aligned_release(data_); }

  // Zero-filled; throws std::bad_alloc.
  void resize(std::size_t n) {
    aligned_release(data_);
    data_ = nullptr;
    size_ = 0;
    allocated_ = 0;
    if (n == 0) return;
    const bool huge = n * sizeof(T) >= kHugePage;
    const std::size_t align = huge ? kHugePage : 64;
    const std::size_t bytes = (n * sizeof(T) + align - 1) / align * align;
    data_ = static_cast<T*>(aligned_allocate(align, bytes));
    if (!data_) throw std::bad_alloc();
    if (huge) advise_huge_pages(data_, bytes);
    std::memset(static_cast<void*>(data_), 0, bytes);
    size_ = n;
    allocated_ = bytes;
  }
  T* data() { return data_; }
  const T* data() const { return data_; }
  std::size_t size() const { return size_; }
  std::size_t bytes() const { return size_ * sizeof(T); }
  std::size_t allocated_bytes() const { return allocated_; }  // with the rounding to 64 B or 2 MB
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0, allocated_ = 0;
};

}  // namespace softdeca::kernels
