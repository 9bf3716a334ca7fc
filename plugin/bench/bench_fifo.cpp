#include "bench_fifo.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <future>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "core/error.h"
#include "live/receiver.h"
#include "recording/conversions.h"
#include "recording/livelinkface_csv.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "softdeca/softdeca.h"
#include "stream/steady_clock.h"

namespace softdeca::cli {
namespace {

// Milliseconds `use` took to refuse `fifo` with "is a FIFO".
double refusal_ms(const std::string& name, const std::string& fifo, const std::function<void()>& use) {
  const double start = stream::steady_seconds();
  auto result = std::async(std::launch::async, [&]() -> std::string {
    try {
      use();
      return "accepted the FIFO";
    } catch (const std::exception& e) {
      return e.what();
    }
  });
  if (result.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    const int other_end = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::close(other_end);
    result.wait();
    throw std::runtime_error(name + " blocked on a FIFO");
  }
  const double ms = 1000 * (stream::steady_seconds() - start);
  const std::string message = result.get();
  if (message.find("is a FIFO") == std::string::npos) throw std::runtime_error(name + ": " + message);
  return ms;
}

}  // namespace

FifoRefusal fifo_refusal_run(const std::string& scratch) {
  std::signal(SIGPIPE, SIG_IGN);  // freeing a blocked writer closes its reader
  const std::string fifo = scratch + "/bench-reliability-fifo.sdrec", fifo_csv = scratch + "/bench-reliability-fifo.csv";
  const std::string good = scratch + "/bench-reliability-good.sdrec";
  for (const std::string& p : {fifo, fifo_csv}) {
    std::filesystem::remove(p);
    if (::mkfifo(p.c_str(), 0600) != 0) throw std::runtime_error("cannot make a FIFO at " + p);
  }
  recording::RecordingWriter(good, recording::Header{}).write(stream::Frame{});
  live::ReceiverConfig config;
  config.port = 0;
  live::Receiver receiver(config);
  const std::vector<std::pair<std::string, std::function<void()>>> paths = {
      {"read a recording (info, play, replay)", [&] { recording::read_recording(fifo); }},
      {"read a CSV take (replay)", [&] { recording::read_livelinkface_csv(fifo_csv, 60); }},
      {"convert from CSV", [&] { recording::csv_to_recording(fifo_csv, scratch + "/bench-reliability-out.sdrec", 60); }},
      {"convert to CSV", [&] { recording::recording_to_csv(good, fifo_csv, 60); }},
      {"convert into a recording", [&] { recording::RecordingWriter(fifo, recording::Header{}); }},
      {"softdeca_player_load",
       [&] {
         softdeca_player* player = nullptr;
         if (softdeca_player_load(fifo.c_str(), &player) != SOFTDECA_OK) throw std::runtime_error(softdeca_last_error());
         softdeca_player_destroy(player);
       }},
      {"receive --out", [&] { receiver.start_recording(fifo, recording::Header{}); }},
  };
  FifoRefusal out;
  for (const auto& [name, use] : paths) {
    const double ms = refusal_ms(name, name.find("CSV") != std::string::npos ? fifo_csv : fifo, use);
    ++out.paths;
    if (ms >= out.worst_ms) {
      out.worst_ms = ms;
      out.worst = name;
    }
  }
  for (const std::string& p : {fifo, fifo_csv, good, scratch + "/bench-reliability-out.sdrec"}) std::filesystem::remove(p);
  return out;
}

}  // namespace softdeca::cli
