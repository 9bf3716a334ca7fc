// Receiver part of the C ABI: thin, checked wrappers over live::Receiver.
#include <memory>
#include <string>

#include "api/error_boundary.h"
#include "api/frame_abi.h"
#include "api/handles.h"
#include "live/receiver.h"
#include "stream/arkit_names.h"
#include "stream/rig_names.h"

struct softdeca_receiver {
  std::unique_ptr<softdeca::live::Receiver> impl;
};

namespace {
using namespace softdeca;
using namespace softdeca::api;

const live::Receiver& receiver_of(const softdeca_receiver* r) {
  require_not_null(r, "receiver");
  return *r->impl;
}
live::Receiver& receiver_of(softdeca_receiver* r) {
  require_not_null(r, "receiver");
  return *r->impl;
}

void frame_out(softdeca_frame* out, softdeca_bool* out_received, bool got, const stream::Frame& f) {
  *out_received = got ? 1 : 0;
  if (got) frame_to_abi(f, out);
}
}  // namespace

extern "C" {

SOFTDECA_API const char* softdeca_blendshape_get_name(uint32_t index) { return stream::blendshape_name(index); }

SOFTDECA_API softdeca_status softdeca_blendshape_find_index(const char* name, int32_t* out_index) {
  return guarded(__func__, [&] {
    require_not_null(name, "name");
    require_not_null(out_index, "out_index");
    *out_index = stream::rig_blendshape_index(name);
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_config_init(softdeca_receiver_config* config) {
  return guarded(__func__, [&] {
    require_struct(config, "config");
    reset_struct(config);
    config->format = SOFTDECA_FORMAT_AUTO;
    config->bind_address = nullptr;
    config->port = stream::default_port(stream::Format::softdeca);
    config->queue_capacity = 256;
    config->jitter_delay = 0;
    const live::ReceiverConfig defaults;
    config->session_hold = defaults.session_hold;
    config->source_rate_limit = defaults.source_rate_limit;
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_create(const softdeca_receiver_config* config,
                                                      softdeca_receiver** out_receiver) {
  return guarded(__func__, [&] {
    require_struct(config, "config");
    require_not_null(out_receiver, "out_receiver");
    require(config->format >= SOFTDECA_FORMAT_AUTO && config->format <= SOFTDECA_FORMAT_IFACIALMOCAP,
            "config->format is not a softdeca_stream_format");
    require(config->port <= 65535, "config->port exceeds 65535");
    require(std::isfinite(config->jitter_delay), "config->jitter_delay is not finite", SOFTDECA_ERROR_NON_FINITE);
    require(std::isfinite(config->session_hold) && std::isfinite(config->source_rate_limit),
            "config->session_hold and source_rate_limit must be finite", SOFTDECA_ERROR_NON_FINITE);
    live::ReceiverConfig c;
    c.listen_network = config->listen_network != 0;
    c.bind_address = config->bind_address ? config->bind_address : c.listen_network ? "0.0.0.0" : "127.0.0.1";
    c.follow_newest = config->follow_newest != 0;
    if (config->session_hold != 0) c.session_hold = config->session_hold;
    if (config->source_rate_limit != 0) c.source_rate_limit = config->source_rate_limit < 0 ? 0 : config->source_rate_limit;
    c.port = static_cast<uint16_t>(config->port);
    c.format = static_cast<stream::Format>(config->format);
    c.delay = config->jitter_delay;
    c.queue_capacity = config->queue_capacity;
    create_handle(out_receiver, "out_receiver",
                  [&](softdeca_receiver& r) { r.impl = std::make_unique<live::Receiver>(c); });
  });
}

SOFTDECA_API void softdeca_receiver_destroy(softdeca_receiver* receiver) {
  destroy_handle(__func__, receiver);
}

SOFTDECA_API softdeca_status softdeca_receiver_get_port(const softdeca_receiver* receiver, uint32_t* out_port) {
  return guarded(__func__, [&] {
    const auto& r = receiver_of(receiver);
    require_not_null(out_port, "out_port");
    *out_port = r.port();
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_get_next(softdeca_receiver* receiver, double timeout,
                                                    softdeca_frame* out_frame, softdeca_bool* out_received) {
  return guarded(__func__, [&] {
    auto& r = receiver_of(receiver);
    require_struct(out_frame, "out_frame");
    require_not_null(out_received, "out_received");
    require(std::isfinite(timeout) && timeout >= 0, "timeout must be finite and >= 0");
    stream::Frame f;
    frame_out(out_frame, out_received, r.next(timeout, f), f);
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_get_latest(const softdeca_receiver* receiver,
                                                      softdeca_frame* out_frame, softdeca_bool* out_received) {
  return guarded(__func__, [&] {
    const auto& r = receiver_of(receiver);
    require_struct(out_frame, "out_frame");
    require_not_null(out_received, "out_received");
    stream::Frame f;
    frame_out(out_frame, out_received, r.latest(f), f);
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_get_stats(const softdeca_receiver* receiver,
                                                         softdeca_receiver_stats* out) {
  return guarded(__func__, [&] {
    const auto& r = receiver_of(receiver);
    require_struct(out, "out_stats");
    const live::ReceiverStats s = r.stats();
    reset_struct(out);
    out->datagrams = s.datagrams;
    out->frames = s.frames;
    out->control_messages = s.control_messages;
    out->delivered = s.delivered;
    out->malformed = s.malformed;
    out->undersized = s.undersized;
    out->oversized = s.oversized;
    out->bad_magic = s.bad_magic;
    out->incompatible_version = s.incompatible_version;
    out->bad_length = s.bad_length;
    out->bad_value = s.bad_value;
    out->unknown_type = s.unknown_type;
    out->duplicates = s.duplicates;
    out->reordered = s.reordered;
    out->late = s.late;
    out->lost = s.lost;
    out->expected = s.expected;
    out->overflowed = s.overflowed;
    out->session_changes = s.session_changes;
    out->clock_resyncs = s.clock_resyncs;
    out->requests_sent = s.requests_sent;
    out->frame_rate_hz = s.frame_rate_hz;
    out->loss_ratio = s.loss_ratio;
    out->latency_p50_ms = s.latency_p50_ms;
    out->latency_p99_ms = s.latency_p99_ms;
    out->foreign = s.foreign;
    out->rate_limited = s.rate_limited;
    out->recording_dropped = s.recording_dropped;
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_get_profile(const softdeca_receiver* receiver, uint32_t* out_id,
                                                       int32_t* out_indices, uint32_t capacity,
                                                       uint32_t* out_count) {
  return guarded(__func__, [&] {
    stream::wire::Profile p;
    const bool have = receiver_of(receiver).profile(p);
    profile_to_abi(have ? &p : nullptr, out_id, out_indices, capacity, out_count);
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_get_neutral(const softdeca_receiver* receiver, float* out_xyz,
                                                       uint32_t vertex_capacity, uint32_t* out_vertex_count) {
  return guarded(__func__, [&] {
    std::vector<float> xyz;
    receiver_of(receiver).neutral(xyz);
    neutral_to_abi(xyz, out_xyz, vertex_capacity, out_vertex_count);
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_request_neutral(softdeca_receiver* receiver, softdeca_bool* out_sent) {
  return guarded(__func__, [&] {
    auto& r = receiver_of(receiver);
    require_not_null(out_sent, "out_sent");
    *out_sent = r.request_neutral() ? 1 : 0;
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_start_recording(softdeca_receiver* receiver, const char* path,
                                                               const softdeca_recording_header* header) {
  return guarded(__func__, [&] {
    auto& r = receiver_of(receiver);
    require_not_null(path, "path");
    r.start_recording(path, header_from_abi(header));
  });
}

SOFTDECA_API softdeca_status softdeca_receiver_stop_recording(softdeca_receiver* receiver, uint32_t* out_frames) {
  return guarded(__func__, [&] {
    auto& r = receiver_of(receiver);
    // Counted after stopping: frames still queued for the writer thread are written by then.
    const std::string error = r.stop_recording();
    const std::size_t frames = r.frames_recorded();
    if (out_frames) *out_frames = static_cast<uint32_t>(frames);
    require(error.empty(), "the recording stopped early: " + error, SOFTDECA_ERROR_IO);
  });
}

}  // extern "C"
