#include "live/receiver.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "stream/crc32.h"
#include "stream/percentile.h"
#include "stream/steady_clock.h"

namespace softdeca::live {
// The stream/ parts this receiver puts together.
using stream::Arrival;
using stream::crc32;
using stream::Datagram;
using stream::DropReason;
using stream::Endpoint;
using stream::Format;
using stream::Frame;
using stream::JitterBuffer;
using stream::kBlendshapeCount;
using stream::percentile;
using stream::SequenceTracker;
using stream::steady_seconds;
namespace wire = stream::wire;

namespace {

constexpr std::size_t kReceiveBuffer = 65536;  // any UDP datagram fits: sizes are exact
constexpr int kMaxWaitMs = 20;                 // how soon the thread notices stop()
constexpr std::size_t kRateWindow = 64;
constexpr double kRateHorizon = 2.0;
constexpr std::size_t kLatencyWindow = 2048;
constexpr std::size_t kMaxProfiles = 16;
constexpr double kRequestInterval = 1.0;  // at most one profile request per second

bool is_loopback(const std::string& address) {
  return address.compare(0, 4, "127.") == 0 || address == "::1" || address == "[::1]";
}

const ReceiverConfig& checked(const ReceiverConfig& c) {
  require(std::isfinite(c.delay) && c.delay >= 0 && c.delay <= 5, "jitter delay must be in [0, 5] seconds");
  require(c.queue_capacity >= 1 && c.queue_capacity <= 65536, "queue capacity must be in [1, 65536]");
  require(std::isfinite(c.session_hold) && c.session_hold > 0 && c.session_hold <= 3600,
          "session hold must be in (0, 3600] seconds");
  require(std::isfinite(c.source_rate_limit) && c.source_rate_limit >= 0 && c.source_rate_limit <= 100000,
          "source rate limit must be in [0, 100000] datagrams per second");
  require(c.listen_network || is_loopback(c.bind_address),
          "binding " + c.bind_address + " listens on the network: that needs listen_network (CLI: --listen)");
  require(c.recording_queue >= 16 && c.recording_queue <= 65536, "recording queue must be in [16, 65536] records");
  require(c.format == Format::automatic || c.format == Format::softdeca || c.format == Format::livelinkface ||
              c.format == Format::ifacialmocap,
          "unknown stream format");
  return c;
}

}  // namespace

Receiver::Receiver(const ReceiverConfig& config)
    : config_(checked(config)),
      socket_(config.bind_address, config.port),
      jitter_(config.delay),
      rate_limit_(config.source_rate_limit) {
  port_ = socket_.local_port();
  thread_ = std::thread([this] { run(); });
}

Receiver::~Receiver() { stop(); }

void Receiver::stop() {
  if (stopping_.exchange(true)) return;
  if (thread_.joinable()) thread_.join();
}

void Receiver::run() {
  std::vector<uint8_t> buffer(kReceiveBuffer);
  while (!stopping_.load()) {
    double due;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      release_due(steady_seconds());
      due = jitter_.next_due();
    }
    const double wait = std::clamp((due - steady_seconds()) * 1000.0, 0.0, double(kMaxWaitMs));
    if (!socket_.wait_readable(static_cast<int>(std::ceil(wait)))) continue;
    std::size_t size = 0;
    Endpoint from;
    for (int i = 0; i < 256 && socket_.receive(buffer.data(), buffer.size(), size, from); ++i)
      handle(buffer.data(), std::min(size, buffer.size()), from, steady_seconds());
  }
  std::unique_ptr<recording::BackgroundRecorder> recorder;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Frame f;
    while (jitter_.pop_any(f)) deliver(f, steady_seconds());
    recorder = std::move(recorder_);
  }
  if (recorder) {  // the disk may be slow: written outside the lock
    const std::string error = recorder->finish();
    std::lock_guard<std::mutex> lock(mutex_);
    frames_recorded_ = recorder->frames_written();
    recording_dropped_before_ += recorder->dropped();
    if (recording_error_.empty()) recording_error_ = error;
  }
}

void Receiver::count_drop(DropReason reason) {
  switch (reason) {
    case DropReason::none: return;
    case DropReason::unknown_type: ++stats_.unknown_type; return;
    case DropReason::undersized: ++stats_.undersized; break;
    case DropReason::oversized: ++stats_.oversized; break;
    case DropReason::bad_magic: ++stats_.bad_magic; break;
    case DropReason::incompatible_version: ++stats_.incompatible_version; break;
    case DropReason::bad_length: ++stats_.bad_length; break;
    case DropReason::bad_value: ++stats_.bad_value; break;
  }
  ++stats_.malformed;
}

// Before anything is decoded: the source's rate, then whether another sender holds the
// session (it does until it has been quiet for session_hold seconds).
bool Receiver::admit(const Endpoint& from, double now) {
  ++stats_.datagrams;
  if (!rate_limit_.allow(from, now)) {
    ++stats_.rate_limited;
    if (have_holder_ && endpoint_key(from) == holder_) ++holder_rate_limited_;
    return false;
  }
  if (have_holder_ && !config_.follow_newest && now - holder_heard_ < config_.session_hold &&
      endpoint_key(from) != holder_) {
    ++stats_.foreign;
    return false;
  }
  return true;
}

void Receiver::handle(const uint8_t* data, std::size_t size, const Endpoint& from, double now) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!admit(from, now)) return;
  }
  Datagram d;
  const wire::Verdict verdict = decode_datagram(data, size, config_.format, d);
  std::lock_guard<std::mutex> lock(mutex_);
  if (verdict.reason != DropReason::none) {
    count_drop(verdict.reason);
    return;
  }
  // A well-formed datagram: its sender holds the session from now on.
  have_holder_ = true;
  holder_ = endpoint_key(from);
  holder_heard_ = now;
  // Only our protocol names its session; the others are told apart by device (Live Link Face)
  // or by the sender's address (iFacialMocap).
  uint32_t session = d.message.envelope.session_id;
  if (d.format == Format::livelinkface) session = d.message.frame.session_id;
  if (d.format == Format::ifacialmocap) session = crc32(&from.address, from.length);
  if (!have_session_ || session != session_) start_session(session);
  session_format_ = d.format;
  sender_ = from;
  have_sender_ = true;
  if (d.format == Format::softdeca) {
    switch (sequence_.observe(d.message.envelope.sequence)) {
      case Arrival::duplicate: ++stats_.duplicates; return;
      case Arrival::stale: ++stats_.late; return;
      case Arrival::reordered: ++stats_.reordered; break;
      case Arrival::in_order:
      case Arrival::restart: break;
    }
  }
  switch (d.message.envelope.type) {
    case wire::MessageType::frame:
      ++stats_.frames;
      on_frame(d.message.frame, d, now);
      break;
    case wire::MessageType::profile: {
      ++stats_.control_messages;
      const wire::Profile& p = d.message.profile;
      if (profiles_.size() >= kMaxProfiles && !profiles_.count(p.id)) profiles_.erase(profiles_.begin());
      const bool fresh = profiles_.find(p.id) == profiles_.end();
      profiles_[p.id] = p;
      newest_profile_ = p.id;
      if (fresh && recorder_) recorder_->push(p);
      break;
    }
    case wire::MessageType::neutral_chunk: {
      ++stats_.control_messages;
      std::vector<float> xyz;
      if (assembler_.add(d.message.neutral, xyz) && xyz != neutral_) {
        neutral_ = std::move(xyz);
        if (recorder_) recorder_->push(neutral_);
      }
      break;
    }
    case wire::MessageType::request:
      ++stats_.control_messages;  // senders answer requests; a receiver has nothing to send
      break;
  }
  release_due(now);
}

void Receiver::start_session(uint32_t session) {
  if (have_session_) {
    ++stats_.session_changes;
    Frame f;
    while (jitter_.pop_any(f)) deliver(f, steady_seconds());
  }
  lost_before_ += session_lost();
  expected_before_ += sequence_.expected();
  sequence_ = SequenceTracker();
  holder_rate_limited_ = 0;
  jitter_ = JitterBuffer(config_.delay);
  previous_weights_.fill(0);
  have_session_ = true;
  session_ = session;
}

void Receiver::on_frame(Frame f, const Datagram& d, double now) {
  f.session_id = session_;
  f.receive_time = now;
  if (d.format == Format::ifacialmocap) {
    f.capture_time = now;  // the format has no clock of its own
    for (std::size_t i = 0; i < kBlendshapeCount; ++i)
      if (!d.present[i]) f.weights[i] = previous_weights_[i];
  }
  previous_weights_ = f.weights;
  switch (jitter_.insert(f, now)) {
    case JitterBuffer::Outcome::late: ++stats_.late; return;
    case JitterBuffer::Outcome::duplicate: ++stats_.duplicates; return;
    case JitterBuffer::Outcome::resync: ++stats_.clock_resyncs; break;
    case JitterBuffer::Outcome::queued: break;
  }
  if (f.landmark_count > 0) {
    profile_in_use_ = f.profile_id;
    if (!profiles_.count(f.profile_id) && d.format == Format::softdeca && now - last_profile_request_ >= kRequestInterval) {
      last_profile_request_ = now;
      send_request(wire::RequestKind::profile, f.profile_id);
    }
  }
}

void Receiver::release_due(double now) {
  Frame f;
  while (jitter_.pop_due(now, f)) deliver(f, now);
}

void Receiver::deliver(const Frame& f, double now) {
  if (queue_.size() >= config_.queue_capacity) {
    queue_.pop_front();
    ++stats_.overflowed;
  }
  queue_.push_back(f);
  latest_ = f;
  have_latest_ = true;
  ++stats_.delivered;
  latencies_.push_back(now - f.receive_time);
  if (latencies_.size() > kLatencyWindow) latencies_.pop_front();
  delivery_times_.push_back(now);
  if (delivery_times_.size() > kRateWindow) delivery_times_.pop_front();
  if (recorder_) recorder_->push(f);  // never waits for the disk
  delivered_cv_.notify_all();
}

void Receiver::send_request(wire::RequestKind what, uint32_t id) {
  if (!have_sender_ || session_format_ != Format::softdeca) return;
  std::vector<uint8_t> bytes;
  wire::encode_request(session_, request_sequence_++, wire::Request{what, id}, bytes);
  if (socket_.send(bytes.data(), bytes.size(), sender_)) ++stats_.requests_sent;
}

bool Receiver::next(double timeout, Frame& out) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto ready = [&] { return !queue_.empty(); };
  if (!ready() && timeout > 0)
    delivered_cv_.wait_for(lock, std::chrono::duration<double>(std::min(timeout, 3600.0)), ready);
  if (queue_.empty()) return false;
  out = queue_.front();
  queue_.pop_front();
  return true;
}

uint64_t Receiver::session_lost() const {
  const uint64_t gaps = sequence_.lost();
  return gaps - std::min(gaps, holder_rate_limited_);
}

bool Receiver::latest(Frame& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (have_latest_) out = latest_;
  return have_latest_;
}

ReceiverStats Receiver::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  ReceiverStats s = stats_;
  s.lost = lost_before_ + session_lost();
  s.expected = expected_before_ + sequence_.expected();
  s.loss_ratio = s.expected ? double(s.lost) / double(s.expected) : 0.0;
  const double now = steady_seconds();
  if (delivery_times_.size() >= 2 && now - delivery_times_.back() < kRateHorizon) {
    std::size_t first = 0;
    while (delivery_times_[first] < now - kRateHorizon) ++first;
    const double span = delivery_times_.back() - delivery_times_[first];
    const std::size_t n = delivery_times_.size() - first;
    if (n >= 2 && span > 0) s.frame_rate_hz = double(n - 1) / span;
  }
  const std::vector<double> lat(latencies_.begin(), latencies_.end());
  s.latency_p50_ms = 1000.0 * percentile(lat, 0.5);
  s.latency_p99_ms = 1000.0 * percentile(lat, 0.99);
  s.recording_dropped = recording_dropped_before_ + (recorder_ ? recorder_->dropped() : 0);
  return s;
}

bool Receiver::profile(wire::Profile& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = profiles_.find(profile_in_use_);
  if (it == profiles_.end()) it = profiles_.find(newest_profile_);
  if (it == profiles_.end()) return false;
  out = it->second;
  return true;
}

bool Receiver::neutral(std::vector<float>& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (neutral_.empty()) return false;
  out = neutral_;
  return true;
}

bool Receiver::request_neutral() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!have_sender_ || session_format_ != Format::softdeca) return false;
  const uint64_t before = stats_.requests_sent;
  send_request(wire::RequestKind::neutral, 0);
  return stats_.requests_sent > before;
}

void Receiver::start_recording(const std::string& path, const recording::Header& header) {
  start_recording(std::make_unique<recording::RecordingWriter>(path, header), header);  // may throw: no lock held
}

void Receiver::start_recording(std::unique_ptr<recording::RecordingWriter> writer, const recording::Header& header) {
  require(writer != nullptr, "no writer to record into");
  auto recorder = std::make_unique<recording::BackgroundRecorder>(std::move(writer), config_.recording_queue);
  std::unique_ptr<recording::BackgroundRecorder> previous;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // What the stream already told us goes in first, so that the file is complete on its own
    // (at most kMaxProfiles + 1 records: the queue holds them).
    if (!header.has_profile)
      for (const auto& [id, p] : profiles_) recorder->push(p);
    if (header.neutral.empty() && !neutral_.empty()) recorder->push(neutral_);
    previous = std::move(recorder_);
    recorder_ = std::move(recorder);
    recording_error_.clear();
    frames_recorded_ = 0;
  }
  if (previous) previous->finish();
}

std::string Receiver::stop_recording() {
  std::unique_ptr<recording::BackgroundRecorder> recorder;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    recorder = std::move(recorder_);
  }
  const std::string error = recorder ? recorder->finish() : std::string();  // outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  if (recorder) {
    frames_recorded_ = recorder->frames_written();
    recording_dropped_before_ += recorder->dropped();
    if (recording_error_.empty()) recording_error_ = error;
  }
  return recording_error_;
}

std::size_t Receiver::frames_recorded() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return recorder_ ? recorder_->frames_written() : frames_recorded_;
}

}  // namespace softdeca::live
