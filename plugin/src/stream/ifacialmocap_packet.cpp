#include "stream/ifacialmocap_packet.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "core/error.h"
#include "stream/arkit_names.h"
#include "stream/rotation.h"
#include "stream/text_fields.h"

namespace softdeca::stream::ifacialmocap {
namespace {

wire::Verdict drop(DropReason reason, const char* detail) { return {reason, detail}; }

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

// "eyeBlink_L" -> canonical index of eyeBlinkLeft; -1 when unknown.
int canonical_of(std::string_view name) {
  if (name.size() > 64) return -1;
  std::string canonical(name);
  if (ends_with(name, "_L")) canonical = std::string(name.substr(0, name.size() - 2)) + "Left";
  else if (ends_with(name, "_R")) canonical = std::string(name.substr(0, name.size() - 2)) + "Right";
  return blendshape_index(canonical);
}

bool parse_number(std::string_view text, double& out) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  if (text.empty()) return false;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out) && std::fabs(out) < 1e6;
}

// "a,b,c" -> exactly n numbers.
bool parse_numbers(std::string_view text, double* out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t comma = text.find(',');
    const bool last = i + 1 == n;
    if (last != (comma == std::string_view::npos)) return false;
    if (!parse_number(text.substr(0, comma), out[i])) return false;
    text = last ? std::string_view() : text.substr(comma + 1);
  }
  return true;
}

}  // namespace

std::string wire_name(std::size_t i) {
  std::string name = blendshape_name(i);
  if (name == "jawLeft" || name == "jawRight" || name == "mouthLeft" || name == "mouthRight") return name;
  if (ends_with(name, "Left")) return name.substr(0, name.size() - 4) + "_L";
  if (ends_with(name, "Right")) return name.substr(0, name.size() - 5) + "_R";
  return name;
}

wire::Verdict decode_packet(const uint8_t* data, std::size_t size, Frame& f, Presence& present) {
  if (size > kMaxPacketBytes) return drop(DropReason::oversized, "iFacialMocap packet over 8192 bytes");
  if (size == 0) return drop(DropReason::undersized, "empty datagram");
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (std::any_of(text.begin(), text.end(), [](char c) { return c == '\0'; }))
    return drop(DropReason::bad_magic, "binary data is no iFacialMocap text");
  f = Frame{};
  present.fill(false);
  std::size_t known = 0;
  TextFields fields(text, '|');
  std::string_view field;
  while (fields.next(field)) {
    if (!field.empty() && field.front() == '=') field.remove_prefix(1);  // weights | transforms
    if (field.empty()) continue;
    const std::size_t hash = field.find('#');
    if (hash != std::string_view::npos) {
      const std::string_view name = field.substr(0, hash), values = field.substr(hash + 1);
      double v[6];
      if (name == "head") {
        if (!parse_numbers(values, v, 6)) return drop(DropReason::bad_value, "iFacialMocap head needs 6 numbers");
        f.head.rotation = quaternion_from_unity_euler_degrees(v[0], v[1], v[2]);
        f.head.position = {static_cast<float>(v[3]), static_cast<float>(v[4]), static_cast<float>(-v[5])};
        f.has_head = true;
      } else if (name == "rightEye" || name == "leftEye") {
        if (!parse_numbers(values, v, 3)) return drop(DropReason::bad_value, "iFacialMocap eye needs 3 numbers");
        (name == "leftEye" ? f.left_eye : f.right_eye).rotation =
            quaternion_from_unity_euler_degrees(v[0], v[1], v[2]);
        f.has_eyes = true;
      }
      continue;
    }
    std::size_t sep = field.find('&');
    if (sep == std::string_view::npos) sep = field.find('-');
    if (sep == std::string_view::npos || sep == 0) continue;  // an unnamed field
    const std::string_view name = field.substr(0, sep);
    double value = 0;
    if (name == "trackingStatus") {
      if (!parse_number(field.substr(sep + 1), value)) return drop(DropReason::bad_value, "iFacialMocap trackingStatus is no number");
      f.tracking = value > 0 ? Tracking::tracked : Tracking::lost;
      continue;
    }
    const int index = canonical_of(name);
    if (index < 0) continue;
    if (!parse_number(field.substr(sep + 1), value)) return drop(DropReason::bad_value, "iFacialMocap value is no number");
    f.weights[static_cast<std::size_t>(index)] = static_cast<float>(std::clamp(value / 100.0, 0.0, 1.0));
    present[static_cast<std::size_t>(index)] = true;
    ++known;
  }
  if (known == 0) return drop(DropReason::bad_magic, "no iFacialMocap blendshape in the datagram");
  return {};
}

std::string encode_packet(const Frame& f, char separator) {
  require(separator == '-' || separator == '&', "iFacialMocap separates with '-' or '&'");
  std::string out;
  char buf[160];
  for (std::size_t i = 0; i < kBlendshapeCount; ++i) {
    require(std::isfinite(f.weights[i]), "weight not finite", SOFTDECA_ERROR_NON_FINITE);
    const long v = std::lround(double(std::clamp(f.weights[i], 0.0f, 1.0f)) * 100.0);
    out += wire_name(i) + separator + std::to_string(v) + '|';
  }
  const auto angles = [](const Pose& p) { return unity_euler_degrees_from_quaternion(p.rotation); };
  const auto h = angles(f.head);
  std::snprintf(buf, sizeof buf, "=head#%.6f,%.6f,%.6f,%.6f,%.6f,%.6f|", h[0], h[1], h[2],
                double(f.head.position[0]), double(f.head.position[1]), double(-f.head.position[2]));
  out += buf;
  const auto r = angles(f.right_eye), l = angles(f.left_eye);
  std::snprintf(buf, sizeof buf, "rightEye#%.6f,%.6f,%.6f|leftEye#%.6f,%.6f,%.6f|", r[0], r[1], r[2],
                l[0], l[1], l[2]);
  out += buf;
  return out;
}

}  // namespace softdeca::stream::ifacialmocap
