// A FIFO and a regular file swapped at one name while the import reads it, round after round:
// a reader that checked the name and then opened it would sooner or later open the FIFO and
// wait for a writer forever. Every read must return within seconds, with the file read whole
// or refused as a FIFO; a watchdog aborts the run rather than let it hang.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>

#include "avatar_file.h"
#include "avatar_source.h"
#include "avatar_test_files.h"

using namespace softdeca::avatar_import;
using softdeca::test::TempDir;

namespace {
constexpr int kRounds = 1000;
constexpr auto kRoundLimit = std::chrono::seconds(10);

struct Outcome {
  int read = 0, refused = 0;
};

// Until stopped: a FIFO, then `content` as a regular file, renamed over `target` in turn (each
// rename replaces it at once, so the name always exists).
class Swapper {
 public:
  Swapper(std::filesystem::path target, std::string content) : target_(std::move(target)), content_(std::move(content)) {
    thread_ = std::thread([this] { run(); });
  }
  ~Swapper() {
    stop_ = true;
    thread_.join();
  }

 private:
  void run() {
    const std::string fifo = target_.string() + ".fifo", regular = target_.string() + ".regular";
    for (bool as_fifo = true; !stop_; as_fifo = !as_fifo) {
      if (as_fifo) {
        ::mkfifo(fifo.c_str(), 0600);
        std::rename(fifo.c_str(), target_.c_str());
      } else {
        std::FILE* f = std::fopen(regular.c_str(), "wb");
        if (f) {
          std::fwrite(content_.data(), 1, content_.size(), f);
          std::fclose(f);
        }
        std::rename(regular.c_str(), target_.c_str());
      }
      std::this_thread::sleep_for(std::chrono::microseconds(50));  // each state for a while
    }
  }
  std::filesystem::path target_;
  std::string content_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// `read` kRounds times against the swapper, each within kRoundLimit (else the process aborts).
Outcome race(const std::function<void()>& read) {
  std::atomic<int> finished{0};
  std::atomic<bool> done{false};
  std::thread watchdog([&] {
    int seen = -1;
    auto since = std::chrono::steady_clock::now();
    while (!done) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (finished != seen) {
        seen = finished;
        since = std::chrono::steady_clock::now();
      } else if (std::chrono::steady_clock::now() - since > kRoundLimit) {
        std::fprintf(stderr, "a read of the swapped file did not return within 10 s (round %d): it hangs\n", seen + 1);
        std::abort();
      }
    }
  });
  Outcome out;
  for (int round = 0; round < kRounds; ++round, ++finished) {
    try {
      read();
      ++out.read;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("is a FIFO, not a regular file"), std::string::npos) << e.what();
      ++out.refused;
    }
  }
  done = true;
  watchdog.join();
  std::printf("%d rounds: %d read, %d refused as a FIFO\n", kRounds, out.read, out.refused);
  return out;
}

std::string quad_obj(float dy) {
  return "v 0 0 0\nv 1 " + std::to_string(dy) + " 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
}
}  // namespace

TEST(ImportRaces, AnAvatarFileSwappedWithAFifoIsReadOrRefusedNeverWaitedOn) {
  const TempDir dir("import-race-file");
  softdeca::test::TestScene scene;
  scene.meshes.push_back({"Quad", {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 0, 2, 3}, {{"jawOpen", std::vector<float>(12, 0.01f), {}}}});
  const std::filesystem::path target = dir.write("avatar.glb", softdeca::test::glb_bytes(scene));
  const Swapper swapper(target, softdeca::test::glb_bytes(scene));
  const Outcome o = race([&] {
    const SourceScene read = read_scene_file(target.string(), {});
    ASSERT_EQ(read.meshes.size(), 1u);
    EXPECT_EQ(read.meshes[0].vertex_count(), 4u);
  });
  EXPECT_EQ(o.read + o.refused, kRounds);
}

TEST(ImportRaces, AShapeFileSwappedWithAFifoIsReadOrRefusedNeverWaitedOn) {
  // blendshapes/ is listed (regular files only) and then read: between the two, the name may
  // have become a FIFO.
  const TempDir dir("import-race-folder");
  dir.write("avatar/neutral.obj", quad_obj(0));
  const std::filesystem::path target = dir.write("avatar/blendshapes/jawOpen.obj", quad_obj(0.5f));
  const Swapper swapper(target, quad_obj(0.5f));
  const Outcome o = race([&] {
    const SourceScene read = read_avatar_folder(dir.file("avatar"), ShapeNames(), {});
    ASSERT_EQ(read.meshes.size(), 1u);
    // Listed as a regular file or not at all (a FIFO is not listed); read whole when read.
    for (const SourceShape& shape : read.meshes[0].shapes) {
      if (!shape.deltas.empty()) {
        EXPECT_FLOAT_EQ(shape.deltas[4], 0.5f);
      }
    }
  });
  EXPECT_EQ(o.read + o.refused, kRounds);
}
