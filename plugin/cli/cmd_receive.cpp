// softdeca receive: a live stream into frames on the console and, with --out, a recording.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <string>

#include "command.h"
#include "json.h"
#include "live/receiver.h"
#include "options.h"
#include "recording/recording_format.h"
#include "stop_limits.h"
#include "stream/steady_clock.h"
#include "stream_format_arg.h"

namespace softdeca::cli {
namespace {

// Set by SIGINT/SIGTERM: the only way a signal may talk to the loop.
std::atomic<bool> g_interrupted{false};
extern "C" void on_signal(int) { g_interrupted.store(true); }

std::string stats_json(const live::ReceiverStats& s, std::size_t recorded) {
  JsonObject o;
  const auto u = [&](const char* k, uint64_t v) { o.number(k, static_cast<double>(v)); };
  u("datagrams", s.datagrams);
  u("frames", s.frames);
  u("control_messages", s.control_messages);
  u("delivered", s.delivered);
  u("malformed", s.malformed);
  u("undersized", s.undersized);
  u("oversized", s.oversized);
  u("bad_magic", s.bad_magic);
  u("incompatible_version", s.incompatible_version);
  u("bad_length", s.bad_length);
  u("bad_value", s.bad_value);
  u("unknown_type", s.unknown_type);
  u("duplicates", s.duplicates);
  u("reordered", s.reordered);
  u("late", s.late);
  u("lost", s.lost);
  u("expected", s.expected);
  u("overflowed", s.overflowed);
  u("session_changes", s.session_changes);
  u("clock_resyncs", s.clock_resyncs);
  u("requests_sent", s.requests_sent);
  u("foreign", s.foreign);
  u("rate_limited", s.rate_limited);
  u("recording_dropped", s.recording_dropped);
  u("recorded", recorded);
  o.number("frame_rate_hz", s.frame_rate_hz);
  o.number("loss_ratio", s.loss_ratio);
  o.number("latency_p50_ms", s.latency_p50_ms);
  o.number("latency_p99_ms", s.latency_p99_ms);
  return o.str(true) + "\n";
}

void progress(const live::ReceiverStats& s, std::size_t recorded, bool recording) {
  std::fprintf(stderr,
               "\rframes %llu  %.1f Hz  lost %llu  late %llu  dup %llu  malformed %llu%s%llu   ",
               static_cast<unsigned long long>(s.delivered), s.frame_rate_hz,
               static_cast<unsigned long long>(s.lost), static_cast<unsigned long long>(s.late),
               static_cast<unsigned long long>(s.duplicates), static_cast<unsigned long long>(s.malformed),
               recording ? "  recorded " : "", recording ? static_cast<unsigned long long>(recorded) : 0ull);
  std::fflush(stderr);
}

}  // namespace

int run_receive(const Args& args) {
  Options o("receive",
            "Receive a live face stream over UDP: our protocol (docs/protocol.md), Epic's Live Link Face\n"
            "app (point it at this machine's address and port 11111) or iFacialMocap (port 49983).\n"
            "Frames are ordered in a jitter buffer; with --out every delivered frame is recorded.\n"
            "Stops on Ctrl-C or on --frames / --duration / --idle.");
  o.option("--format", "NAME", "auto, softdeca, livelinkface or ifacialmocap", "auto")
      .option("--bind", "ADDRESS", "numeric IPv4 or IPv6 address to listen on (default 127.0.0.1; 0.0.0.0 with --listen)")
      .flag("--listen", "accept datagrams from the network, not only this machine (docs/security.md)")
      .option("--hold", "SECONDS", "a sender holds the session until quiet this long; others are dropped", "2")
      .flag("--follow-newest", "a new sender takes the session at once (trusted networks only)")
      .option("--rate-limit", "HZ", "datagrams per second accepted from each sender (0: no limit)", "1000")
      .option("--port", "PORT", "UDP port; 0: any free port (default: the format's, ours 50110)")
      .option("--delay", "SECONDS", "jitter buffer delay", "0.05")
      .option("--out", "FILE", "record delivered frames into FILE (.sdrec)")
      .option("--subject", "NAME", "subject or take name written into the recording");
  StopLimits::declare(o, "delivered frames");
  o.option("--idle", "SECONDS", "stop this long after the last datagram, once one came (0: never)", "0")
      .option("--stats-json", "FILE", "write the final statistics as JSON")
      .flag("--quiet", "no progress line");
  if (!o.parse(args)) return 0;

  live::ReceiverConfig config;
  config.format = parse_format(o.text("--format"), true);
  config.listen_network = o.on("--listen");
  config.bind_address = o.given("--bind") ? o.text("--bind") : config.listen_network ? "0.0.0.0" : "127.0.0.1";
  config.session_hold = o.number("--hold");
  config.follow_newest = o.on("--follow-newest");
  config.source_rate_limit = o.number("--rate-limit");
  const long port = o.given("--port") ? o.integer("--port") : stream::default_port(config.format);
  if (port < 0 || port > 65535) throw UsageError("--port must be in [0, 65535]");
  config.port = static_cast<uint16_t>(port);
  config.delay = o.number("--delay");
  const StopLimits limits = StopLimits::read(o);
  const double idle = o.number("--idle");

  live::Receiver receiver(config);
  std::printf("listening on %s port %u (%s)\n", config.bind_address.c_str(), receiver.port(),
              stream::format_name(config.format));
  std::fflush(stdout);
  const bool recording = o.given("--out");
  if (recording) {
    recording::Header h;
    h.device = "softdeca receive";
    h.subject = o.text("--subject");
    h.source = std::string(stream::format_name(config.format)) + "-udp";
    h.clock = "sender seconds";
    h.start_unix_time = static_cast<double>(std::time(nullptr));
    receiver.start_recording(o.text("--out"), h);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  const double start = stream::steady_seconds();
  double last_progress = start, last_datagram = start;
  uint64_t datagrams = 0;
  stream::Frame frame;
  while (!g_interrupted.load()) {
    receiver.next(0.05, frame);  // frames are only counted here; recording happens in the receiver
    const double now = stream::steady_seconds();
    const live::ReceiverStats s = receiver.stats();
    if (s.datagrams != datagrams) {
      datagrams = s.datagrams;
      last_datagram = now;
    }
    if (!o.on("--quiet") && now - last_progress >= 1.0) {
      progress(s, receiver.frames_recorded(), recording);
      last_progress = now;
    }
    if (limits.reached(double(s.delivered), now - start) || (idle > 0 && datagrams > 0 && now - last_datagram >= idle))
      break;
  }
  receiver.stop();  // flushes the jitter buffer into the recording
  const std::size_t recorded = receiver.frames_recorded();
  const std::string error = receiver.stop_recording();
  const live::ReceiverStats s = receiver.stats();
  if (!o.on("--quiet")) {
    progress(s, recorded, recording);
    std::fputc('\n', stderr);
  }
  std::printf("received %llu frames (%llu datagrams, %llu lost, %llu late, %llu duplicates, %llu malformed)\n",
              static_cast<unsigned long long>(s.delivered), static_cast<unsigned long long>(s.datagrams),
              static_cast<unsigned long long>(s.lost), static_cast<unsigned long long>(s.late),
              static_cast<unsigned long long>(s.duplicates), static_cast<unsigned long long>(s.malformed));
  if (recording) std::printf("recorded %zu frames into %s\n", recorded, o.text("--out").c_str());
  if (o.given("--stats-json")) write_text_file(o.text("--stats-json"), stats_json(s, recorded));
  if (!error.empty()) {
    std::fprintf(stderr, "softdeca receive: the recording stopped early: %s\n", error.c_str());
    return 1;
  }
  return 0;
}

}  // namespace softdeca::cli
