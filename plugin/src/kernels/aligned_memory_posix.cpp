#include <sys/mman.h>

#include <cstdlib>

#include "kernels/aligned_memory.h"

namespace softdeca::kernels {

// posix_memalign rather than aligned_alloc: Android has aligned_alloc from API 28 only, macOS from
// 10.15.
void* aligned_allocate(std::size_t alignment, std::size_t bytes) {
  void* p = nullptr;
  return posix_memalign(&p, alignment, bytes) == 0 ? p : nullptr;
}

void aligned_release(void* p) { std::free(p); }

void advise_huge_pages([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) {
#ifdef MADV_HUGEPAGE  // Linux only
  madvise(p, bytes, MADV_HUGEPAGE);  // failure is harmless
#endif
}

}  // namespace softdeca::kernels
