// Recording part of the C ABI: recorder, player and the Live Link Face CSV conversions.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "api/error_boundary.h"
#include "api/frame_abi.h"
#include "api/handles.h"
#include "recording/conversions.h"
#include "recording/player.h"
#include "recording/recording_index.h"
#include "recording/recording_writer.h"

struct softdeca_recorder {
  std::unique_ptr<softdeca::recording::RecordingWriter> impl;
};
struct softdeca_player {
  std::unique_ptr<softdeca::recording::Player> impl;
};

namespace {
using namespace softdeca;
using namespace softdeca::api;

recording::RecordingWriter& recorder_of(softdeca_recorder* r) {
  require_not_null(r, "recorder");
  return *r->impl;
}
const recording::Player& player_of(const softdeca_player* p) {
  require_not_null(p, "player");
  return *p->impl;
}
recording::Player& player_of(softdeca_player* p) {
  require_not_null(p, "player");
  return *p->impl;
}

void copy_text(const std::string& s, char (&out)[64]) {
  const std::size_t n = std::min(s.size(), sizeof out - 1);
  std::memcpy(out, s.data(), n);
  out[n] = '\0';
}

void report_out(const recording::ConversionReport& r, softdeca_convert_report* out) {
  if (!out) return;
  require_struct(out, "out_report");
  reset_struct(out);
  out->frames = static_cast<uint32_t>(r.frames);
  out->rows = static_cast<uint32_t>(r.rows);
  out->face_lost_rows = static_cast<uint32_t>(r.face_lost_rows);
  out->malformed_rows = static_cast<uint32_t>(r.malformed_rows);
}

// A file conversion (Live Link Face CSV <-> recording): its arguments checked, then `convert`
// (from, to, timecode_rate) run and its report written.
template <class Convert>
void convert_file(const char* from, const char* from_name, const char* to, const char* to_name, double timecode_rate,
                  softdeca_convert_report* out_report, Convert&& convert) {
  require_not_null(from, from_name);
  require_not_null(to, to_name);
  require(std::isfinite(timecode_rate) && timecode_rate >= 0 && timecode_rate <= 1000, "timecode_rate must be in [0, 1000]");
  if (out_report) require_struct(out_report, "out_report");
  report_out(convert(from, to, timecode_rate, recording::ReadLimits{}), out_report);
}
}  // namespace

extern "C" {

SOFTDECA_API softdeca_status softdeca_recorder_create(const char* path, const softdeca_recording_header* header,
                                                      softdeca_recorder** out_recorder) {
  return guarded(__func__, [&] {
    require_not_null(path, "path");
    create_handle(out_recorder, "out_recorder", [&](softdeca_recorder& r) {
      r.impl = std::make_unique<recording::RecordingWriter>(path, header_from_abi(header));
    });
  });
}

SOFTDECA_API softdeca_status softdeca_recorder_write(softdeca_recorder* recorder, const softdeca_frame* frame) {
  return guarded(__func__, [&] {
    auto& r = recorder_of(recorder);
    r.write(frame_from_abi(frame));
  });
}

SOFTDECA_API softdeca_status softdeca_recorder_write_profile(softdeca_recorder* recorder, const char* name,
                                                             const int32_t* indices, uint32_t count,
                                                             uint32_t* out_id) {
  return guarded(__func__, [&] {
    auto& r = recorder_of(recorder);
    require(count <= SOFTDECA_MAX_LANDMARKS, "a profile names at most 150 vertices");
    if (count > 0) require_not_null(indices, "indices");
    require_not_null(out_id, "out_id");
    stream::wire::Profile p;
    p.name = name ? name : "";
    for (uint32_t i = 0; i < count; ++i) {
      expect(indices[i] >= 0 && indices[i] < SOFTDECA_ARKIT_VERTEX_COUNT, [&] {
        return "indices[" + std::to_string(i) + "] = " + std::to_string(indices[i]) + " is not an ARKit face-mesh vertex";
      });
      p.indices.push_back(static_cast<uint16_t>(indices[i]));
    }
    p.id = stream::wire::profile_id_of(p.indices);
    r.write_profile(p);
    *out_id = p.id;
  });
}

SOFTDECA_API softdeca_status softdeca_recorder_write_neutral(softdeca_recorder* recorder, const float* xyz,
                                                             uint32_t vertex_count) {
  return guarded(__func__, [&] {
    auto& r = recorder_of(recorder);
    require_not_null(xyz, "xyz");
    require(vertex_count >= 1 && vertex_count <= 4096, "vertex_count must be in [1, 4096]");
    require_finite(xyz, 3 * vertex_count, "xyz");
    r.write_neutral(std::vector<float>(xyz, xyz + 3 * vertex_count));
  });
}

SOFTDECA_API void softdeca_recorder_destroy(softdeca_recorder* recorder) {
  destroy_handle(__func__, recorder);
}

SOFTDECA_API softdeca_status softdeca_player_load(const char* path, softdeca_player** out_player) {
  return guarded(__func__, [&] {
    require_not_null(path, "path");
    create_handle(out_player, "out_player", [&](softdeca_player& p) {
      p.impl = std::make_unique<recording::Player>(recording::RecordingIndex::open(path));
    });
  });
}

SOFTDECA_API void softdeca_player_destroy(softdeca_player* player) {
  destroy_handle(__func__, player);
}

SOFTDECA_API softdeca_status softdeca_player_get_info(const softdeca_player* player, softdeca_recording_info* out) {
  return guarded(__func__, [&] {
    const auto& p = player_of(player);
    require_struct(out, "out_info");
    const auto& rec = p.recording();
    reset_struct(out);
    out->frame_count = static_cast<uint32_t>(p.frame_count());
    out->duration = p.duration();
    out->start_unix_time = rec.header.start_unix_time;
    out->timecode_rate = rec.header.timecode_rate;
    out->damaged_regions = static_cast<uint32_t>(rec.recovery.damaged_regions);
    out->truncated_bytes = static_cast<uint32_t>(rec.recovery.truncated_bytes);
    copy_text(rec.header.device, out->device);
    copy_text(rec.header.subject, out->subject);
    copy_text(rec.header.source, out->source);
  });
}

SOFTDECA_API softdeca_status softdeca_player_get_frame(const softdeca_player* player, uint32_t index,
                                                   softdeca_frame* out_frame) {
  return guarded(__func__, [&] {
    const auto& p = player_of(player);
    require_struct(out_frame, "out_frame");
    require(index < p.frame_count(), "index " + std::to_string(index) + " is not below the frame count " +
                                         std::to_string(p.frame_count()));
    frame_to_abi(p.frame(index), out_frame);
  });
}

SOFTDECA_API softdeca_status softdeca_player_get_frame_at(const softdeca_player* player, double time,
                                                      softdeca_frame* out_frame) {
  return guarded(__func__, [&] {
    const auto& p = player_of(player);
    require_struct(out_frame, "out_frame");
    require(std::isfinite(time), "time is not finite", SOFTDECA_ERROR_NON_FINITE);
    frame_to_abi(p.frame_at(time), out_frame);
  });
}

SOFTDECA_API softdeca_status softdeca_player_seek(softdeca_player* player, double time) {
  return guarded(__func__, [&] { player_of(player).seek(time); });
}

SOFTDECA_API softdeca_status softdeca_player_set_speed(softdeca_player* player, double speed) {
  return guarded(__func__, [&] { player_of(player).set_speed(speed); });
}

SOFTDECA_API softdeca_status softdeca_player_set_loop(softdeca_player* player, softdeca_bool loop) {
  return guarded(__func__, [&] { player_of(player).set_loop(loop != 0); });
}

SOFTDECA_API softdeca_status softdeca_player_advance(softdeca_player* player, double dt,
                                                     softdeca_frame* out_frame, softdeca_bool* out_ended) {
  return guarded(__func__, [&] {
    auto& p = player_of(player);
    require_struct(out_frame, "out_frame");
    require(std::isfinite(dt) && dt >= 0, "dt must be finite and >= 0");
    const bool ended = p.advance(dt);
    frame_to_abi(p.frame_at(p.position()), out_frame);
    if (out_ended) *out_ended = ended ? 1 : 0;
  });
}

SOFTDECA_API softdeca_status softdeca_player_get_position(const softdeca_player* player, double* out_time) {
  return guarded(__func__, [&] {
    const auto& p = player_of(player);
    require_not_null(out_time, "out_time");
    *out_time = p.position();
  });
}

SOFTDECA_API softdeca_status softdeca_player_get_profile(const softdeca_player* player, uint32_t* out_id,
                                                     int32_t* out_indices, uint32_t capacity, uint32_t* out_count) {
  return guarded(__func__, [&] {
    const auto& profiles = player_of(player).recording().profiles;
    profile_to_abi(profiles.empty() ? nullptr : &profiles.back(), out_id, out_indices, capacity, out_count);
  });
}

SOFTDECA_API softdeca_status softdeca_player_get_neutral(const softdeca_player* player, float* out_xyz,
                                                     uint32_t vertex_capacity, uint32_t* out_vertex_count) {
  return guarded(__func__, [&] {
    neutral_to_abi(player_of(player).recording().neutral, out_xyz, vertex_capacity, out_vertex_count);
  });
}

SOFTDECA_API softdeca_status softdeca_convert_livelinkface_csv(const char* csv_path, const char* recording_path,
                                                               double timecode_rate,
                                                               softdeca_convert_report* out_report) {
  return guarded(__func__, [&] {
    convert_file(csv_path, "csv_path", recording_path, "recording_path", timecode_rate, out_report, recording::csv_to_recording);
  });
}

SOFTDECA_API softdeca_status softdeca_export_livelinkface_csv(const char* recording_path, const char* csv_path,
                                                              double timecode_rate,
                                                              softdeca_convert_report* out_report) {
  return guarded(__func__, [&] {
    convert_file(recording_path, "recording_path", csv_path, "csv_path", timecode_rate, out_report, recording::recording_to_csv);
  });
}

}  // extern "C"
