// Untrusted bundles (docs/security.md): external data, FIFOs, links out of the bundle, size
// limits, sha256 verification and the memory budget, on copies of the test bundle made hostile.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "bundle/bundle_files.h"
#include "bundle/onnx_model_scan.h"
#include "bundle/sha256.h"
#include "onnx_test_support.h"
#include "runtime/model.h"
#include "runtime_fixture.h"
#include "softdeca/softdeca.h"

namespace fs = std::filesystem;
using softdeca::Error;
using namespace softdeca::bundle;
using namespace softdeca::runtime;

namespace {

using namespace softdeca::test;

// TensorProto: a float tensor of 4 elements whose data lives at `location`.
std::string external_tensor(const std::string& name, const std::string& location) {
  return field(1, 4) + field(2, 1) + field(8, name) + field(13, field(1, std::string("location")) + field(2, location)) +
         field(14, 1);
}

// GraphProto fragment: ConstantOfShape of a constant int64 shape [elements] (float output).
std::string constant_of_shape(std::int64_t elements) {
  return initializer(int64_vector("big_shape", {elements})) + node("ConstantOfShape", {"big_shape"}, "big");
}

// Appending a second `graph` field to a ModelProto merges it into the first (protobuf rules):
// ONNX Runtime would see the extra initializers and nodes.
std::string with_graph(const std::string& model, const std::string& graph_fields) { return model + field(7, graph_fields); }

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
void write_text(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(s.data(), static_cast<std::streamsize>(s.size()));
}
std::string sha(const std::string& s) { return sha256_hex(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()); }

// A private copy of the test bundle; `replace` swaps a file's bytes and its manifest sha256.
class HostileBundle : public ::testing::Test {
 protected:
  void SetUp() override {
    if (rt::data_dir().empty()) GTEST_SKIP() << "SOFTDECA_TEST_DATA is not set (run through ctest)";
    dir_ = fs::path(::testing::TempDir()) / ("softdeca-hostile-" + std::to_string(::getpid()) + "-" +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    bundle_ = dir_ / "bundle";
    fs::copy(fs::path(rt::data_dir()) / "bundle", bundle_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  void replace(const std::string& name, const std::string& bytes) {
    const std::string old = read_text(bundle_ / name);
    std::string manifest = read_text(bundle_ / "manifest.json");
    const std::size_t at = manifest.find(sha(old));
    ASSERT_NE(at, std::string::npos) << name;
    manifest.replace(at, 64, sha(bytes));
    write_text(bundle_ / "manifest.json", manifest);
    write_text(bundle_ / name, bytes);
  }
  std::string load_error(const ModelOptions& options = {}) {
    try {
      Model::load(BundleFiles::from_path(bundle_.string()), options);
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), SOFTDECA_ERROR_FORMAT) << e.what();
      return e.what();
    }
    return "";
  }
  fs::path dir_, bundle_;
};

}  // namespace

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(sha(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),  // 56 bytes: two tail blocks
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha(std::string(1000, 'a')), "41edece42d63e8d9bf515a9ba6932e1c20cbc9f5a5d134645adb5db1b9737ea3");
}

TEST(OnnxModelScan, FindsExternalDataAndCountsConstantShapes) {
  const auto scan = [](const std::string& m) {
    return scan_onnx_model(reinterpret_cast<const std::uint8_t*>(m.data()), m.size(), {});
  };
  const std::string big = model(constant_of_shape(std::int64_t{1} << 30));
  const OnnxModelScan counted = scan(big);
  EXPECT_EQ(counted.bytes, (std::uint64_t{4} << 30) + 8);
  EXPECT_EQ(counted.largest_tensor, "big");
  const OnnxModelScan external = scan(model(field(5, external_tensor("w", "x.bin")) + constant_of_shape(1)));
  ASSERT_EQ(external.external_tensors.size(), 1u);
  EXPECT_EQ(external.external_tensors[0], "w");
  // Bytes that are not a protobuf message are refused, never read past their end.
  const std::string cut = big.substr(0, big.size() - 3);
  EXPECT_THROW(scan(cut), Error);
  std::string deep;
  for (int i = 0; i < 40; ++i) deep = field(1, field(5, field(6, deep)));  // nodes in subgraphs in nodes...
  EXPECT_THROW(scan(field(8, field(2, 17)) + field(7, deep)), Error);
}

TEST_F(HostileBundle, ExternalDataIsRefusedWithoutReadingAndWithoutHostPaths) {
  // FIFOs where the locations point: anything opening them for reading would hang the test.
  const fs::path cwd = dir_ / "cwd";
  fs::create_directories(cwd);
  ASSERT_EQ(::mkfifo((cwd / "x.bin").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir_ / "x").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((bundle_ / "x.bin").c_str(), 0600), 0);
  const fs::path before = fs::current_path();
  fs::current_path(cwd);
  const std::string model = read_text(bundle_ / "identity_encoder.onnx");
  const std::pair<const char*, const char*> cases[] = {
      {"../x", "w_parent"}, {"/etc/passwd", "w_passwd"}, {"x.bin", "w_cwd"}};
  for (const auto& [location, tensor] : cases) {
    replace("identity_encoder.onnx", with_graph(model, field(5, external_tensor(tensor, location))));
    const auto start = std::chrono::steady_clock::now();
    const std::string error = load_error();
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
    EXPECT_NE(error.find(std::string("tensor '") + tensor + "'"), std::string::npos) << error;
    EXPECT_NE(error.find("external data"), std::string::npos) << error;
    EXPECT_EQ(error.find(location), std::string::npos) << "the message shows a host path: " << error;
  }
  fs::current_path(before);
}

TEST_F(HostileBundle, FifoAndOutsideLinksAreRefusedFastInsideLinksWork) {
  // A link to a file inside the bundle is fine.
  fs::rename(bundle_ / "non_skin_bones.u8", bundle_ / "bones-real.u8");
  fs::create_symlink("bones-real.u8", bundle_ / "non_skin_bones.u8");
  EXPECT_EQ(load_error(), "");
  // A link that leaves the bundle (to a copy of the very same bytes) is not.
  fs::copy_file(bundle_ / "bones-real.u8", dir_ / "outside.u8");
  fs::remove(bundle_ / "non_skin_bones.u8");
  fs::create_symlink(dir_ / "outside.u8", bundle_ / "non_skin_bones.u8");
  std::string error = load_error();
  EXPECT_NE(error.find("non_skin_bones.u8 is a link that leaves the bundle"), std::string::npos) << error;
  fs::remove(bundle_ / "non_skin_bones.u8");
  fs::create_symlink("../outside.u8", bundle_ / "non_skin_bones.u8");
  error = load_error();
  EXPECT_NE(error.find("leaves the bundle"), std::string::npos) << error;
  fs::remove(bundle_ / "non_skin_bones.u8");
  fs::rename(bundle_ / "bones-real.u8", bundle_ / "non_skin_bones.u8");
  // A FIFO (no writer: opening it for reading would block forever).
  fs::rename(bundle_ / "skin_triangles.i32", dir_ / "triangles.i32");
  ASSERT_EQ(::mkfifo((bundle_ / "skin_triangles.i32").c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  error = load_error();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_NE(error.find("skin_triangles.i32 is a FIFO"), std::string::npos) << error;
  // A link to a FIFO inside the bundle, and a .tar path that is a FIFO.
  fs::remove(bundle_ / "skin_triangles.i32");
  ASSERT_EQ(::mkfifo((bundle_ / "fifo").c_str(), 0600), 0);
  fs::create_symlink("fifo", bundle_ / "skin_triangles.i32");
  error = load_error();
  EXPECT_NE(error.find("is a FIFO"), std::string::npos) << error;
  EXPECT_THROW(BundleFiles::from_path((bundle_ / "fifo").string()), Error);
}

TEST_F(HostileBundle, SizeLimitsNameTheFile) {
  BundleLimits small;
  small.max_file_bytes = 4096;
  try {
    Model::load(BundleFiles::from_path(bundle_.string(), small), {});
    FAIL() << "loaded over the per-file limit";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("over the limit"), std::string::npos) << e.what();
  }
  BundleLimits total;
  total.max_total_bytes = read_text(bundle_ / "manifest.json").size() + 10;
  EXPECT_THROW(Model::load(BundleFiles::from_path(bundle_.string(), total), {}), Error);
  // Tar members obey the same limits.
  std::string member = "manifest.json";
  std::string header(512, '\0');
  header.replace(0, member.size(), member);
  header.replace(100, 7, "0000644");
  header.replace(124, 11, "00000010000");  // 4096 bytes
  header[156] = '0';
  header.replace(148, 8, "        ");
  unsigned sum = 0;
  for (const char c : header) sum += static_cast<unsigned char>(c);
  char text[8];
  std::snprintf(text, sizeof text, "%06o", sum);
  header.replace(148, 7, std::string(text, 6) + '\0');
  const std::string tar = header + std::string(4096, 'x') + std::string(1024, '\0');
  BundleLimits tiny;
  tiny.max_file_bytes = 1024;
  try {
    BundleFiles::from_tar(reinterpret_cast<const std::uint8_t*>(tar.data()), tar.size(), tiny);
    FAIL() << "read a tar member over the limit";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("manifest.json"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(BundleFiles::from_tar(reinterpret_cast<const std::uint8_t*>(tar.data()), tar.size()));
}

TEST_F(HostileBundle, TamperedFilesFailTheirSha256) {
  for (const char* name : {"softdeca_f_w.onnx", "skin_triangles.i32"}) {
    SCOPED_TRACE(name);
    fs::copy_file(bundle_ / name, dir_ / "saved", fs::copy_options::overwrite_existing);
    std::string bytes = read_text(bundle_ / name);
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 1);
    write_text(bundle_ / name, bytes);
    const std::string error = load_error();
    EXPECT_NE(error.find(std::string(name) + ": sha256 does not match the manifest"), std::string::npos) << error;
    fs::copy_file(dir_ / "saved", bundle_ / name, fs::copy_options::overwrite_existing);
  }
  EXPECT_EQ(load_error(), "");
}

TEST_F(HostileBundle, FourGibibyteModelIsRefusedBeforeAllocation) {
  const std::string model = read_text(bundle_ / "identity_encoder.onnx");
  replace("identity_encoder.onnx", with_graph(model, constant_of_shape(std::int64_t{1} << 30)));
  EXPECT_LT(read_text(bundle_ / "identity_encoder.onnx").size(), model.size() + 100);
  rusage before{}, after{};
  ::getrusage(RUSAGE_SELF, &before);
  const std::string error = load_error();
  ::getrusage(RUSAGE_SELF, &after);
  EXPECT_NE(error.find("over the memory budget of 2048 MiB"), std::string::npos) << error;
  EXPECT_NE(error.find("identity_encoder.onnx tensor 'big', 4096 MiB"), std::string::npos) << error;
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 256L * 1024) << "peak resident memory grew (KiB)";
}

// Graphs that fold to gigabytes however their shapes are computed (onnx_test_support.h), each
// added to a network of the test bundle: refused under a 200 MiB budget that the bundle itself
// fits, by operator or by size, before any session exists.
TEST_F(HostileBundle, RedTeamGraphsAreRefusedUnderTheBudget) {
  ModelOptions budget;
  budget.memory_budget_bytes = std::uint64_t{200} << 20;
  EXPECT_EQ(load_error(budget), "");
  const std::string model = read_text(bundle_ / "identity_encoder.onnx");
  rusage before{}, after{};
  ::getrusage(RUSAGE_SELF, &before);
  for (const RedTeamGraph& g : red_team_graphs()) {
    SCOPED_TRACE(g.what);
    replace("identity_encoder.onnx", with_graph(model, g.fields));
    const std::string error = load_error(budget);
    if (g.refused_operator) {
      EXPECT_NE(error.find(std::string("identity_encoder.onnx: ONNX model: operator '") + g.refused_operator + "'"),
                std::string::npos)
          << error;
    } else {
      EXPECT_NE(error.find("over the memory budget of 200 MiB"), std::string::npos) << error;
      EXPECT_NE(error.find("largest: identity_encoder.onnx tensor 'red_big'"), std::string::npos) << error;
    }
  }
  ::getrusage(RUSAGE_SELF, &after);
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 256L * 1024) << "peak resident memory grew (KiB)";
}

TEST_F(HostileBundle, MemoryBudgetIsConfigurable) {
  ModelOptions tight;
  tight.memory_budget_bytes = 1024;  // the test bundle is small, but not that small
  EXPECT_NE(load_error(tight).find("over the memory budget of 1 MiB"), std::string::npos);  // rounded up
  EXPECT_EQ(load_error(), "");
  // Through the C ABI (in MiB): the default takes the bundle; with 64 MiB of ConstantOfShape
  // added, a budget of 32 MiB does not.
  softdeca_model_options o{};
  o.struct_size = sizeof o;
  o.memory_budget_mib = 0;  // the default
  softdeca_model* m = nullptr;
  ASSERT_EQ(softdeca_model_load(bundle_.c_str(), &o, &m), SOFTDECA_OK) << softdeca_last_error();
  softdeca_model_destroy(m);
  m = nullptr;
  replace("identity_encoder.onnx", with_graph(read_text(bundle_ / "identity_encoder.onnx"), constant_of_shape(1u << 24)));
  o.memory_budget_mib = 32;
  EXPECT_EQ(softdeca_model_load(bundle_.c_str(), &o, &m), SOFTDECA_ERROR_FORMAT);
  EXPECT_NE(std::string(softdeca_last_error()).find("over the memory budget of 32 MiB"), std::string::npos)
      << softdeca_last_error();
  EXPECT_EQ(m, nullptr);
}

// The physics at prepare's head (rest_head.bin): a file that does not match its manifest's
// sizes, an index out of range and a non-finite position are refused at load, by name.
TEST_F(HostileBundle, RestHeadFileIsCheckedAtLoad) {
  const std::string good = read_text(bundle_ / "rest_head.bin");
  ASSERT_FALSE(good.empty());
  replace("rest_head.bin", good.substr(0, good.size() - 4));
  EXPECT_NE(load_error().find("rest_head.bin: shorter than declared"), std::string::npos) << load_error();
  replace("rest_head.bin", good + std::string(8, '\0'));
  EXPECT_NE(load_error().find("bytes more than declared"), std::string::npos) << load_error();
  // The first soft tet starts right after the fill's vertices (float64 x 3 each).
  const std::string manifest = read_text(bundle_ / "manifest.json");
  const std::size_t at = manifest.find("\"fill_vertices\": ");
  ASSERT_NE(at, std::string::npos);
  const std::size_t fill = std::stoul(manifest.substr(at + 17));
  std::string bad = good;
  const std::int32_t huge = 1 << 30;
  std::memcpy(&bad[fill * 24], &huge, 4);
  replace("rest_head.bin", bad);
  EXPECT_NE(load_error().find("soft tets: index 1073741824"), std::string::npos) << load_error();
  bad = good;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&bad[8], &nan, 8);
  replace("rest_head.bin", bad);
  EXPECT_NE(load_error().find("fill vertices: value 1 is not finite"), std::string::npos) << load_error();
}

// SoftDECA's rest gate (format version 6): anything but a positive number, in a bundle of an
// older version or without SoftDECA's vertex stage (the test bundle has none), is refused at
// load, by name.
TEST_F(HostileBundle, RestGateIsCheckedAtLoad) {
  const std::string manifest = read_text(bundle_ / "manifest.json");
  const std::string version = "\"format_version\": 5";
  ASSERT_NE(manifest.find(version), std::string::npos);
  const auto load_with = [&](const std::string& v, const std::string& gate) {
    std::string m = manifest;
    m.replace(m.find(version), version.size(), "\"format_version\": " + v + ", \"rest_gate\": " + gate);
    write_text(bundle_ / "manifest.json", m);
    return load_error();
  };
  std::string e = load_with("5", "0.3");
  EXPECT_NE(e.find("rest_gate (SoftDECA's rest gate) needs bundle format version 6"), std::string::npos) << e;
  e = load_with("6", "-0.3");
  EXPECT_NE(e.find("rest_gate (SoftDECA's rest gate tau) must be positive"), std::string::npos) << e;
  e = load_with("6", "\"0.3\"");
  EXPECT_NE(e.find("rest_gate must be a number, not a string"), std::string::npos) << e;
  e = load_with("6", "0.3");
  EXPECT_NE(e.find("needs SoftDECA's vertex stage"), std::string::npos) << e;
}
