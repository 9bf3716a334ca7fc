// The sending side of a stream: frames (and, in our protocol, the landmark profile and the
// neutral mesh) to one UDP destination in our format, Live Link Face's or iFacialMocap's. Used
// by `softdeca play --send`, the benchmark and the tests; the iOS app is the real sender.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "stream/datagram_decoder.h"
#include "stream/livelinkface_packet.h"
#include "stream/udp_socket.h"
#include "stream/wire_format.h"

namespace softdeca::stream {

class FrameSender {
 public:
  // format: softdeca, livelinkface or ifacialmocap. session_id identifies the stream (ours).
  FrameSender(const Endpoint& destination, Format format, uint32_t session_id);

  // Sends a frame. Ours: the header gets this sender's session and next sequence number, and
  // send_time this host's steady clock. False when the socket did not take the datagram.
  bool send(const Frame& frame);
  bool send_profile(const wire::Profile& profile);         // ours only
  bool send_neutral(const std::vector<float>& xyz);        // ours only: all chunks
  bool send_raw(const uint8_t* data, std::size_t size);    // any bytes (tests)
  // Answers the profile and neutral requests waiting on this socket; returns how many.
  std::size_t answer_requests(const wire::Profile* profile, const std::vector<float>* neutral);

  livelinkface::PacketInfo& livelinkface_info() { return livelinkface_; }
  uint32_t next_sequence() const { return sequence_; }

 private:
  Endpoint to_;
  Format format_;
  uint32_t session_;
  uint32_t sequence_ = 0;
  UdpSocket socket_;
  livelinkface::PacketInfo livelinkface_;
  std::vector<uint8_t> buffer_;
};

}  // namespace softdeca::stream
