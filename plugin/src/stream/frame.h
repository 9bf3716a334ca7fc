// The canonical frame every source (our protocol, Live Link Face, iFacialMocap, recordings)
// is converted into. Units and frame follow docs/ARCHITECTURE.md, Conventions: metres; ARKit's right-handed face-anchor
// frame (+Y up, +Z out of the face); weights in canonical order (arkit_names.h), in [0, 1].
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "stream/arkit_names.h"

namespace softdeca::stream {

// Landmarks per frame: a profile names at most this many ARKit face-mesh vertices, so that a
// full frame datagram stays under 1,200 bytes with room for future blocks (docs/protocol.md).
constexpr std::size_t kMaxLandmarks = 150;
// Vertices of ARKit's face mesh (ARFaceGeometry), whose indices a landmark profile names.
constexpr std::size_t kArkitVertexCount = 1220;

enum class Tracking : uint8_t { lost = 0, tracked = 1, limited = 2 };

// A rigid pose: translation (metres) and rotation as a unit quaternion (x, y, z, w).
struct Pose {
  std::array<float, 3> position{0, 0, 0};
  std::array<float, 4> rotation{0, 0, 0, 1};
};

struct Frame {
  uint32_t session_id = 0;    // sender's stream; 0 when unknown
  uint32_t sequence = 0;      // sender's datagram counter, meaningful when has_sequence
  bool has_sequence = false;  // false for sources without one (Live Link Face, iFacialMocap)
  Tracking tracking = Tracking::tracked;
  double capture_time = 0;  // seconds on the sender's clock (ARFrame.timestamp, timecode)
  double send_time = 0;     // seconds on the sender's clock when sent; 0 when unknown
  double receive_time = 0;  // seconds on this host's steady clock; 0 when not received live
  std::array<float, kBlendshapeCount> weights{};
  bool has_head = false;  // head pose: the face anchor's transform (ARKit world frame)
  Pose head;
  bool has_eyes = false;  // eye poses relative to the face anchor
  Pose left_eye;
  Pose right_eye;
  uint32_t profile_id = 0;  // landmark profile that names the landmarks' vertices
  uint16_t landmark_count = 0;
  std::array<float, kMaxLandmarks * 3> landmarks{};  // xyz per landmark, face-anchor frame
};

}  // namespace softdeca::stream
