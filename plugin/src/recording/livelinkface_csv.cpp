#include "recording/livelinkface_csv.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/regular_file.h"
#include "recording/frame_rule.h"
#include "recording/timecode.h"
#include "stream/livelinkface_layout.h"
#include "stream/text_fields.h"

namespace softdeca::recording {
namespace {
namespace llf = stream::livelinkface;

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(line.substr(begin, comma == std::string_view::npos ? std::string_view::npos : comma - begin));
    if (comma == std::string_view::npos) return fields;
    begin = comma + 1;
  }
}

// Read as a float directly (not through a double, which could round twice): the text the
// writer below makes comes back as the very float it was written from.
bool parse_float(std::string_view s, float& out) {
  float v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) return false;
  out = v;
  return true;
}

// The shortest text that reads back as exactly `v` (1e-45 and 3.4028235e+38 alike).
void append_float(std::string& out, float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v + 0.0f);  // + 0 turns -0 into 0
  out.append(buf, ec == std::errc() ? end : buf);
}

// The app's CSV column order: its packet order with JawLeft/JawRight and MouthLeft/MouthRight
// swapped (as in every take of the sample Live Link Face recordings).
std::array<std::size_t, llf::kValueCount> csv_order() {
  std::array<std::size_t, llf::kValueCount> order{};
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::swap(order[15], order[16]);  // JawLeft, JawRight
  std::swap(order[21], order[22]);  // MouthLeft, MouthRight
  return order;
}

std::string read_file(const std::string& path, const ReadLimits& limits) {
  const FilePtr file = open_regular_file(path, FileAccess::read);
  const std::uint64_t size = file_size(file.get());
  require_within(path, size, limits, "a CSV take");
  std::string text(static_cast<std::size_t>(size), '\0');
  if (std::fread(text.data(), 1, text.size(), file.get()) != text.size())
    throw Error(SOFTDECA_ERROR_IO, "cannot read " + path);
  return text;
}
}  // namespace

CsvTake parse_livelinkface_csv(std::string_view text, double rate) {
  require(rate > 0 && rate <= 1000, "timecode rate must be in (0, 1000]");
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // a UTF-8 byte-order mark
  CsvTake take;
  int timecode_col = -1, count_col = -1;
  std::array<int, llf::kValueCount> value_col;
  value_col.fill(-1);
  std::size_t columns = 0;
  bool header = true;
  stream::TextFields lines(text, "\r\n");  // LF, CRLF or CR-only (old Mac) line endings
  std::string_view line;
  while (lines.next(line)) {
    if (line.empty()) continue;
    const auto fields = split(line);
    if (header) {
      header = false;
      columns = fields.size();
      for (std::size_t c = 0; c < fields.size(); ++c) {
        const std::string_view name = fields[c];
        if (name == "Timecode") timecode_col = static_cast<int>(c);
        else if (name == "BlendShapeCount" || name == "BlendshapeCount") count_col = static_cast<int>(c);
        for (std::size_t i = 0; i < llf::kValueCount; ++i)
          if (name == llf::value_name(i)) value_col[i] = static_cast<int>(c);
      }
      require(timecode_col >= 0, "Live Link Face CSV without a Timecode column", SOFTDECA_ERROR_FORMAT);
      for (std::size_t i = 0; i < llf::kHeadYaw; ++i)
        require(value_col[i] >= 0, std::string("Live Link Face CSV without a ") + llf::value_name(i) + " column",
                SOFTDECA_ERROR_FORMAT);
      continue;
    }
    ++take.rows;
    // The app writes a lost face as the timecode and a zero count, nothing else.
    const bool zero_count = count_col >= 0 && static_cast<std::size_t>(count_col) < fields.size() &&
                            fields[static_cast<std::size_t>(count_col)] == "0";
    if (fields.size() != columns) {
      ++(zero_count ? take.face_lost_rows : take.malformed_rows);
      continue;
    }
    stream::Frame f;
    llf::Values values{};
    bool ok = parse_timecode(fields[static_cast<std::size_t>(timecode_col)], rate, f.capture_time);
    for (std::size_t i = 0; ok && i < llf::kValueCount; ++i)
      if (value_col[i] >= 0) ok = parse_float(fields[static_cast<std::size_t>(value_col[i])], values[i]);
    for (std::size_t i = llf::kHeadYaw; ok && i < llf::kValueCount; ++i) ok = pose_angle_ok(values[i]);
    if (!ok) {
      ++take.malformed_rows;
      continue;
    }
    // The frame rule on the weights as written (values_to_frame clamps them as the rule does).
    stream::Frame raw;
    for (std::size_t i = 0; i < llf::kHeadYaw; ++i) raw.weights[static_cast<std::size_t>(llf::canonical_index(i))] = values[i];
    if (apply_frame_rule(raw) == FrameVerdict::clamped) ++take.clamped_rows;
    llf::values_to_frame(values, f);
    f.has_head = value_col[llf::kHeadYaw] >= 0 && value_col[llf::kHeadYaw + 1] >= 0 && value_col[llf::kHeadYaw + 2] >= 0;
    f.has_eyes = value_col[llf::kLeftEyeYaw] >= 0 && value_col[llf::kRightEyeYaw + 2] >= 0;
    take.frames.push_back(f);
  }
  require(!header, "empty Live Link Face CSV", SOFTDECA_ERROR_FORMAT);
  return take;
}

CsvTake read_livelinkface_csv(const std::string& path, double rate, const ReadLimits& limits) {
  return parse_livelinkface_csv(read_file(path, limits), rate);
}

std::string format_livelinkface_csv(const std::vector<stream::Frame>& frames, int rate) {
  std::string out = csv_header(rate);
  for (const stream::Frame& f : frames) append_csv_row(out, f, rate);
  return out;
}

std::string csv_header(int rate) {
  require(rate > 0 && rate <= 1000, "timecode rate must be an integer in [1, 1000]");
  std::string out = "Timecode,BlendShapeCount";
  for (std::size_t i : csv_order()) out += std::string(",") + llf::value_name(i);
  return out + '\n';
}

bool append_csv_row(std::string& out, const stream::Frame& f, int rate) {
  if (f.tracking != stream::Tracking::tracked) return false;
  require(std::isfinite(f.capture_time) && f.capture_time >= 0, "capture time not a time of day");
  out += format_timecode(f.capture_time, rate) + ",61";
  const llf::Values values = llf::frame_to_values(f);
  for (std::size_t i : csv_order()) {
    out += ',';
    append_float(out, values[i]);
  }
  out += '\n';
  return true;
}

CsvWriter::CsvWriter(const std::string& path, int rate) : path_(path), rate_(rate), text_(csv_header(rate)) {
  file_ = open_regular_file(path, FileAccess::create);
}

void CsvWriter::write(const stream::Frame& frame) {
  rows_ += append_csv_row(text_, frame, rate_);
  if (text_.size() >= kFlushBytes) flush();
}

void CsvWriter::finish() {
  flush();
  if (std::fflush(file_.get()) != 0) throw Error(SOFTDECA_ERROR_IO, "cannot write " + path_);
}

void CsvWriter::flush() {
  if (std::fwrite(text_.data(), 1, text_.size(), file_.get()) != text_.size())
    throw Error(SOFTDECA_ERROR_IO, "cannot write " + path_);
  text_.clear();
}

void write_livelinkface_csv(const std::string& path, const std::vector<stream::Frame>& frames, int rate) {
  CsvWriter out(path, rate);
  for (const stream::Frame& f : frames) out.write(f);
  out.finish();
}

}  // namespace softdeca::recording
