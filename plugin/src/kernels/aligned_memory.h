// Aligned allocation for AlignedArray: aligned_memory_posix.cpp (aligned_alloc, and huge-page
// advice where Linux offers it) or aligned_memory_windows.cpp (_aligned_malloc, which needs its
// own free); the build compiles one of them.
#pragma once

#include <cstddef>

namespace softdeca::kernels {

// `bytes` a multiple of `alignment` (a power of two); nullptr when out of memory.
void* aligned_allocate(std::size_t alignment, std::size_t bytes);
// Frees what aligned_allocate returned; nullptr is a no-op.
void aligned_release(void* p);
// Asks for transparent huge pages over [p, p + bytes); advice only, ignored where unsupported.
void advise_huge_pages(void* p, std::size_t bytes);

}  // namespace softdeca::kernels
