#include "avatar_view.h"

#include <Eigen/Core>

#include "bundle/json.h"
#include "fit/avatar_frame.h"
#include "json.h"

namespace softdeca::cli {

AvatarView avatar_view(const AvatarFile& a, double metres_per_unit) {
  fit::AvatarShapes shapes;
  shapes.neutral = a.neutral.data();
  shapes.vertex_count = a.vertex_count();
  for (std::size_t k = 0; k < 52; ++k)
    shapes.deltas[k] = a.shape_sources[k].empty() ? nullptr : a.blendshapes.data() + 3 * k * a.vertex_count();
  shapes.triangles = a.triangles.data();
  shapes.triangle_count = a.triangles.size() / 3;
  const fit::AvatarFrame frame = fit::avatar_frame(shapes);
  Eigen::Vector3d centre = frame.eyes;
  if (frame.eye_distance <= 0) {  // no eye shapes: the moving vertices' centre
    centre.setZero();
    std::size_t n = 0;
    for (std::size_t v = 0; v < a.vertex_count(); ++v)
      if (frame.face[v]) centre += Eigen::Vector3f(a.neutral.data() + 3 * v).cast<double>(), ++n;
    if (n) centre /= static_cast<double>(n);
  }
  AvatarView view{};
  for (int k = 0; k < 3; ++k) {
    view.left[k] = frame.left[k];
    view.up[k] = frame.up[k];
    view.forward[k] = frame.forward[k];
    view.eyes[k] = centre[k];
  }
  view.metres_per_unit = metres_per_unit;
  return view;
}

double fit_metres_per_unit(const std::string& fit_report) {
  const bundle::Json report = bundle::Json::parse(fit_report);
  return report.at("metres_per_unit", "the fit's report").number("metres_per_unit");
}

std::string view_json(const AvatarFile& a, const AvatarView& v) {
  using Matrix4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
  Eigen::Matrix3d axes;  // rows: common space -> the subject's frame
  axes.row(0) = Eigen::Vector3d(v.left[0], v.left[1], v.left[2]);
  axes.row(1) = Eigen::Vector3d(v.up[0], v.up[1], v.up[2]);
  axes.row(2) = Eigen::Vector3d(v.forward[0], v.forward[1], v.forward[2]);
  const Eigen::Vector3d eyes(v.eyes[0], v.eyes[1], v.eyes[2]);
  std::string parts = "[";
  for (const AvatarPart& p : a.parts) {
    const Matrix4 own_to_common = Eigen::Map<const Matrix4>(p.transform);
    const Eigen::Matrix3d linear = v.metres_per_unit * axes * own_to_common.topLeftCorner<3, 3>();
    const Eigen::Vector3d offset = v.metres_per_unit * axes * (own_to_common.topRightCorner<3, 1>() - eyes);
    std::string m = "[";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) m += (m.size() > 1 ? "," : "") + json_number(c < 3 ? linear(r, c) : offset[r]);
    JsonObject o;
    o.number("first_vertex", static_cast<double>(p.first_vertex))
        .number("vertex_count", static_cast<double>(p.vertex_count))
        .raw("to_view", m + "]");
    parts += (parts.size() > 1 ? "," : "") + o.str();
  }
  JsonObject o;
  o.number("metres_per_unit", v.metres_per_unit).raw("parts", parts + "]");
  return o.str();
}

}  // namespace softdeca::cli
