// Recording and take paths that are not regular files (docs/security.md, "Recordings"): every
// path that reads or writes a recording or a Live Link Face CSV refuses a FIFO at once with a
// clear error instead of blocking in open, and a folder with an invalid-argument error.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <future>
#include <string>
#include <thread>

#include "core/error.h"
#include "live/receiver.h"
#include "recording/conversions.h"
#include "recording/livelinkface_csv.h"
#include "recording/recording_reader.h"
#include "recording/recording_writer.h"
#include "softdeca/softdeca.h"
#include "stream_test_support.h"

using namespace softdeca;

namespace {

class RecordingFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    std::signal(SIGPIPE, SIG_IGN);  // releasing a blocked writer below closes its reader
    dir_ = test::temp_path("recording-files");
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    fifo_ = dir_ + "/take.sdrec";
    fifo_csv_ = dir_ + "/take.csv";
    ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
    ASSERT_EQ(::mkfifo(fifo_csv_.c_str(), 0600), 0);
    good_ = dir_ + "/good.sdrec";
    recording::RecordingWriter w(good_, recording::Header{});
    w.write(test::make_frame(1, 0, 0));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Runs `use` (which must refuse `fifo`) and returns the error message; fails when it has not
  // returned within 10 s, then opens and closes the FIFO's other end so that code blocked in
  // open fails the test instead of hanging it.
  std::string refused(const std::string& fifo, const std::function<void()>& use,
                      softdeca_status status = SOFTDECA_ERROR_INVALID_ARGUMENT) {
    auto result = std::async(std::launch::async, [&]() -> std::string {
      try {
        use();
        return "accepted";
      } catch (const Error& e) {
        return e.status() == status ? e.what() : std::string("status ") + std::to_string(e.status()) + ": " + e.what();
      } catch (const std::exception& e) {
        return std::string("unexpected exception: ") + e.what();
      }
    });
    if (result.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
      const int other_end = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK);
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      ::close(other_end);
      result.wait();
      return "blocked on the FIFO";
    }
    return result.get();
  }

  static void c_abi(softdeca_status status) {
    if (status != SOFTDECA_OK) throw Error(status, softdeca_last_error());
  }

  std::string dir_, fifo_, fifo_csv_, good_;
};

#define EXPECT_FIFO_REFUSED(message) EXPECT_NE((message).find("is a FIFO, not a regular file"), std::string::npos) << (message)

TEST_F(RecordingFiles, ReadingAFifoIsRefusedAtOnce) {
  EXPECT_FIFO_REFUSED(refused(fifo_, [&] { recording::read_recording(fifo_); }));
  EXPECT_FIFO_REFUSED(refused(fifo_csv_, [&] { recording::read_livelinkface_csv(fifo_csv_, 60); }));
  EXPECT_FIFO_REFUSED(refused(fifo_csv_, [&] { recording::csv_to_recording(fifo_csv_, dir_ + "/out.sdrec", 60); }));
  EXPECT_FIFO_REFUSED(refused(fifo_, [&] { recording::recording_to_csv(fifo_, dir_ + "/out.csv", 60); }));
  EXPECT_FIFO_REFUSED(refused(fifo_, [&] {
    softdeca_player* player = nullptr;
    c_abi(softdeca_player_load(fifo_.c_str(), &player));
    softdeca_player_destroy(player);
  }));
}

TEST_F(RecordingFiles, WritingAFifoIsRefusedAtOnceWithOrWithoutAReader) {
  for (const bool reader : {false, true}) {
    SCOPED_TRACE(reader ? "a reader holds the FIFO open" : "no reader");
    const int other_end = reader ? ::open(fifo_.c_str(), O_RDONLY | O_NONBLOCK) : -1;
    const int other_csv = reader ? ::open(fifo_csv_.c_str(), O_RDONLY | O_NONBLOCK) : -1;
    EXPECT_FIFO_REFUSED(refused(fifo_, [&] { recording::RecordingWriter(fifo_, recording::Header{}); }));
    EXPECT_FIFO_REFUSED(refused(fifo_csv_, [&] { recording::recording_to_csv(good_, fifo_csv_, 60); }));
    EXPECT_FIFO_REFUSED(refused(fifo_csv_, [&] { recording::write_livelinkface_csv(fifo_csv_, {}, 60); }));
    live::ReceiverConfig c;
    c.port = 0;
    live::Receiver r(c);
    EXPECT_FIFO_REFUSED(refused(fifo_, [&] { r.start_recording(fifo_, recording::Header{}); }));
    EXPECT_EQ(r.stop_recording(), "");
    if (other_end >= 0) ::close(other_end);
    if (other_csv >= 0) ::close(other_csv);
  }
}

TEST_F(RecordingFiles, TheCAbisRecordersRefuseAFifo) {
  softdeca_receiver_config config{};
  config.struct_size = sizeof config;
  ASSERT_EQ(softdeca_receiver_config_init(&config), SOFTDECA_OK);
  config.port = 0;
  softdeca_receiver* receiver = nullptr;
  ASSERT_EQ(softdeca_receiver_create(&config, &receiver), SOFTDECA_OK) << softdeca_last_error();
  softdeca_recording_header header{};
  header.struct_size = sizeof header;
  EXPECT_FIFO_REFUSED(refused(fifo_, [&] { c_abi(softdeca_receiver_start_recording(receiver, fifo_.c_str(), &header)); }));
  softdeca_recorder* recorder = nullptr;
  EXPECT_FIFO_REFUSED(refused(fifo_, [&] { c_abi(softdeca_recorder_create(fifo_.c_str(), &header, &recorder)); }));
  softdeca_recorder_destroy(recorder);
  softdeca_receiver_destroy(receiver);
}

// A folder named as a recording: an invalid argument that says what it is, not an internal error.
TEST_F(RecordingFiles, AFolderIsAnInvalidArgument) {
  const std::string folder = dir_ + "/folder.sdrec";
  std::filesystem::create_directories(folder);
  softdeca_player* player = nullptr;
  EXPECT_EQ(softdeca_player_load(folder.c_str(), &player), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("is a folder, not a regular file"), std::string::npos)
      << softdeca_last_error();
  const std::string read = refused(folder, [&] { recording::read_recording(folder); });
  EXPECT_NE(read.find("is a folder"), std::string::npos) << read;
  const std::string write = refused(folder, [&] { recording::RecordingWriter(folder, recording::Header{}); });
  EXPECT_NE(write.find("is a folder"), std::string::npos) << write;
}

}  // namespace
