#include "stream/frame_sender.h"

#include <string>

#include "core/error.h"
#include "stream/ifacialmocap_packet.h"
#include "stream/steady_clock.h"

namespace softdeca::stream {

FrameSender::FrameSender(const Endpoint& destination, Format format, uint32_t session_id)
    : to_(destination), format_(format), session_(session_id), socket_(destination) {
  require(format == Format::softdeca || format == Format::livelinkface || format == Format::ifacialmocap,
          "a sender sends softdeca, livelinkface or ifacialmocap");
  livelinkface_.device_id = "softdeca-sender";
  livelinkface_.subject = "take";
}

bool FrameSender::send(const Frame& frame) {
  switch (format_) {
    case Format::softdeca: {
      Frame f = frame;
      f.session_id = session_;
      f.sequence = sequence_++;
      f.send_time = steady_seconds();
      wire::encode_frame(f, buffer_);
      break;
    }
    case Format::livelinkface:
      livelinkface::encode_packet(frame, livelinkface_, buffer_);
      break;
    default: {
      const std::string text = ifacialmocap::encode_packet(frame);
      buffer_.assign(text.begin(), text.end());
      break;
    }
  }
  return send_raw(buffer_.data(), buffer_.size());
}

bool FrameSender::send_profile(const wire::Profile& profile) {
  require(format_ == Format::softdeca, "only our protocol carries profiles");
  wire::encode_profile(session_, sequence_++, profile, buffer_);
  return send_raw(buffer_.data(), buffer_.size());
}

bool FrameSender::send_neutral(const std::vector<float>& xyz) {
  require(format_ == Format::softdeca, "only our protocol carries neutral meshes");
  bool all = true;
  for (const wire::NeutralChunk& c : wire::split_neutral(xyz.data(), xyz.size() / 3)) {
    wire::encode_neutral_chunk(session_, sequence_++, c, buffer_);
    all = send_raw(buffer_.data(), buffer_.size()) && all;
  }
  return all;
}

bool FrameSender::send_raw(const uint8_t* data, std::size_t size) { return socket_.send(data, size, to_); }

std::size_t FrameSender::answer_requests(const wire::Profile* profile, const std::vector<float>* neutral) {
  uint8_t buf[wire::kDatagramLimit];
  std::size_t size = 0, answered = 0;
  Endpoint from;
  wire::Message m;
  while (socket_.receive(buf, sizeof buf, size, from)) {
    if (size > sizeof buf || wire::decode(buf, size, m).reason != DropReason::none ||
        m.envelope.type != wire::MessageType::request || m.envelope.session_id != session_)
      continue;
    if (m.request.what == wire::RequestKind::profile && profile && m.request.id == profile->id) {
      send_profile(*profile);
      ++answered;
    } else if (m.request.what == wire::RequestKind::neutral && neutral && !neutral->empty()) {
      send_neutral(*neutral);
      ++answered;
    }
  }
  return answered;
}

}  // namespace softdeca::stream
