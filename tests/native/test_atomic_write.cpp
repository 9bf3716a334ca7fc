// core/atomic_write.h: a file replaced whole. Threads replacing one path while another reads it
// leave one writer's bytes every time; a failed write leaves the previous file and no temporary
// file; a link at the path is replaced, never written through.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>
#ifndef _WIN32
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#endif

#include "core/atomic_write.h"
#include "core/error.h"

namespace fs = std::filesystem;

namespace {

struct TempFolder {
  fs::path path;
  explicit TempFolder(const std::string& name) {
    path = fs::temp_directory_path() / name;
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempFolder() {
    std::error_code error;
    fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, error);
    fs::remove_all(path, error);
  }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path)) names.push_back(e.path().filename().string());
    return names;
  }
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void save(const fs::path& p, const std::string& text) { softdeca::write_file_atomically(p.string(), text.data(), text.size()); }

// Writer w's content: long enough to take several write calls, its writer in every byte.
std::string content(int w) { return std::string(std::size_t{1} << 18, static_cast<char>('a' + w)); }

}  // namespace

TEST(AtomicWrite, ThreadsReplacingOnePathLeaveOneWritersBytesEveryTime) {
  TempFolder dir("softdeca-atomic-threads");
  const fs::path target = dir.path / "shared.bin";
  save(target, content(0));
  std::atomic<bool> done{false};
  std::atomic<int> torn{0}, reads{0};
  std::thread reader([&] {
    while (!done) {
      const std::string seen = read_text(target);
      ++reads;
      if (seen.size() != content(0).size() || seen.find_first_not_of(seen.front()) != std::string::npos) ++torn;
    }
  });
  std::vector<std::thread> writers;
  for (int w = 0; w < 8; ++w)
    writers.emplace_back([&, w] {
      for (int round = 0; round < 40; ++round) save(target, content(w));
    });
  for (std::thread& t : writers) t.join();
  done = true;
  reader.join();
  EXPECT_EQ(torn, 0) << "of " << reads << " reads";
  EXPECT_GT(reads, 0);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"shared.bin"}) << "no temporary file is left";
}

TEST(AtomicWrite, AFailedWriteLeavesThePreviousFileAndNoTemporaryFile) {
  TempFolder dir("softdeca-atomic-fail");
  const fs::path target = dir.path / "kept.bin";
  save(target, "previous");
  // The path is a folder with a file in it: the rename over it fails.
  fs::create_directories(dir.path / "folder");
  save(dir.path / "folder" / "inside", "inside");
  EXPECT_THROW(save(dir.path / "folder", "new"), softdeca::Error);
  EXPECT_EQ(read_text(dir.path / "folder" / "inside"), "inside");
  // The parent is a file: nothing can be made.
  try {
    save(target / "child", "new");
    ADD_FAILURE() << "saved below a file";
  } catch (const softdeca::Error& e) {
    EXPECT_EQ(e.status(), SOFTDECA_ERROR_IO);
    EXPECT_NE(std::string(e.what()).find("could not save"), std::string::npos) << e.what();
  }
#ifndef _WIN32
  // A write cut short (the file size limit, as a full disk would): the previous file stays whole.
  struct rlimit before {};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = before;
  small.rlim_cur = 1000;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  bool refused = false;
  try {
    save(target, content(1));
  } catch (const softdeca::Error& e) {
    refused = e.status() == SOFTDECA_ERROR_IO;
  }
  setrlimit(RLIMIT_FSIZE, &before);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(refused);
  if (::geteuid() != 0) {  // a read-only folder (the superuser writes in any)
    fs::permissions(dir.path, fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write, fs::perm_options::remove);
    EXPECT_THROW(save(target, "new"), softdeca::Error);
    fs::permissions(dir.path, fs::perms::owner_write, fs::perm_options::add);
  }
#endif
  EXPECT_EQ(read_text(target), "previous");
  std::vector<std::string> names = dir.entries();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"folder", "kept.bin"})) << "no temporary file is left";
}

#ifndef _WIN32
TEST(AtomicWrite, ALinkAtThePathIsReplacedNotWrittenThrough) {
  TempFolder dir("softdeca-atomic-link");
  const fs::path outside = dir.path / "outside.txt";
  save(outside, "not yours");
  fs::create_directories(dir.path / "out");
  fs::create_symlink(outside, dir.path / "out" / "file.bin");
  save(dir.path / "out" / "file.bin", "new");
  EXPECT_EQ(read_text(outside), "not yours");
  EXPECT_FALSE(fs::is_symlink(dir.path / "out" / "file.bin"));
  EXPECT_EQ(read_text(dir.path / "out" / "file.bin"), "new");
}
#endif

TEST(AtomicWrite, TemporarySiblingsAreHiddenInTheSameFolderAndDiffer) {
  const std::string a = softdeca::temporary_sibling("some/dir/avatar.fit", 42);
  const std::string b = softdeca::temporary_sibling("some/dir/avatar.fit", 42);
  EXPECT_EQ(a.rfind("some/dir/.avatar.fit.42-", 0), 0u) << a;
  EXPECT_NE(a, b);
  EXPECT_EQ(softdeca::temporary_sibling("avatar.fit", 1).rfind(".avatar.fit.1-", 0), 0u);
}
