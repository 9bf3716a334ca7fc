// softdeca play: a recording in real time, as JSON lines or streamed over UDP.
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <thread>

#include "command.h"
#include "json.h"
#include "options.h"
#include "read_limits_arg.h"
#include "recording/player.h"
#include "stop_limits.h"
#include "stream/frame_sender.h"
#include "stream/steady_clock.h"
#include "stream_format_arg.h"

namespace softdeca::cli {
namespace {

std::string frame_json(double t, const stream::Frame& f) {
  JsonObject o;
  o.number("t", t).number("capture_time", f.capture_time).number("tracking", static_cast<int>(f.tracking));
  o.raw("weights", json_array(f.weights.data(), f.weights.size()));
  if (f.has_head) o.raw("head_rotation", json_array(f.head.rotation.data(), 4));
  if (f.landmark_count) {
    o.number("profile_id", f.profile_id);
    o.raw("landmarks", json_array(f.landmarks.data(), 3u * f.landmark_count));
  }
  return o.str();
}

void sleep_for(double seconds) {
  if (seconds > 0) std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

}  // namespace

int run_play(const Args& args) {
  Options o("play",
            "Play a recording in real time. Without --send, every frame is printed as a JSON line when\n"
            "its time comes; with --send, frames go out over UDP (our protocol with its landmark profile\n"
            "and neutral mesh, or Live Link Face's packets), so a recording can stand in for a phone.\n"
            "Recorded frames keep their timing; --rate instead samples interpolated frames at a fixed rate.");
  o.positional("RECORDING", "a .sdrec file")
      .option("--speed", "X", "playback speed, > 0", "1")
      .flag("--loop", "start over at the end (stop with --frames, --duration or Ctrl-C)")
      .option("--start", "SECONDS", "start this far into the recording", "0")
      .option("--rate", "HZ", "output interpolated frames at this rate instead of the recorded ones")
      .option("--send", "HOST:PORT", "stream over UDP to this numeric address instead of printing")
      .option("--format", "NAME", "what --send sends: softdeca or livelinkface", "softdeca");
  StopLimits::declare(o, "frames");
  declare_read_limits(o);
  o.flag("--quiet", "print nothing but errors");
  if (!o.parse(args)) return 0;
  recording::Player player(recording::RecordingIndex::open(o.arg(0), read_limits(o)));
  const double speed = o.number("--speed");
  if (!(speed > 0)) throw UsageError("--speed must be > 0");
  player.set_speed(speed);
  player.set_loop(o.on("--loop"));
  player.seek(o.number("--start"));
  const StopLimits limits = StopLimits::read(o);
  const double rate = o.given("--rate") ? o.number("--rate") : 0;
  if (o.given("--rate") && !(rate > 0 && rate <= 10000)) throw UsageError("--rate must be in (0, 10000]");

  const auto& rec = player.recording();
  const stream::wire::Profile* profile = rec.profiles.empty() ? nullptr : &rec.profiles.back();
  const bool quiet = o.on("--quiet");
  std::unique_ptr<stream::FrameSender> sender;
  stream::Format format = stream::Format::softdeca;
  if (o.given("--send")) {
    format = parse_format(o.text("--format"), false);
    std::random_device entropy;  // a fresh session id tells receivers this is a new stream
    sender = std::make_unique<stream::FrameSender>(stream::parse_endpoint(o.text("--send")), format, entropy() | 1u);
    sender->livelinkface_info().device_id = "softdeca-play";
    sender->livelinkface_info().subject = rec.header.subject.empty() ? "take" : rec.header.subject;
    if (format == stream::Format::softdeca) {
      if (profile) sender->send_profile(*profile);
      if (!rec.neutral.empty()) sender->send_neutral(rec.neutral);
    }
  }

  const double wall_start = stream::steady_seconds();
  double last_profile = wall_start;
  long emitted = 0;
  const auto emit = [&](const stream::Frame& f, double t) {
    if (!sender) {
      if (!quiet) std::printf("%s\n", frame_json(t, f).c_str());
    } else {
      sender->send(f);
      if (format == stream::Format::softdeca) {
        sender->answer_requests(profile, &rec.neutral);
        const double now = stream::steady_seconds();
        if (profile && now - last_profile >= 1.0) {  // late joiners learn the profile within a second
          sender->send_profile(*profile);
          last_profile = now;
        }
      }
    }
    ++emitted;
  };
  const auto done = [&] { return limits.reached(double(emitted), stream::steady_seconds() - wall_start); };

  if (rate > 0) {
    // Fixed-rate sampling through the player: interpolated frames, speed and looping.
    double tick = wall_start, last = wall_start;
    bool ended = false;
    while (!done()) {
      emit(player.frame_at(player.position()), player.position());
      if (ended) break;
      tick += 1.0 / rate;
      sleep_for(tick - stream::steady_seconds());
      const double now = stream::steady_seconds();
      ended = player.advance(now - last);
      last = now;
    }
  } else {
    // Recorded frames at their own times; a loop lasts one frame interval longer than the take,
    // so that the last and the first frame do not coincide.
    const std::size_t n = player.frame_count();
    const double cycle = player.duration() + (n > 1 ? player.duration() / double(n - 1) : 1.0 / 30);
    const double start = player.position();
    std::size_t i = 0;
    while (i < n && player.frame_time(i) < start) ++i;
    for (long k = 0; !done();) {
      if (i == n) {
        if (!player.loop()) break;
        i = 0;
        ++k;
      }
      const double t = double(k) * cycle + player.frame_time(i);
      sleep_for(wall_start + (t - start) / speed - stream::steady_seconds());
      emit(player.frame(i), player.frame_time(i));
      ++i;
    }
  }
  std::fflush(stdout);
  if (sender && !quiet)
    std::fprintf(stderr, "sent %ld frames to %s (%s)\n", emitted, o.text("--send").c_str(), stream::format_name(format));
  return 0;
}

}  // namespace softdeca::cli
