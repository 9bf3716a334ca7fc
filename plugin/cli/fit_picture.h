// fit.png: how the template sits on a user's avatar. Two orthographic views, front and side (from
// the subject's left), of the avatar in grey with the registered template's skin in colour
// where it shows at or in front of the avatar's surface; framed on the template. A software
// rasteriser (z-buffer, Lambert shading): no graphics library.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace softdeca::cli {

struct PictureMesh {
  const float* vertices = nullptr;  // xyz
  std::size_t vertex_count = 0;
  const std::int32_t* triangles = nullptr;  // may be null: then the vertices are drawn as dots
  std::size_t triangle_count = 0;
};

// The subject's frame in the avatar's coordinates (need not be unit length).
struct PictureAxes {
  double left[3], up[3], forward[3];
};

struct Picture {
  std::size_t width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // rows top to bottom
};

// Throws std::invalid_argument when an axis is zero or not finite, or the template is empty.
Picture draw_fit(const PictureMesh& avatar, const PictureMesh& registered, const PictureAxes& axes,
                 std::size_t view_pixels = 480);
// fit.png's bytes: draw_fit's picture as a PNG file.
std::string fit_picture_png(const PictureMesh& avatar, const PictureMesh& registered, const PictureAxes& axes);

}  // namespace softdeca::cli
