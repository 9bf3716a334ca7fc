#include "stream/udp_socket.h"

#include <cstdlib>
#include <string>

#include "core/error.h"
#include "stream/socket_platform.h"

namespace softdeca::stream {
namespace {

[[noreturn]] void fail(const std::string& what) { throw Error(SOFTDECA_ERROR_IO, what + ": " + platform::last_error()); }

}  // namespace

Endpoint make_endpoint(const std::string& host, uint16_t port) {
  Endpoint e;
  if (!platform::resolve_numeric(host, port, e))
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "'" + host + "' is not a numeric IPv4 or IPv6 address");
  return e;
}

Endpoint parse_endpoint(const std::string& text) {
  std::string host;
  std::string port;
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':')
      throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "'" + text + "' is not [address]:port");
    host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string::npos) throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "'" + text + "' is not address:port");
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 1 || p > 65535)
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "'" + port + "' is not a port number");
  return make_endpoint(host, static_cast<uint16_t>(p));
}

std::string Endpoint::text() const {
  const std::string host = platform::host_text(*this);
  const std::string port = std::to_string(platform::port(*this));
  return host.find(':') == std::string::npos ? host + ":" + port : "[" + host + "]:" + port;
}

void UdpSocket::open(int family) {
  fd_ = platform::open_udp(family);
  if (fd_ == -1) fail("cannot create a UDP socket");
}

UdpSocket::UdpSocket(const std::string& address, uint16_t port) {
  const Endpoint local = make_endpoint(address, port);
  open(platform::family(local));
  if (!platform::bind_socket(fd_, local)) {
    const std::string what = "cannot bind UDP " + local.text() + ": " + platform::last_error();
    close();  // the destructor does not run for a constructor that throws
    throw Error(SOFTDECA_ERROR_IO, what);
  }
}

UdpSocket::UdpSocket(const Endpoint& destination_family) { open(platform::family(destination_family)); }

UdpSocket::~UdpSocket() { close(); }

void UdpSocket::close() {
  platform::close_socket(fd_);
  fd_ = -1;
}

uint16_t UdpSocket::local_port() const {
  Endpoint e;
  return platform::local_address(fd_, e) ? platform::port(e) : 0;
}

bool UdpSocket::wait_readable(int timeout_ms) const { return platform::wait_readable(fd_, timeout_ms); }

bool UdpSocket::receive(uint8_t* buf, std::size_t capacity, std::size_t& size, Endpoint& from) {
  bool truncated = false;
  const long n = platform::receive_from(fd_, buf, capacity, from, truncated);
  if (n < 0 && !truncated) return false;
  size = truncated && static_cast<std::size_t>(n) <= capacity ? capacity + 1 : static_cast<std::size_t>(n);
  return true;
}

bool UdpSocket::send(const uint8_t* data, std::size_t size, const Endpoint& to) {
  const long n = platform::send_to(fd_, data, size, to);
  return n >= 0 && static_cast<std::size_t>(n) == size;
}

}  // namespace softdeca::stream
