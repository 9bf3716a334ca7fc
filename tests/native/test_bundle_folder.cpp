// Bundle folders as the library reads them on every platform (Linux, and Windows under wine):
// files are read as bytes, anything that is not a regular file inside the bundle is refused
// with an error naming the bundle file, never the resolved host path. FIFOs and devices, which
// Windows folders cannot hold, are covered by test_bundle_security.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "bundle/bundle_files.h"
#include "core/error.h"

namespace fs = std::filesystem;
using softdeca::Error;
using softdeca::bundle::BundleFiles;
using softdeca::bundle::BundleLimits;

namespace {

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string text(const softdeca::bundle::Bytes& bytes) { return std::string(bytes.begin(), bytes.end()); }

// The error `call` throws: its code and message.
template <class Call>
std::pair<int, std::string> failure(Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    return {static_cast<int>(e.status()), e.what()};
  }
  ADD_FAILURE() << "no error thrown";
  return {0, {}};
}

// A bundle folder with a UTF-8 name (UTF-16 for the Windows API) below a scratch folder that is
// the working directory, so the bundle is named by a relative path in messages.
class BundleFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    scratch_ = fs::temp_directory_path() / ("softdeca-bundle-folder-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(scratch_);
    fs::create_directories(scratch_ / name_ / "sub");
    previous_ = fs::current_path();
    fs::current_path(scratch_);
    write(bundle() / "manifest.json", "{}");
    write(bundle() / "sub" / "data.bin", std::string("\x01\x00\x02", 3));
    write(scratch_ / "outside.bin", "outside");
  }
  void TearDown() override {
    fs::current_path(previous_);
    std::error_code ignored;
    fs::remove_all(scratch_, ignored);
  }
  fs::path bundle() const { return scratch_ / name_; }
  // The bundle as the caller names it: relative to the working directory.
  std::string relative() const { return name_.u8string(); }
  // A symbolic link, or false where the system does not let this process make one.
  bool link(const fs::path& target, const fs::path& at) {
    std::error_code error;
    fs::create_symlink(target, at, error);
    return !error;
  }
  // No message may show where the bundle really lives on this machine.
  void expect_no_host_path(const std::string& message) {
    EXPECT_EQ(message.find(scratch_.string()), std::string::npos) << message;
    EXPECT_EQ(message.find(fs::canonical(scratch_).string()), std::string::npos) << message;
    EXPECT_EQ(message.find("\\\\?\\"), std::string::npos) << message;
  }

  fs::path scratch_, previous_;
  const fs::path name_ = fs::u8path(u8"b\u00fcndel");
};

TEST_F(BundleFolder, ReadsFilesBelowTheFolder) {
  const BundleFiles files = BundleFiles::from_path(relative());
  EXPECT_EQ(files.origin(), relative());
  EXPECT_TRUE(files.has("manifest.json"));
  EXPECT_TRUE(files.has("sub/data.bin"));
  EXPECT_FALSE(files.has("missing.bin"));
  EXPECT_FALSE(files.has("sub"));
  EXPECT_EQ(text(files.get("manifest.json")), "{}");
  EXPECT_EQ(text(files.get("sub/data.bin")), std::string("\x01\x00\x02", 3));
  const auto [code, message] = failure([&] { files.get("missing.bin"); });
  EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(message, relative() + ": bundle has no file missing.bin");
  EXPECT_NE(failure([&] { files.get("../outside.bin"); }).second.find("not a plain relative path"), std::string::npos);
}

TEST_F(BundleFolder, MissingPathIsAnInputOutputError) {
  EXPECT_EQ(failure([] { BundleFiles::from_path("no-such-bundle"); }).first, SOFTDECA_ERROR_IO);
}

// A NUL in a name the manifest gives: the message shows the whole name, the NUL escaped (a C
// string would end there and hide the rest).
TEST_F(BundleFolder, ANulInAFileNameIsShownEscaped) {
  const BundleFiles files = BundleFiles::from_path(relative());
  const auto [code, message] = failure([&] { files.get(std::string("weights\0/../../secret", 21)); });
  EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(message, "bundle file name 'weights\\x00/../../secret' is not a plain relative path");
}

TEST_F(BundleFolder, FolderInPlaceOfAFileIsRefused) {
  fs::create_directories(bundle() / "weights.bin");
  const BundleFiles files = BundleFiles::from_path(relative());
  const auto [code, message] = failure([&] { files.get("weights.bin"); });
  EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(message, relative() + ": bundle file weights.bin is a folder, not a regular file");
}

TEST_F(BundleFolder, SizeLimitsNameTheFile) {
  write(bundle() / "big.bin", std::string(3u << 20, 'x'));
  BundleLimits limits;
  limits.max_file_bytes = 2u << 20;
  const BundleFiles files = BundleFiles::from_path(relative(), limits);
  const auto [code, message] = failure([&] { files.get("big.bin"); });
  EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(message, relative() + ": bundle file big.bin is 3 MiB, over the limit of 2 MiB");
  // The total budget counts what was read: the second file gets only what is left.
  limits.max_file_bytes = 4u << 20;
  limits.max_total_bytes = 4u << 20;
  write(bundle() / "big2.bin", std::string(2u << 20, 'y'));
  const BundleFiles budget = BundleFiles::from_path(relative(), limits);
  EXPECT_EQ(budget.get("big.bin").size(), 3u << 20);
  EXPECT_NE(failure([&] { budget.get("big2.bin"); }).second.find("over the limit of 1 MiB"), std::string::npos);
}

TEST_F(BundleFolder, TarFileIsReadWhole) {
  std::string tar(512, '\0');
  const std::string body = "{}";
  tar.replace(0, 13, "manifest.json");
  tar.replace(100, 7, "0000644");
  tar.replace(124, 11, "00000000002");
  tar[156] = '0';
  tar.replace(148, 8, "        ");
  unsigned sum = 0;
  for (unsigned char c : tar) sum += c;
  char field[8];
  std::snprintf(field, sizeof field, "%06o", sum);
  tar.replace(148, 7, std::string(field, 6) + '\0');
  tar += body + std::string(510, '\0') + std::string(1024, '\0');
  write(scratch_ / "bundle.tar", tar);
  const BundleFiles files = BundleFiles::from_path("bundle.tar");
  EXPECT_EQ(files.origin(), "bundle.tar");
  EXPECT_EQ(text(files.get("manifest.json")), "{}");
  BundleLimits small;
  small.max_total_bytes = 1024;
  const auto [code, message] = failure([&] { BundleFiles::from_path("bundle.tar", small); });
  EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(message, "bundle.tar is 1 MiB, over the limit of 1 MiB");
}

TEST_F(BundleFolder, LinksMustStayInsideTheBundle) {
  if (!link("manifest.json", bundle() / "inside.json"))
    GTEST_SKIP() << "this process may not create symbolic links (Windows without developer mode)";
  const BundleFiles files = BundleFiles::from_path(relative());
  EXPECT_TRUE(files.has("inside.json"));
  EXPECT_EQ(text(files.get("inside.json")), "{}");

  ASSERT_TRUE(link(fs::path("..") / "outside.bin", bundle() / "relative.bin"));
  ASSERT_TRUE(link(fs::canonical(scratch_ / "outside.bin"), bundle() / "absolute.bin"));
  ASSERT_TRUE(link("gone.bin", bundle() / "broken.bin"));
  for (const std::string name : {"relative.bin", "absolute.bin"}) {
    const auto [code, message] = failure([&] { files.get(name); });
    EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
    EXPECT_EQ(message, relative() + ": bundle file " + name + " is a link that leaves the bundle");
    expect_no_host_path(message);
  }
  const auto [code, message] = failure([&] { files.get("broken.bin"); });
  EXPECT_EQ(code, SOFTDECA_ERROR_FORMAT);
  EXPECT_EQ(message, relative() + ": bundle file broken.bin is a broken link");

  // A linked folder leading out of the bundle is refused the same way.
  fs::create_directories(scratch_ / "elsewhere");
  write(scratch_ / "elsewhere" / "x.bin", "x");
  ASSERT_TRUE(link(fs::canonical(scratch_ / "elsewhere"), bundle() / "linked"));
  EXPECT_NE(failure([&] { files.get("linked/x.bin"); }).second.find("leaves the bundle"), std::string::npos);
}

}  // namespace
