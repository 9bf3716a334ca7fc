#include "bench_bundle_memory.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "bench_child_memory.h"
#include "bundle/bundle_files.h"
#include "bundle/sha256.h"
#include "core/error.h"
#include "runtime/model.h"

namespace softdeca::cli {
namespace {
namespace fs = std::filesystem;
using bundle::BundleFiles;
using runtime::Model;
using runtime::ModelOptions;

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;

// Protobuf fields, enough to write a graph fragment.
std::string varint(std::uint64_t v) {
  std::string out;
  do {
    const auto b = static_cast<std::uint8_t>(v & 0x7F);
    v >>= 7;
    out += static_cast<char>(v ? b | 0x80 : b);
  } while (v);
  return out;
}
std::string pb(int number, std::uint64_t value) { return varint(std::uint64_t(number) << 3) + varint(value); }
std::string pb(int number, const std::string& bytes) {
  return varint(std::uint64_t(number) << 3 | 2) + varint(bytes.size()) + bytes;
}

// An initializer (TensorProto) with dims and raw little-endian data; dtype 1 float, 7 int64.
std::string initializer(const std::string& name, std::uint64_t dtype, const std::vector<std::uint64_t>& dims,
                        const std::vector<std::int64_t>& values) {
  std::string raw;
  for (std::int64_t v : values) {
    if (dtype == 1) {
      const float f = static_cast<float>(v);
      raw.append(reinterpret_cast<const char*>(&f), 4);
    } else {
      for (int i = 0; i < 8; ++i) raw += static_cast<char>(static_cast<std::uint64_t>(v) >> (8 * i));
    }
  }
  std::string t;
  for (std::uint64_t d : dims) t += pb(1, d);
  return pb(5, t + pb(2, dtype) + pb(8, name) + pb(9, raw));
}
std::string node(const std::string& op, const std::vector<std::string>& inputs, const std::string& output,
                 const std::string& attributes = "") {
  std::string n;
  for (const std::string& i : inputs) n += pb(1, i);
  return pb(1, n + pb(2, output) + pb(3, "sdbench_" + output) + pb(4, op) + attributes);
}
std::int64_t count(std::uint64_t bytes, std::uint64_t per) { return static_cast<std::int64_t>(std::max<std::uint64_t>(bytes / per, 1)); }

// The graph fragment of one family whose tensors take about `bytes` in all (the budget counts
// every tensor of a graph, docs/security.md): a shape computed inside the graph, then filled,
// expanded, joined or multiplied out. Every operator is one a bundle's networks may use.
std::string fragment(const std::string& family, std::uint64_t bytes) {
  const auto side = static_cast<std::int64_t>(std::floor(std::sqrt(double(bytes) / 4)));
  const std::string axis0 = pb(5, pb(1, std::string("axis")) + pb(3, 0) + pb(20, 2));
  if (family == "constant_of_shape")
    return initializer("sdb_s", 7, {1}, {count(bytes, 4)}) + node("ConstantOfShape", {"sdb_s"}, "sdb_out");
  if (family == "expand")  // [1, 4] floats to [n, 4]
    return initializer("sdb_x", 1, {1, 4}, {1, 2, 3, 4}) + initializer("sdb_s", 7, {2}, {count(bytes, 16), 1}) +
           node("Expand", {"sdb_x", "sdb_s"}, "sdb_out");
  if (family == "mul")  // a side squared, filled
    return initializer("sdb_s", 7, {1}, {side}) + node("Mul", {"sdb_s", "sdb_s"}, "sdb_n") +
           node("ConstantOfShape", {"sdb_n"}, "sdb_out");
  if (family == "gather")  // the first of [n, 7], filled
    return initializer("sdb_s", 7, {2}, {count(bytes, 4), 7}) + initializer("sdb_i", 7, {1}, {0}) +
           node("Gather", {"sdb_s", "sdb_i"}, "sdb_n") + node("ConstantOfShape", {"sdb_n"}, "sdb_out");
  if (family == "concat")  // a third of the bytes joined with itself
    return initializer("sdb_s", 7, {1}, {count(bytes, 12)}) + node("ConstantOfShape", {"sdb_s"}, "sdb_x") +
           node("Concat", {"sdb_x", "sdb_x"}, "sdb_out", axis0);
  if (family == "matmul")  // the outer product of [side, 1] and [1, side]
    return initializer("sdb_a", 7, {2}, {side, 1}) + initializer("sdb_b", 7, {2}, {1, side}) +
           node("ConstantOfShape", {"sdb_a"}, "sdb_x") + node("ConstantOfShape", {"sdb_b"}, "sdb_y") +
           node("MatMul", {"sdb_x", "sdb_y"}, "sdb_out");
  // shape: the shape of 256 floats with n appended, filled: [256, n] floats
  std::vector<std::int64_t> x(256, 1);
  return initializer("sdb_x", 1, {256}, x) + initializer("sdb_k", 7, {1}, {count(bytes, 1024)}) +
         node("Shape", {"sdb_x"}, "sdb_shape") + node("Concat", {"sdb_shape", "sdb_k"}, "sdb_dims", axis0) +
         node("ConstantOfShape", {"sdb_dims"}, "sdb_out");
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
void write_file(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(s.data(), static_cast<std::streamsize>(s.size()));
}
std::string sha(const std::string& s) { return bundle::sha256_hex(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()); }

// A copy of `bundle` whose identity encoder (loaded by every Model::load) also holds the
// fragment: a second `graph` field merges into the first (protobuf rules), and the manifest's
// sha256 follows.
void splice(const fs::path& bundle, const fs::path& copy, const std::string& fragment) {
  fs::remove_all(copy);
  fs::copy(bundle, copy);
  const fs::path network = copy / "identity_encoder.onnx";
  const std::string old = read_file(network);
  const std::string spliced = old + pb(7, fragment);
  std::string manifest = read_file(copy / "manifest.json");
  const std::size_t at = manifest.find(sha(old));
  if (at == std::string::npos) throw std::runtime_error("bench-reliability: the manifest lists no identity encoder");
  manifest.replace(at, 64, sha(spliced));
  write_file(copy / "manifest.json", manifest);
  write_file(network, spliced);
}

struct Load {
  std::uint64_t peak_increase = 0;
  bool loaded = false;
  std::string error;
};

// Model::load of `bundle` in a child process: its peak RSS over its RSS before loading. With
// `warm_with`, the child first loads that bundle and drops it, so that ONNX Runtime's own
// start (its code, environment and thread pools, once a process) is not counted.
Load load_in_child(const fs::path& bundle, std::uint64_t budget, const fs::path& warm_with = {}) {
  ModelOptions o;
  o.memory_budget_bytes = budget;
  const auto warm = [&]() -> std::string {
    if (warm_with.empty()) return "";
    try {
      Model::load(BundleFiles::from_path(warm_with.string()), o);
      return "";
    } catch (const std::exception& e) {
      return std::string("warming up: ") + e.what();
    }
  };
  const auto load = [&]() -> std::string {
    try {
      Model::load(BundleFiles::from_path(bundle.string()), o);
      return "";
    } catch (const std::exception& e) {
      return e.what();  // refused
    }
  };
  const ChildPeak c = peak_in_child("loading " + bundle.string(), warm, load);
  Load out;
  out.peak_increase = c.increase;
  out.loaded = c.prepared && c.report.empty();
  if (!out.loaded) out.error = c.report;
  return out;
}

// The unchanged bundle's estimate, rounded up to MiB, read from the refusal a 1-byte budget gets.
std::uint64_t base_estimate(const fs::path& bundle) {
  try {
    ModelOptions o;
    o.memory_budget_bytes = 1;
    Model::load(BundleFiles::from_path(bundle.string()), o);
  } catch (const std::exception& e) {
    const char* at = std::strstr(e.what(), "need an estimated ");
    if (at) return std::strtoull(at + std::strlen("need an estimated "), nullptr, 10) * kMiB;
  }
  throw std::runtime_error("bench-reliability: no estimate for " + bundle.string());
}

}  // namespace

BundleMemory bundle_memory_run(const std::string& bundle, const std::string& scratch, std::uint64_t budget) {
  const std::uint64_t base = base_estimate(bundle);
  if (base + 4 * kMiB > budget) throw std::runtime_error("bench-reliability: the bundle nearly fills the budget");
  struct Size {
    const char* name;
    std::uint64_t bytes;
    bool loads;
  };
  const Size sizes[] = {{"just under", budget - base - 2 * kMiB, true},
                        {"just over", budget - base + 2 * kMiB, false},
                        {"large", 64 * budget, false}};
  BundleMemory out;
  const Load start = load_in_child(bundle, budget);
  if (!start.loaded) throw std::runtime_error("bench-reliability: the bundle does not load: " + start.error);
  out.runtime_start_bytes = start.peak_increase;
  const fs::path copy = fs::path(scratch) / "bench-reliability-bundle";
  for (const char* family : {"constant_of_shape", "expand", "mul", "gather", "concat", "matmul", "shape"})
    for (const Size& size : sizes) {
      splice(bundle, copy, fragment(family, size.bytes));
      const Load l = load_in_child(copy, budget, bundle);
      if (l.error.rfind("warming up", 0) == 0)
        throw std::runtime_error("bench-reliability: " + l.error);
      if (size.loads && !l.loaded)
        throw std::runtime_error(std::string("bench-reliability: the ") + family + " bundle " + size.name +
                                 " the budget was refused: " + l.error);
      const double ratio = double(l.peak_increase) / double(budget);
      std::fprintf(stderr, "  %-17s %-10s %s, peak RSS +%.0f MiB (%.3f of the budget)\n", family, size.name,
                   l.loaded ? "loaded " : "refused", double(l.peak_increase) / double(kMiB), ratio);
      ++out.bundles;
      ++(l.loaded ? out.loaded : out.refused);
      if (ratio >= out.worst_ratio) {
        out.worst_ratio = ratio;
        out.worst = std::string(family) + " " + size.name + ", " + (l.loaded ? "loaded" : "refused");
      }
    }
  fs::remove_all(copy);
  return out;
}

}  // namespace softdeca::cli
