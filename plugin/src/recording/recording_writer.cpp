#include "recording/recording_writer.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include "core/error.h"
#include "recording/record_codec.h"
#include "stream/byte_io.h"
#include "stream/crc32.h"

namespace softdeca::recording {

RecordingWriter::RecordingWriter(const std::string& path, const Header& header) : path_(path) {
  std::vector<uint8_t> fields;
  encode_header_fields(header, fields);  // throws on an invalid profile before touching the file
  file_ = open_regular_file(path, FileAccess::create);
  write_header(header);
}

RecordingWriter::RecordingWriter(FilePtr file, const std::string& name, const Header& header)
    : path_(name), file_(std::move(file)) {
  require(file_ != nullptr, "no file to record into");
  write_header(header);
}

void RecordingWriter::write_header(const Header& header) {
  std::vector<uint8_t> fields;
  encode_header_fields(header, fields);
  std::vector<uint8_t> block;
  stream::ByteWriter w(block);
  w.bytes(kFileMagic.data(), kFileMagic.size());
  w.u16le(kVersionMajor);
  w.u16le(kVersionMinor);
  w.u32le(static_cast<uint32_t>(fields.size()));
  w.bytes(fields.data(), fields.size());
  w.u32le(stream::crc32(block.data() + kFileMagic.size(), block.size() - kFileMagic.size()));
  put(block.data(), block.size());
}

void RecordingWriter::write(const stream::Frame& frame) {
  encode_frame_record(frame, payload_);
  append_record(payload_);
  ++frames_;
}

void RecordingWriter::write_profile(const stream::wire::Profile& profile) {
  encode_profile_record(profile, payload_);
  append_record(payload_);
}

void RecordingWriter::write_neutral(const std::vector<float>& xyz) {
  encode_neutral_record(xyz, payload_);
  append_record(payload_);
}

void RecordingWriter::append_record(const std::vector<uint8_t>& payload) {
  record_.clear();
  stream::ByteWriter w(record_);
  w.bytes(kRecordMagic.data(), kRecordMagic.size());
  w.u32le(static_cast<uint32_t>(payload.size()));
  w.u32le(stream::crc32(payload.data(), payload.size(), stream::crc32(record_.data() + 4, 4)));
  w.bytes(payload.data(), payload.size());
  put(record_.data(), record_.size());
}

void RecordingWriter::put(const void* data, std::size_t size) {
  if (std::fwrite(data, 1, size, file_.get()) != size || std::fflush(file_.get()) != 0)
    throw Error(SOFTDECA_ERROR_IO, "cannot write " + path_ + ": " + std::strerror(errno));
}

}  // namespace softdeca::recording
