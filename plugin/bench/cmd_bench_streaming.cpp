// softdeca bench-streaming: receiver throughput and latency on loopback, decoder cost, and
// recording write and read rates, as medians over repeated runs -> build/bench/streaming.json.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>

#include "bench_figures.h"
#include "command.h"
#include "json.h"
#include "live/receiver.h"
#include "options.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "stream/frame_sender.h"
#include "stream/percentile.h"
#include "stream/steady_clock.h"
#include "stream/udp_socket.h"

namespace softdeca::cli {
namespace {
using stream::percentile;
using stream::steady_seconds;

constexpr std::size_t kLandmarks = 149;  // SparseSoftDECA's landmark profile (softdeca149)

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A plausible full frame: every weight, both poses, 68 landmarks in a face-sized box.
stream::Frame sample_frame(std::size_t i) {
  stream::Frame f;
  f.capture_time = 1000.0 + double(i) / 60.0;
  for (std::size_t k = 0; k < f.weights.size(); ++k) f.weights[k] = float(0.5 + 0.5 * std::sin(0.1 * double(i + k)));
  f.has_head = f.has_eyes = true;
  f.head.position = {0.01f, -0.02f, -0.4f};
  f.profile_id = 0x12345678;
  f.landmark_count = kLandmarks;
  for (std::size_t k = 0; k < 3 * kLandmarks; ++k) f.landmarks[k] = float(0.08 * std::sin(double(k) + 0.01 * double(i)));
  return f;
}

struct Receiving {
  live::Receiver receiver;
  std::atomic<bool> done{false};
  std::vector<double> latencies;  // send -> available, seconds
  double last_pop = 0;
  std::size_t popped = 0;
  std::thread consumer;

  explicit Receiving(const live::ReceiverConfig& c) : receiver(c) {
    consumer = std::thread([this] {
      stream::Frame f;
      while (!done.load()) {
        if (!receiver.next(0.01, f)) continue;
        const double now = steady_seconds();
        latencies.push_back(now - f.send_time);
        last_pop = now;
        ++popped;
      }
    });
  }
  void finish() {
    done.store(true);
    consumer.join();
  }
};

// The receiver's own throughput is measured with the per-source rate limit off (it would
// otherwise measure the limit: 1,000 datagrams a second); flood_run measures the limit.
live::ReceiverConfig loopback(double source_rate_limit = 0) {
  live::ReceiverConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;
  c.format = stream::Format::softdeca;
  c.delay = 0;
  c.queue_capacity = 65536;
  c.source_rate_limit = source_rate_limit;
  return c;
}

struct Throughput {
  double per_second;       // frames delivered per second
  double delivered_ratio;  // of the frames sent (the rest overflowed the socket's buffer)
  double cpu_us;           // process CPU time (all threads: sender, receiver, consumer) per frame
};

// User plus system CPU seconds of this process so far.
double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Frames sent as fast as the socket takes them; the rate at which the receiver delivers them.
Throughput throughput_run(std::size_t frames) {
  const double cpu_start = process_cpu_seconds();
  Receiving r(loopback());
  stream::FrameSender sender(stream::make_endpoint("127.0.0.1", r.receiver.port()), stream::Format::softdeca, 7);
  const double start = steady_seconds();
  for (std::size_t i = 0; i < frames; ++i) sender.send(sample_frame(i));
  // Done when nothing more arrives for 0.2 s.
  std::size_t seen = 0;
  for (double quiet_since = steady_seconds(); steady_seconds() - quiet_since < 0.2;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::size_t now_popped = r.receiver.stats().delivered;
    if (now_popped != seen) {
      seen = now_popped;
      quiet_since = steady_seconds();
    }
  }
  r.finish();
  if (r.popped < 2) throw std::runtime_error("the throughput run delivered no frames");
  // The 0.2 s of polling at the end costs next to no CPU: the figure is the streaming work.
  const double cpu = process_cpu_seconds() - cpu_start;
  return {double(r.popped) / (r.last_pop - start), double(r.popped) / double(frames), 1e6 * cpu / double(r.popped)};
}

struct Flood {
  double cpu_us_per_datagram;  // process CPU time per datagram the receiver read
  double dropped_ratio;        // of those, the share the rate limit dropped
};

// CPU time per frame of the sending side alone (encoding and the send call), into a socket
// nobody reads: what the throughput and flood runs' process CPU holds besides the receiver's.
double sender_cpu_us(std::size_t frames) {
  stream::UdpSocket sink("127.0.0.1", 0);
  stream::FrameSender sender(stream::make_endpoint("127.0.0.1", sink.local_port()), stream::Format::softdeca, 13);
  const double cpu_start = process_cpu_seconds();
  for (std::size_t i = 0; i < frames; ++i) sender.send(sample_frame(i));
  return 1e6 * (process_cpu_seconds() - cpu_start) / double(frames);
}

// One sender floods a receiver that keeps the default rate limit: what each datagram costs
// when nearly all are dropped before decoding.
Flood flood_run(std::size_t frames) {
  const double cpu_start = process_cpu_seconds();
  Receiving r(loopback(1000));
  stream::FrameSender sender(stream::make_endpoint("127.0.0.1", r.receiver.port()), stream::Format::softdeca, 11);
  for (std::size_t i = 0; i < frames; ++i) sender.send(sample_frame(i));
  uint64_t seen = 0;
  for (double quiet_since = steady_seconds(); steady_seconds() - quiet_since < 0.2;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const uint64_t now_seen = r.receiver.stats().datagrams;
    if (now_seen != seen) {
      seen = now_seen;
      quiet_since = steady_seconds();
    }
  }
  r.finish();
  const live::ReceiverStats s = r.receiver.stats();
  if (s.datagrams == 0) throw std::runtime_error("the flood run received nothing");
  const double cpu = process_cpu_seconds() - cpu_start;
  return {1e6 * cpu / double(s.datagrams), double(s.rate_limited) / double(s.datagrams)};
}

// Frames paced at `rate`; send -> available latencies of every frame.
std::vector<double> latency_run(std::size_t frames, double rate) {
  Receiving r(loopback());
  stream::FrameSender sender(stream::make_endpoint("127.0.0.1", r.receiver.port()), stream::Format::softdeca, 9);
  const double start = steady_seconds();
  for (std::size_t i = 0; i < frames; ++i) {
    const double due = start + double(i) / rate;
    while (steady_seconds() < due) std::this_thread::sleep_for(std::chrono::microseconds(50));
    sender.send(sample_frame(i));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  r.finish();
  return r.latencies;
}

double decode_run(std::size_t n) {
  std::vector<uint8_t> bytes;
  stream::Frame f = sample_frame(1);
  stream::wire::encode_frame(f, bytes);
  stream::wire::Message m;
  std::size_t ok = 0;
  const double start = steady_seconds();
  for (std::size_t i = 0; i < n; ++i) ok += stream::wire::decode(bytes.data(), bytes.size(), m).reason == stream::DropReason::none;
  const double ns = (steady_seconds() - start) * 1e9 / double(n);
  if (ok != n) throw std::runtime_error("the decoder rejected the benchmark's own frames");
  return ns;
}

struct RecordingRates {
  double write_fps, read_fps, bytes_per_frame;
};

RecordingRates recording_run(const std::string& path, std::size_t frames) {
  recording::Header h;
  h.device = "bench";
  double start = steady_seconds();
  {
    recording::RecordingWriter w(path, h);
    for (std::size_t i = 0; i < frames; ++i) w.write(sample_frame(i));
  }
  const double write_s = steady_seconds() - start;
  start = steady_seconds();
  const recording::Recording rec = recording::read_recording(path);
  const double read_s = steady_seconds() - start;
  if (rec.frames.size() != frames) throw std::runtime_error("the benchmark recording did not read back whole");
  std::FILE* f = std::fopen(path.c_str(), "rb");
  std::fseek(f, 0, SEEK_END);
  const double bytes = double(std::ftell(f));
  std::fclose(f);
  std::remove(path.c_str());
  return {double(frames) / write_s, double(frames) / read_s, bytes / double(frames)};
}

}  // namespace

int run_bench_streaming(const Args& args) {
  Options o("bench-streaming",
            "Measure the streaming path on this machine: receiver throughput on 127.0.0.1 (frames blasted\n"
            "as fast as the socket takes them, the per-source rate limit off), what the rate limit costs\n"
            "per datagram under a flood, latency from send to frame available (frames paced),\n"
            "decoder cost, recording write and read rates. Medians over --runs runs; writes the figures\n"
            "as JSON (the benchmark format of docs/ARCHITECTURE.md, Conventions).");
  declare_output_options(o, "streaming", "where the recording runs write their file");
  o.option("--runs", "N", "repetitions of each measurement", "5")
      .option("--throughput-frames", "N", "frames blasted per throughput run", "100000")
      .option("--latency-frames", "N", "frames per latency run", "2000")
      .option("--latency-rate", "HZ", "send rate of the latency runs", "1000")
      .option("--recording-frames", "N", "frames per recording run", "20000");
  if (!o.parse(args)) return 0;
  const std::string scratch = create_output_folders(o);
  const long runs = o.integer("--runs"), tp = o.integer("--throughput-frames"), lat = o.integer("--latency-frames"),
             recf = o.integer("--recording-frames");
  const double lat_rate = o.number("--latency-rate");
  if (runs < 1 || tp < 100 || lat < 100 || recf < 100 || !(lat_rate > 0))
    throw UsageError("runs >= 1, frame counts >= 100 and a positive rate, please");
  std::vector<uint8_t> probe;
  stream::wire::encode_frame(sample_frame(0), probe);

  std::vector<double> tput, delivered, cpu_us, p50, p99, decode_ns, write_fps, read_fps, flood_us, flood_dropped,
      sender_us;
  double load = load_average();
  double bytes_per_frame = 0;
  for (long run = 0; run < runs; ++run) {
    std::fprintf(stderr, "\rbench-streaming: run %ld/%ld: throughput", run + 1, runs);
    const Throughput t = throughput_run(static_cast<std::size_t>(tp));
    tput.push_back(t.per_second);
    delivered.push_back(t.delivered_ratio);
    cpu_us.push_back(t.cpu_us);
    std::fprintf(stderr, ", flood");
    const Flood fl = flood_run(static_cast<std::size_t>(tp));
    flood_us.push_back(fl.cpu_us_per_datagram);
    flood_dropped.push_back(fl.dropped_ratio);
    sender_us.push_back(sender_cpu_us(static_cast<std::size_t>(tp)));
    std::fprintf(stderr, ", latency");
    const auto l = latency_run(static_cast<std::size_t>(lat), lat_rate);
    if (l.size() < static_cast<std::size_t>(lat) / 2) throw std::runtime_error("most latency frames were lost");
    p50.push_back(1000 * percentile(l, 0.5));
    p99.push_back(1000 * percentile(l, 0.99));
    std::fprintf(stderr, ", decode");
    decode_ns.push_back(decode_run(200000));
    std::fprintf(stderr, ", recording   ");
    const auto r = recording_run(scratch + "/bench-streaming.sdrec", static_cast<std::size_t>(recf));
    write_fps.push_back(r.write_fps);
    read_fps.push_back(r.read_fps);
    bytes_per_frame = r.bytes_per_frame;
    load = std::max(load, load_average());
  }
  std::fputc('\n', stderr);

  char load_text[80];
  std::snprintf(load_text, sizeof load_text, " (2-core machine load average up to %.1f during the runs)", load);
  const std::string cmd = "softdeca bench-streaming --runs " + std::to_string(runs) + load_text;
  const std::string frame = std::to_string(probe.size()) + "-byte frame datagrams (52 weights, head and eye poses, " +
                            std::to_string(kLandmarks) + " landmarks)";
  JsonObject out;
  out.raw("streaming.datagrams_per_s",
          figure(median(tput), "datagrams/s", "20000", "higher",
                 cmd + ": median of " + std::to_string(runs) + " runs; " + std::to_string(tp) + " " + frame +
                     " sent as fast as possible to a receiver on 127.0.0.1 (no jitter delay, per-source rate "
                     "limit off); frames delivered per second from the first send to the last delivery"));
  out.raw("streaming.cpu_us_per_datagram",
          figure(median(cpu_us), "us", "null", "lower",
                 cmd + ": in the throughput runs, the process's CPU time (sender, receiver and consumer "
                       "threads, user + system) per frame delivered; unlike the rate, it does not depend on "
                       "what else the machine runs"));
  out.raw("streaming.blast_delivered_ratio",
          figure(median(delivered), "ratio", "1.0", "higher",
                 cmd + ": in the throughput runs, the share of frames delivered (the rest overflowed the "
                       "socket's receive buffer while the receiver was behind)"));
  const double sender = median(sender_us);
  const std::string sender_text = "; less the sending side's " + json_number(sender) +
                                  " us per frame (encoding and sending into a socket nobody reads)";
  out.raw("streaming.receive_cpu_us_per_datagram",
          figure(std::max(0.0, median(cpu_us) - sender), "us", "null", "lower",
                 cmd + ": streaming.cpu_us_per_datagram (every datagram decoded and delivered, rate limit off)" +
                     sender_text));
  out.raw("streaming.rate_limited_cpu_us_per_datagram",
          figure(std::max(0.0, median(flood_us) - sender), "us", "null", "lower",
                 cmd + ": one sender blasting " + std::to_string(tp) + " " + frame + " at a receiver with the "
                       "default per-source rate limit (1,000/s), a median share of " +
                       json_number(median(flood_dropped)) + " dropped by the limit before decoding: the process's "
                       "CPU time per datagram read" + sender_text +
                       "; what the receiver spends on a datagram the limit drops"));
  const std::string lat_how = cmd + ": median over " + std::to_string(runs) + " runs of the percentile over " +
                              std::to_string(lat) + " " + frame + " sent at " + json_number(lat_rate) +
                              " Hz to 127.0.0.1; from the sender's clock reading before encoding to the consumer "
                              "thread holding the frame (no jitter delay)";
  out.raw("streaming.latency_p50_ms", figure(median(p50), "ms", "0.5", "lower", lat_how));
  out.raw("streaming.latency_p99_ms", figure(median(p99), "ms", "1.0", "lower", lat_how));
  out.raw("streaming.decode_ns_per_datagram",
          figure(median(decode_ns), "ns", "null", "lower",
                 cmd + ": median of " + std::to_string(runs) + " runs of decoding one " + frame + " 200000 times"));
  const std::string rec_how = cmd + ": median of " + std::to_string(runs) + " runs; " + std::to_string(recf) +
                              " frames with " + std::to_string(kLandmarks) + " landmarks (" +
                              json_number(bytes_per_frame) + " bytes each on disk)";
  out.raw("streaming.recording_write_frames_per_s",
          figure(median(write_fps), "frames/s", "null", "higher", rec_how + ", each record flushed to the OS"));
  out.raw("streaming.recording_write_mb_per_s",
          figure(median(write_fps) * bytes_per_frame / 1e6, "MB/s", "null", "higher", rec_how));
  out.raw("streaming.recording_read_frames_per_s",
          figure(median(read_fps), "frames/s", "null", "higher", rec_how + ", read and checked back"));
  write_text_file(o.text("--out"), out.str(true) + "\n");
  std::printf("%s\n", out.str(true).c_str());
  return 0;
}

}  // namespace softdeca::cli
