#include <malloc.h>

#include "kernels/aligned_memory.h"

namespace softdeca::kernels {

// The Microsoft C runtime has no aligned_alloc; _aligned_malloc's blocks need _aligned_free.
void* aligned_allocate(std::size_t alignment, std::size_t bytes) { return _aligned_malloc(bytes, alignment); }

void aligned_release(void* p) { _aligned_free(p); }

// Large pages on Windows need a privilege most users lack; the advice is skipped.
void advise_huge_pages(void*, std::size_t) {}

}  // namespace softdeca::kernels
