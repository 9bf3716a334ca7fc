// The live receiver: a background thread reads datagrams from a UDP socket, decodes them
// (stream/datagram_decoder.h), drops and counts what is malformed, duplicated or late, tracks loss
// per sender session, orders frames in a jitter buffer, and hands them out in capture order.
// It listens on loopback unless told otherwise; the first sender holds the session until it
// has been quiet for `session_hold` seconds (others are counted and dropped), and every source
// is rate limited (docs/security.md). Optionally it records every delivered frame through a
// bounded queue to a writer thread (recording/background_recorder.h): a slow disk drops
// recorded frames, never stalls the receive thread or a poll. It stands above stream/ (its
// parts) and recording/ (what it records through); neither includes live/.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "live/receiver_stats.h"
#include "recording/background_recorder.h"
#include "stream/datagram_decoder.h"
#include "stream/jitter_buffer.h"
#include "stream/neutral_assembler.h"
#include "stream/sequence_tracker.h"
#include "stream/source_rate_limit.h"
#include "stream/udp_socket.h"

namespace softdeca::live {

struct ReceiverConfig {
  std::string bind_address = "127.0.0.1";  // numeric; not loopback only with listen_network
  bool listen_network = false;             // an explicit choice to accept datagrams from other hosts
  uint16_t port = 50110;  // 0: any free port (see Receiver::port)
  stream::Format format = stream::Format::automatic;
  double delay = 0;                  // jitter buffer delay in seconds, [0, 5]; 0: at once
  std::size_t queue_capacity = 256;  // delivered frames kept for next()
  double session_hold = 2.0;         // seconds, (0, 3600]: a quiet sender keeps the session this long
  bool follow_newest = false;        // true: any new sender takes the session at once
  double source_rate_limit = 1000;   // datagrams per second per source, [0, 100000]; 0: no limit
  std::size_t recording_queue = 256; // records waiting for the disk, [16, 65536]
};

class Receiver {
 public:
  // Binds the socket and starts the thread. Throws softdeca::Error.
  explicit Receiver(const ReceiverConfig& config);
  ~Receiver();  // stop()
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;

  uint16_t port() const { return port_; }
  // The oldest delivered frame not yet taken, waiting up to timeout seconds for one.
  bool next(double timeout, stream::Frame& out);
  // The newest delivered frame (taken or not).
  bool latest(stream::Frame& out) const;
  ReceiverStats stats() const;
  // The profile named by the newest frame with landmarks, else the newest profile received.
  bool profile(stream::wire::Profile& out) const;
  bool neutral(std::vector<float>& out) const;
  // Asks the current sender (our protocol only) for its neutral mesh; false without a sender.
  bool request_neutral();
  // Records every frame delivered from now on (and profiles and neutral meshes as they come).
  void start_recording(const std::string& path, const recording::Header& header);
  // The same into a writer the caller opened (`header` is the one it was opened with).
  void start_recording(std::unique_ptr<recording::RecordingWriter> writer, const recording::Header& header);
  // Stops recording; returns the error that stopped it early, "" if none.
  std::string stop_recording();
  // Frames written by the current or last recording.
  std::size_t frames_recorded() const;
  // Stops the thread and delivers what the jitter buffer still holds. Idempotent.
  void stop();

 private:
  void run();
  void handle(const uint8_t* data, std::size_t size, const stream::Endpoint& from, double now);
  void count_drop(stream::DropReason reason);
  void start_session(uint32_t session);
  // Sequence numbers of this session never received, less those the rate limit dropped.
  uint64_t session_lost() const;
  void on_frame(stream::Frame frame, const stream::Datagram& datagram, double now);
  void release_due(double now);
  void deliver(const stream::Frame& frame, double now);
  bool admit(const stream::Endpoint& from, double now);
  void send_request(stream::wire::RequestKind what, uint32_t id);

  ReceiverConfig config_;
  stream::UdpSocket socket_;
  uint16_t port_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread thread_;

  mutable std::mutex mutex_;  // everything below
  std::condition_variable delivered_cv_;
  ReceiverStats stats_;
  bool have_session_ = false;
  uint32_t session_ = 0;
  stream::Format session_format_ = stream::Format::softdeca;
  stream::SequenceTracker sequence_;
  uint64_t lost_before_ = 0;      // earlier sessions' losses
  // The holder's datagrams this session that the rate limit dropped: the sequence numbers they
  // leave out are counted in rate_limited, not lost.
  uint64_t holder_rate_limited_ = 0;
  uint64_t expected_before_ = 0;
  stream::JitterBuffer jitter_;
  std::array<float, stream::kBlendshapeCount> previous_weights_{};  // for sources that omit weights
  std::deque<stream::Frame> queue_;
  bool have_latest_ = false;
  stream::Frame latest_;
  std::map<uint32_t, stream::wire::Profile> profiles_;
  uint32_t newest_profile_ = 0;
  uint32_t profile_in_use_ = 0;
  stream::NeutralAssembler assembler_;
  std::vector<float> neutral_;
  bool have_sender_ = false;
  stream::Endpoint sender_;
  uint32_t request_sequence_ = 0;
  double last_profile_request_ = -1e9;
  std::deque<double> delivery_times_;  // recent, for the rate
  std::deque<double> latencies_;       // recent, seconds
  stream::SourceRateLimit rate_limit_;
  bool have_holder_ = false;  // the sender that holds the session, and when it was last heard
  std::string holder_;
  double holder_heard_ = 0;
  std::unique_ptr<recording::BackgroundRecorder> recorder_;
  std::string recording_error_;
  std::size_t frames_recorded_ = 0;   // of the last recording, once it has ended
  uint64_t recording_dropped_before_ = 0;
};

}  // namespace softdeca::live
