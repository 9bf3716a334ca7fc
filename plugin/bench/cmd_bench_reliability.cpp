// softdeca bench-reliability: the receiver and the recording reader under hostile input on
// this machine -> build/bench/reliability.json. A flood of iFacialMocap datagrams from many
// source ports on loopback while recording; a crafted damaged recording; a recording whose
// disk cannot keep up while a consumer polls; with an avatar, what fitting a large mesh and a head
// full of sliver triangles costs.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench_bundle_memory.h"
#include "bench_fifo.h"
#include "bench_import_memory.h"
#include "bench_figures.h"
#include "bench_fit_cost.h"
#include "bench_recording_memory.h"
#include "command.h"
#include "imported_avatar.h"
#include "json.h"
#include "live/receiver.h"
#include "options.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "stream/frame_sender.h"
#include "stream/percentile.h"
#include "stream/steady_clock.h"

namespace softdeca::cli {
namespace {
using stream::steady_seconds;

live::ReceiverConfig loopback(stream::Format format) {
  live::ReceiverConfig c;
  c.port = 0;
  c.format = format;
  c.queue_capacity = 65536;
  return c;
}

struct Flood {
  uint64_t session_changes = 0, delivered = 0, foreign = 0, rate_limited = 0, datagrams_sent = 0;
  std::size_t recorded = 0;
  double recording_mb = 0;
};

// `ports` senders, round robin, as fast as the socket takes them, for `seconds`, recording.
Flood flood_run(const std::string& path, int ports, double seconds) {
  live::Receiver r(loopback(stream::Format::ifacialmocap));
  recording::Header h;
  h.source = "bench-reliability flood";
  r.start_recording(path, h);
  std::atomic<bool> done{false};
  std::thread consumer([&] {
    stream::Frame f;
    while (!done.load()) r.next(0.01, f);
  });
  const stream::Endpoint to = stream::make_endpoint("127.0.0.1", r.port());
  std::vector<std::unique_ptr<stream::FrameSender>> senders;
  for (int i = 0; i < ports; ++i)
    senders.push_back(std::make_unique<stream::FrameSender>(to, stream::Format::ifacialmocap, 0));
  const std::string text = "jawOpen-40|mouthSmile_L-10|eyeBlink_R-3|browInnerUp-25|";
  Flood out;
  const double start = steady_seconds();
  while (steady_seconds() - start < seconds)
    for (auto& s : senders) {
      s->send_raw(reinterpret_cast<const uint8_t*>(text.data()), text.size());
      ++out.datagrams_sent;
    }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  r.stop();
  r.stop_recording();
  done.store(true);
  consumer.join();
  const live::ReceiverStats s = r.stats();
  out.session_changes = s.session_changes;
  out.delivered = s.delivered;
  out.foreign = s.foreign;
  out.rate_limited = s.rate_limited;
  out.recorded = r.frames_recorded();
  out.recording_mb = double(std::filesystem::file_size(path)) / 1e6;
  std::filesystem::remove(path);
  return out;
}

// A recording of a few good frames, `mib` MiB of record headers that each claim 64 KiB with a
// wrong checksum (a candidate every 12 bytes), then good frames again. Seconds per MiB read.
double resync_run(const std::string& path, std::size_t mib) {
  {
    recording::RecordingWriter w(path, recording::Header{});
    stream::Frame f;
    f.capture_time = 1;
    w.write(f);
  }
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> head((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<uint8_t> bytes = head;
  const uint8_t candidate[12] = {'S', 'D', 'R', 'C', 0x00, 0x00, 0x01, 0x00, 0xEF, 0xBE, 0xAD, 0xDE};
  while (bytes.size() < head.size() + (mib << 20)) bytes.insert(bytes.end(), candidate, candidate + 12);
  const double start = steady_seconds();
  const recording::Recording rec = recording::parse_recording(bytes.data(), bytes.size());
  const double elapsed = steady_seconds() - start;
  std::filesystem::remove(path);
  if (rec.frames.size() != 1) throw std::runtime_error("the crafted recording lost its good frame");
  return elapsed / (double(bytes.size()) / double(1 << 20));
}

struct SlowDisk {
  double poll_p99_ms = 0, poll_max_ms = 0;
  uint64_t delivered = 0, recording_dropped = 0;
  std::size_t recorded = 0;
};

// The recording goes into a pipe drained at `drain_bytes_per_s` (a disk far slower than the
// stream); frames arrive at `rate` Hz; a consumer polls latest() and next(0) every millisecond.
SlowDisk slow_disk_run(double seconds, double rate, double drain_bytes_per_s) {
  int ends[2];
  if (::pipe(ends) != 0) throw std::runtime_error("cannot make a pipe");
  const int reader = ends[0];
  ::fcntl(reader, F_SETFL, O_NONBLOCK);
  std::atomic<bool> done{false}, draining_all{false};
  std::thread drain([&] {
    char buf[4096];
    const double chunk_s = double(sizeof buf) / drain_bytes_per_s;
    while (!done.load()) {
      if (::read(reader, buf, sizeof buf) <= 0 || !draining_all.load())
        std::this_thread::sleep_for(std::chrono::duration<double>(draining_all.load() ? 0.001 : chunk_s));
    }
  });
  live::ReceiverConfig c = loopback(stream::Format::softdeca);
  c.source_rate_limit = 0;
  live::Receiver r(c);
  r.start_recording(std::make_unique<recording::RecordingWriter>(FilePtr(::fdopen(ends[1], "wb")), "pipe",
                                                                  recording::Header{}),
                    recording::Header{});
  stream::FrameSender sender(stream::make_endpoint("127.0.0.1", r.port()), stream::Format::softdeca, 3);
  std::vector<double> polls;
  stream::Frame f;
  f.landmark_count = 149;
  const double start = steady_seconds();
  for (std::size_t i = 0; steady_seconds() - start < seconds; ++i) {
    const double due = start + double(i) / rate;
    while (steady_seconds() < due) {
      const double t0 = steady_seconds();
      stream::Frame got;
      r.latest(got);
      r.next(0, got);
      polls.push_back(steady_seconds() - t0);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    f.capture_time = 10 + double(i) / rate;
    sender.send(f);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  SlowDisk out;
  const live::ReceiverStats s = r.stats();
  out.delivered = s.delivered;
  out.recording_dropped = s.recording_dropped;
  draining_all.store(true);
  r.stop();
  r.stop_recording();
  out.recorded = r.frames_recorded();
  done.store(true);
  drain.join();
  ::close(reader);
  out.poll_p99_ms = 1000 * stream::percentile(polls, 0.99);
  out.poll_max_ms = 1000 * *std::max_element(polls.begin(), polls.end());
  return out;
}

// The figures of the runs that need inputs (--bundle, --import-corpus, --avatar), where given.
void optional_figures(JsonObject& out, const std::string& how, const Options& o, long budget_mib, const BundleMemory& bundles,
                      const ImportMemory& imports, const FitCost& fits) {
  if (bundles.bundles > 0) {
    char bundle_text[1024];
    std::snprintf(bundle_text, sizeof bundle_text,
                  "%d copies of %s, each grown by one fragment of constant inputs (a ConstantOfShape, an Expand, a "
                  "ConstantOfShape of a shape made by a Mul, a Gather or a Shape and Concat, a self-Concat, a MatMul "
                  "outer product) sized just under, just over and 64 times over a %ld MiB budget, "
                  "loaded in a child process each (%d loaded, %d refused) after the unchanged bundle warmed ONNX "
                  "Runtime up; the worst peak RSS increase while loading (VmHWM, reset before, over VmRSS before) "
                  "over the budget: %s",
                  bundles.bundles, o.text("--bundle").c_str(), budget_mib, bundles.loaded, bundles.refused,
                  bundles.worst.c_str());
    out.raw("reliability.bundle_peak_rss_over_budget",
            figure(bundles.worst_ratio, "ratio", "1.0", "lower", how + bundle_text));
    out.raw("reliability.runtime_start_rss_mib",
            figure(double(bundles.runtime_start_bytes) / double(1 << 20), "MiB", "null", "lower",
                   how + "the peak RSS increase of the first Model::load of " + o.text("--bundle") +
                       " in a fresh process: ONNX Runtime's start, once a process, outside the memory budget"));
  }
  if (imports.avatars > 0) {
    char import_text[600];
    std::snprintf(import_text, sizeof import_text,
                  "the %d avatars of %s that softdeca fit reads (%d read, %d refused), each read in a child "
                  "process; the worst peak RSS increase while reading (VmHWM, reset before, over VmRSS before) "
                  "over the input's bytes + 125 MB, so that 4 is the bound 4 x the input + 500 MB: %s",
                  imports.avatars, o.text("--import-corpus").c_str(), imports.read, imports.refused, imports.worst.c_str());
    out.raw("reliability.import_peak_rss_over_input", figure(imports.worst_ratio, "ratio", "4", "lower", how + import_text));
  }
  if (fits.vertices > 0) {
    const std::string fit_text = fits.describe(o.text("--avatar"), o.text("--bundle"));
    out.raw("reliability.fit_s_per_100k_vertices", figure(fits.seconds_per_100k(), "s", "1.5", "lower", how + fit_text));
    out.raw("reliability.fit_memory_over_target", figure(fits.memory_over_target(), "ratio", "1.0", "lower", how + fit_text));
    out.raw("reliability.fit_slivers_s", figure(fits.sliver.seconds, "s", "60", "lower", how + fit_text));
  }
}

}  // namespace

int run_bench_reliability(const Args& args) {
  Options o("bench-reliability",
            "Measure the receiver and the recording reader under hostile input (docs/security.md): an\n"
            "iFacialMocap flood from many source ports on 127.0.0.1 while recording (session changes,\n"
            "recording growth), the reader on a crafted damaged recording (seconds per MiB), and the\n"
            "consumer's poll while the recording's disk cannot keep up (p99 poll time), and how long every\n"
            "path that opens a recording or CSV take takes to refuse a FIFO, and the memory an opened\n"
            "recording holds per frame; with --bundle, the peak memory of loading copies of that bundle\n"
            "grown by one constant-foldable fragment each, just under, just over and far over a budget; with\n"
            "--import-corpus, the peak memory of reading each hostile avatar against the avatar's size; with\n"
            "--bundle and --avatar, the fit of that avatar subdivided to --fit-vertices vertices (time and\n"
            "peak memory) and of the avatar with 20,000 sliver triangles added.");
  declare_output_options(o, "reliability", "where the runs write their files");
  o.option("--ports", "N", "source ports of the flood", "200")
      .option("--flood-seconds", "S", "how long the flood lasts", "3")
      .option("--resync-mib", "N", "MiB of crafted damage", "16")
      .option("--slow-seconds", "S", "how long the slow-disk run lasts", "3")
      .option("--bundle", "DIR", "a small bundle folder to grow (the runtime test data's bundle)", "")
      .option("--bundle-budget-mib", "N", "the memory budget of the bundle runs", "256")
      .option("--import-corpus", "DIR", "hostile avatars to read (python -m softdeca_train hostile-avatars)", "")
      .option("--avatar", "MESH", "an avatar the bundle fits (the runtime test data's avatar folder)", "")
      .option("--avatar-unit", "X", "the avatar's metres per unit (0: read off its shapes)", "0")
      .option("--fit-vertices", "N", "the vertices of the large avatar's fit (at least)", "500000");
  if (!o.parse(args)) return 0;
  const std::string scratch = create_output_folders(o);
  const long ports = o.integer("--ports"), mib = o.integer("--resync-mib");
  const double flood_s = o.number("--flood-seconds"), slow_s = o.number("--slow-seconds");
  const long budget_mib = o.integer("--bundle-budget-mib");
  if (ports < 2 || ports > 1000 || mib < 1 || mib > 1024 || !(flood_s > 0) || !(slow_s > 0) || budget_mib < 16 ||
      budget_mib > 4096)
    throw UsageError("2 to 1000 ports, 1 to 1024 MiB, positive durations and a 16 to 4096 MiB budget, please");
  // Subdividing quadruples the vertices: at most a quarter of the limit asked keeps the fit within it.
  if (o.integer("--fit-vertices") < 1000 || o.integer("--fit-vertices") > long{SOFTDECA_MAX_AVATAR_VERTICES / 4} ||
      !(o.number("--avatar-unit") >= 0))
    throw UsageError("--fit-vertices from 1000 to a quarter of the avatar vertex limit and an --avatar-unit of 0 or more, please");
  double load = load_average();

  std::fprintf(stderr, "bench-reliability: flood");
  const Flood flood = flood_run(scratch + "/bench-reliability-flood.sdrec", static_cast<int>(ports), flood_s);
  load = std::max(load, load_average());
  std::fprintf(stderr, ", resync");
  const double resync = resync_run(scratch + "/bench-reliability-resync.sdrec", static_cast<std::size_t>(mib));
  std::fprintf(stderr, ", slow disk\n");
  const SlowDisk slow = slow_disk_run(slow_s, 240, 16384);
  load = std::max(load, load_average());
  std::fprintf(stderr, "bench-reliability: FIFOs\n");
  const FifoRefusal fifo = fifo_refusal_run(scratch);
  std::fprintf(stderr, "bench-reliability: recording memory\n");
  const RecordingMemory memory = recording_memory_run(scratch + "/bench-reliability-memory.sdrec", 20000);
  BundleMemory bundles;
  if (!o.text("--bundle").empty()) {
    std::fprintf(stderr, "bench-reliability: bundle memory\n");
    bundles = bundle_memory_run(o.text("--bundle"), scratch, std::uint64_t(budget_mib) << 20);
  }
  ImportMemory imports;
  if (!o.text("--import-corpus").empty()) {
    std::fprintf(stderr, "bench-reliability: import memory\n");
    imports = import_memory_run(o.text("--import-corpus"));
  }
  FitCost fits;
  if (!o.text("--bundle").empty() && !o.text("--avatar").empty()) {
    std::fprintf(stderr, "bench-reliability: fits\n");
    fits = fit_cost_run(o.text("--bundle"), o.text("--avatar"), static_cast<std::size_t>(o.integer("--fit-vertices")),
                        o.number("--avatar-unit"));
  }

  char load_text[80];
  std::snprintf(load_text, sizeof load_text, " (machine load average up to %.1f during the runs)", load);
  const std::string how = std::string("softdeca bench-reliability") + load_text + ": ";
  char flood_text[400];
  std::snprintf(flood_text, sizeof flood_text,
                "%ld source ports on 127.0.0.1 sent %llu iFacialMocap datagrams in %.1f s while recording; "
                "%llu frames delivered, %zu recorded, %llu dropped from other senders, %llu over the rate limit",
                ports, static_cast<unsigned long long>(flood.datagrams_sent), flood_s,
                static_cast<unsigned long long>(flood.delivered), flood.recorded,
                static_cast<unsigned long long>(flood.foreign), static_cast<unsigned long long>(flood.rate_limited));
  char slow_text[400];
  std::snprintf(slow_text, sizeof slow_text,
                "frames with 149 landmarks at 240 Hz for %.0f s recorded into a pipe drained at 16 KiB/s; the "
                "consumer polled latest() and next(0) every ms; %llu delivered, %zu recorded, %llu recording drops; "
                "worst poll %.3f ms",
                slow_s, static_cast<unsigned long long>(slow.delivered), slow.recorded,
                static_cast<unsigned long long>(slow.recording_dropped), slow.poll_max_ms);
  JsonObject out;
  out.raw("reliability.flood_session_changes",
          figure(double(flood.session_changes), "changes", "2", "lower", how + flood_text));
  out.raw("reliability.flood_recording_mb", figure(flood.recording_mb, "MB", "1", "lower", how + flood_text));
  out.raw("reliability.resync_s_per_mib",
          figure(resync, "s/MiB", "0.5", "lower",
                 how + std::to_string(mib) + " MiB of record headers claiming 64 KiB with wrong checksums, one "
                       "every 12 bytes, parsed in memory"));
  out.raw("reliability.poll_p99_ms_slow_disk", figure(slow.poll_p99_ms, "ms", "1", "lower", how + slow_text));
  out.raw("reliability.fifo_open_ms",
          figure(fifo.worst_ms, "ms", "100", "lower",
                 how + "the slowest of " + std::to_string(fifo.paths) + " paths that open a recording or CSV take ("
                       + fifo.worst + ") to refuse a FIFO nobody writes"));
  char memory_text[300];
  std::snprintf(memory_text, sizeof memory_text,
                "a recording of %zu frames with 149 landmarks (%.0f bytes a frame on disk) opened for playing; the "
                "heap it holds (glibc mallinfo2), per frame",
                memory.frames, memory.file_bytes_per_frame);
  out.raw("reliability.recording_bytes_per_frame_in_memory",
          figure(memory.heap_bytes_per_frame, "bytes/frame", "64", "lower", how + memory_text));
  optional_figures(out, how, o, budget_mib, bundles, imports, fits);
  write_text_file(o.text("--out"), out.str(true) + "\n");
  std::printf("%s\n", out.str(true).c_str());
  return 0;
}

}  // namespace softdeca::cli
