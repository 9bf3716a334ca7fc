// Best-fit rigid and similarity transforms between corresponding point sets (3x3 SVD):
// Kabsch for the jaw's motion and the fit's placement, Umeyama for the landmark retargeting.
// Same conventions as training/softdeca_train/models/reference.py (kabsch, similarity).
#pragma once

#include <cstddef>

namespace softdeca::geometry {

struct Similarity {
  double scale = 1.0;
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major, det +1
  double translation[3] = {0, 0, 0};
};

// dst ≈ s R src + t over n points (xyz interleaved; `src_index`/`dst_index` select points,
// or null for 0..n-1). With `with_scale` false, s = 1 (Kabsch).
Similarity fit_similarity(const float* src, const int* src_index, const float* dst, const int* dst_index, std::size_t n,
                          bool with_scale);

// Same for double inputs without index selection.
Similarity fit_similarity(const double* src, const double* dst, std::size_t n, bool with_scale);

}  // namespace softdeca::geometry
