#include "fit_picture.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "png_writer.h"

namespace softdeca::cli {

namespace {
using Vec3 = Eigen::Vector3d;
constexpr double kMargin = 1.3;                 // the view spans the template's extent times this
constexpr double kDepthTolerance = 0.01;        // of the view's width: the template shows this far behind the avatar
const Vec3 kLight = Vec3(-0.3, 0.4, 1.0).normalized();  // in view coordinates: from the viewer, up and left

// One orthographic view: screen right, screen up and toward the viewer, in avatar coordinates.
struct View {
  Vec3 right, up, toward;
  Vec3 project(const float* p) const {
    const Vec3 q = Eigen::Vector3f(p).cast<double>();
    return {right.dot(q), up.dot(q), toward.dot(q)};
  }
};

// Depth and shade per pixel of one view.
struct Layer {
  std::size_t size;
  std::vector<float> depth, shade;
  explicit Layer(std::size_t n) : size(n), depth(n * n, -std::numeric_limits<float>::infinity()), shade(n * n, 0) {}
  bool covered(std::size_t i) const { return std::isfinite(depth[i]); }
};

// Maps view coordinates onto the pixels of a square view around `centre` of half-width `half`.
struct Frame {
  double cx, cy, half;
  std::size_t size;
  double px(double x) const { return (x - (cx - half)) / (2 * half) * static_cast<double>(size); }
  double py(double y) const { return ((cy + half) - y) / (2 * half) * static_cast<double>(size); }
};

double edge(double ax, double ay, double bx, double by, double px, double py) { return (bx - ax) * (py - ay) - (by - ay) * (px - ax); }

void raster_triangle(const Frame& f, const Vec3 (&v)[3], float shade, Layer& layer) {
  double x[3], y[3];
  for (int k = 0; k < 3; ++k) {
    x[k] = f.px(v[k].x());
    y[k] = f.py(v[k].y());
  }
  const double area = edge(x[0], y[0], x[1], y[1], x[2], y[2]);
  if (!(std::abs(area) > 1e-12)) return;
  const double n = static_cast<double>(f.size);
  const double x0 = std::max(0.0, std::floor(std::min({x[0], x[1], x[2]}))), x1 = std::min(n - 1, std::ceil(std::max({x[0], x[1], x[2]})));
  const double y0 = std::max(0.0, std::floor(std::min({y[0], y[1], y[2]}))), y1 = std::min(n - 1, std::ceil(std::max({y[0], y[1], y[2]})));
  for (double py = y0; py <= y1; ++py) {
    for (double px = x0; px <= x1; ++px) {
      const double cx = px + 0.5, cy = py + 0.5;
      const double w0 = edge(x[1], y[1], x[2], y[2], cx, cy) / area, w1 = edge(x[2], y[2], x[0], y[0], cx, cy) / area;
      const double w2 = 1 - w0 - w1;
      if (w0 < 0 || w1 < 0 || w2 < 0) continue;
      const auto depth = static_cast<float>(w0 * v[0].z() + w1 * v[1].z() + w2 * v[2].z());
      const std::size_t i = static_cast<std::size_t>(py) * f.size + static_cast<std::size_t>(px);
      if (depth > layer.depth[i]) {
        layer.depth[i] = depth;
        layer.shade[i] = shade;
      }
    }
  }
}

void raster_mesh(const Frame& f, const View& view, const PictureMesh& mesh, Layer& layer) {
  if (!mesh.triangles) {  // dots of 3 x 3 pixels
    for (std::size_t i = 0; i < mesh.vertex_count; ++i) {
      const Vec3 p = view.project(mesh.vertices + 3 * i);
      if (!p.allFinite()) continue;
      const long cx = std::lround(f.px(p.x())), cy = std::lround(f.py(p.y()));
      for (long y = cy - 1; y <= cy + 1; ++y)
        for (long x = cx - 1; x <= cx + 1; ++x) {
          if (x < 0 || y < 0 || x >= static_cast<long>(f.size) || y >= static_cast<long>(f.size)) continue;
          const std::size_t k = static_cast<std::size_t>(y) * f.size + static_cast<std::size_t>(x);
          if (p.z() > layer.depth[k]) {
            layer.depth[k] = static_cast<float>(p.z());
            layer.shade[k] = 1.0f;
          }
        }
    }
    return;
  }
  for (std::size_t t = 0; t < mesh.triangle_count; ++t) {
    Vec3 v[3];
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t index = mesh.triangles[3 * t + static_cast<std::size_t>(k)];
      inside = inside && index >= 0 && static_cast<std::size_t>(index) < mesh.vertex_count;
      if (inside) v[k] = view.project(mesh.vertices + 3 * static_cast<std::size_t>(index));
    }
    if (!inside) continue;
    const Vec3 normal = (v[1] - v[0]).cross(v[2] - v[0]);
    const double length = normal.norm();
    if (!(length > 0)) continue;
    // Two-sided: a file's triangles may face either way.
    raster_triangle(f, v, static_cast<float>(0.25 + 0.75 * std::abs(normal.dot(kLight)) / length), layer);
  }
}

Vec3 unit_axis(const double* a, const char* name) {
  const Vec3 v(a[0], a[1], a[2]);
  const double n = v.norm();
  if (!std::isfinite(n) || !(n > 0)) throw std::invalid_argument(std::string("the picture's ") + name + " axis is zero or not finite");
  return v / n;
}
}  // namespace

Picture draw_fit(const PictureMesh& avatar, const PictureMesh& registered, const PictureAxes& axes, std::size_t n) {
  if (registered.vertex_count == 0) throw std::invalid_argument("no registered template to draw");
  const Vec3 left = unit_axis(axes.left, "left"), up = unit_axis(axes.up, "up"), forward = unit_axis(axes.forward, "forward");
  // Front: the subject's left on the picture's right; side: seen from the subject's left.
  const View views[2] = {{left, up, forward}, {-forward, up, left}};
  Picture picture;
  picture.width = 2 * n;
  picture.height = n;
  picture.rgb.assign(picture.width * picture.height * 3, 255);
  for (int v = 0; v < 2; ++v) {
    const View& view = views[v];
    Eigen::AlignedBox3d box;
    for (std::size_t i = 0; i < registered.vertex_count; ++i) box.extend(view.project(registered.vertices + 3 * i));
    const Vec3 centre = box.center(), extent = box.sizes();
    const Frame frame{centre.x(), centre.y(), std::max(0.5 * kMargin * std::max(extent.x(), extent.y()), 1e-9), n};
    Layer body(n), skin(n);
    raster_mesh(frame, view, avatar, body);
    raster_mesh(frame, view, registered, skin);
    const auto tolerance = static_cast<float>(kDepthTolerance * 2 * frame.half);
    for (std::size_t i = 0; i < n * n; ++i) {
      double rgb[3] = {255, 255, 255};
      if (body.covered(i)) std::fill(rgb, rgb + 3, 215.0 * body.shade[i]);
      if (skin.covered(i) && skin.depth[i] >= body.depth[i] - tolerance) {
        const double colour[3] = {255 * skin.shade[i], 120 * skin.shade[i], 20 * skin.shade[i]};
        const double opacity = body.covered(i) ? 0.55 : 1.0;
        for (int c = 0; c < 3; ++c) rgb[c] = (1 - opacity) * rgb[c] + opacity * colour[c];
      }
      const std::size_t x = i % n + static_cast<std::size_t>(v) * n, y = i / n;
      for (int c = 0; c < 3; ++c)
        picture.rgb[3 * (y * picture.width + x) + static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(std::clamp(rgb[c], 0.0, 255.0));
    }
  }
  for (std::size_t y = 0; y < n; ++y)  // a line between the views
    for (int c = 0; c < 3; ++c) picture.rgb[3 * (y * picture.width + n) + static_cast<std::size_t>(c)] = 160;
  return picture;
}

std::string fit_picture_png(const PictureMesh& avatar, const PictureMesh& registered, const PictureAxes& axes) {
  const Picture p = draw_fit(avatar, registered, axes);
  return encode_png(p.rgb.data(), p.width, p.height);
}

}  // namespace softdeca::cli
