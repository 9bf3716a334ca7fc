#include "bench_import_memory.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "avatar_file.h"
#include "bench_child_memory.h"
#include "bundle/json.h"

namespace softdeca::cli {
namespace {
namespace fs = std::filesystem;
using avatar_import::ShapeNames;

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
constexpr std::uint64_t kAllowance = 500'000'000;  // bytes any read may use besides 4 x its input

struct Entry {
  std::string name, avatar, names;  // avatar and names file as `softdeca fit` is given them
  std::uint64_t input_bytes = 0;
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("bench-reliability: cannot read " + p.string());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The attacks `softdeca fit` reads (not those only `replay` opens), paths resolved in `corpus`.
std::vector<Entry> entries(const fs::path& corpus) {
  const bundle::Json root = bundle::Json::parse(read_text(corpus / "corpus.json"));
  std::vector<Entry> out;
  for (const bundle::Json& a : root.at("attacks", "corpus.json").array("attacks")) {
    if (a.at("command", "command").string("command") != "fit") continue;
    Entry e;
    e.name = a.at("name", "name").string("name");
    e.avatar = (corpus / a.at("avatar", "avatar").string("avatar")).string();
    e.input_bytes = static_cast<std::uint64_t>(a.at("input_bytes", "input_bytes").integer("input_bytes"));
    const std::vector<bundle::Json>& args = a.at("args", "args").array("args");
    for (std::size_t i = 0; i + 1 < args.size(); ++i)
      if (args[i].string("args") == "--names") e.names = (corpus / args[i + 1].string("args")).string();
    out.push_back(std::move(e));
  }
  if (out.empty()) throw std::runtime_error("bench-reliability: " + (corpus / "corpus.json").string() + " lists no avatar");
  return out;
}
}  // namespace

ImportMemory import_memory_run(const std::string& corpus) {
  ImportMemory out;
  ChildLimits limits;
  limits.seconds = 60;
  limits.address_space = std::uint64_t{8} << 30;  // a 16 GiB claim fails rather than filling the machine
  for (const Entry& e : entries(corpus)) {
    const auto nothing = [] { return std::string(); };
    const auto read = [&] {
      try {
        const ShapeNames names = e.names.empty() ? ShapeNames() : ShapeNames::from_file(e.names);
        avatar_import::read_avatar_file(e.avatar, names);
        return std::string();
      } catch (const std::exception& error) {
        return std::string("refused: ") + error.what();
      }
    };
    const ChildPeak c = peak_in_child("reading " + e.avatar, nothing, read, limits);
    const bool was_read = c.report.empty();
    const double ratio = double(c.increase) / double(e.input_bytes + kAllowance / 4);
    std::fprintf(stderr, "  %-32s %10llu bytes  %s, peak RSS +%.1f MiB (%.3f)\n", e.name.c_str(),
                 static_cast<unsigned long long>(e.input_bytes), was_read ? "read   " : "refused", double(c.increase) / double(kMiB),
                 ratio);
    ++out.avatars;
    ++(was_read ? out.read : out.refused);
    if (ratio >= out.worst_ratio) {
      out.worst_ratio = ratio;
      char text[200];
      std::snprintf(text, sizeof text, "%s: +%.1f MiB for %llu bytes, %s", e.name.c_str(), double(c.increase) / double(kMiB),
                    static_cast<unsigned long long>(e.input_bytes), was_read ? "read" : "refused");
      out.worst = text;
    }
  }
  return out;
}

}  // namespace softdeca::cli
