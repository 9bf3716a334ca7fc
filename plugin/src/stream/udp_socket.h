// A non-blocking UDP socket (IPv4 or IPv6, numeric addresses only: no name lookups on the
// frame path). The system calls live in socket_posix.cpp and socket_windows.cpp (Winsock).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace softdeca::stream {

struct Endpoint {
  // The bytes of a sockaddr_storage (128 on every platform), opaque here so that this header
  // needs no system socket header.
  alignas(8) unsigned char address[128]{};
  uint32_t length = 0;
  std::string text() const;  // "127.0.0.1:50110", "[::1]:50110"
};

// Parses "host:port" or "[v6]:port" with a numeric host. Throws softdeca::Error.
Endpoint parse_endpoint(const std::string& text);
Endpoint make_endpoint(const std::string& host, uint16_t port);

class UdpSocket {
 public:
  // Binds to address:port (port 0: any free port). Throws softdeca::Error (IO) on failure.
  UdpSocket(const std::string& address, uint16_t port);
  // An unbound socket of the endpoint's family, for sending.
  explicit UdpSocket(const Endpoint& destination_family);
  ~UdpSocket();
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  uint16_t local_port() const;
  // Waits until a datagram is readable or `timeout_ms` passes; false on timeout.
  bool wait_readable(int timeout_ms) const;
  // One datagram into buf; false when none is waiting. `size` is its full length even when it
  // was longer than `capacity` (then truncated; where the system does not tell the full length,
  // capacity + 1).
  bool receive(uint8_t* buf, std::size_t capacity, std::size_t& size, Endpoint& from);
  // True when the datagram went out whole.
  bool send(const uint8_t* data, std::size_t size, const Endpoint& to);

 private:
  void open(int family);
  void close();
  std::intptr_t fd_ = -1;  // a file descriptor, or a Winsock SOCKET (INVALID_SOCKET is -1 too)
};

}  // namespace softdeca::stream
