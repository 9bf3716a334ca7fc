#include "stream/udp_socket.h"

#include <cstring>
#include <string>

#include "core/error.h"

#ifdef _WIN32
#pragma comment(lib, "ws2_32.lib")
using ssize_t = int;
#else
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <unistd.h>
#endif

namespace softdeca::stream {
namespace {

[[noreturn]] void fail(const std::string& what) {
#ifdef _WIN32
  throw Error(SOFTDECA_ERROR_IO, what + " (error " + std::to_string(WSAGetLastError()) + ")");
#else
  throw Error(SOFTDECA_ERROR_IO, what + ": " + std::strerror(errno));
#endif
}

#ifdef _WIN32
// Winsock must be started once per process user; the count lives inside Winsock itself.
struct WinsockUser {
  WinsockUser() {
    WSADATA data;
    if (WSAStartup(MAKEWORD(2, 2), &data) != 0) throw Error(SOFTDECA_ERROR_IO, "WSAStartup failed");
  }
  ~WinsockUser() { WSACleanup(); }
};
#endif

}  // namespace

Endpoint make_endpoint(const std::string& host, uint16_t port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICHOST | AI_NUMERICSERV | AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (getaddrinfo(host.c_str(), service.c_str(), &hints, &found) != 0 || !found)
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, "'" + host + "' is not a numeric IPv4 or IPv6 address");
  Endpoint e;
  std::memcpy(&e.address, found->ai_addr, found->ai_addrlen);
  e.length = static_cast<socklen_t>(found->ai_addrlen);
  freeaddrinfo(found);
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
  char host[INET6_ADDRSTRLEN] = "?";
  uint16_t port = 0;
  if (address.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&address);
    inet_ntop(AF_INET, &a->sin_addr, host, sizeof host);
    port = ntohs(a->sin_port);
    return std::string(host) + ":" + std::to_string(port);
  }
  const auto* a = reinterpret_cast<const sockaddr_in6*>(&address);
  inet_ntop(AF_INET6, &a->sin6_addr, host, sizeof host);
  port = ntohs(a->sin6_port);
  return "[" + std::string(host) + "]:" + std::to_string(port);
}

void UdpSocket::open(int family) {
#ifdef _WIN32
  static WinsockUser winsock;  // process-wide start of Winsock, never changed afterwards
  fd_ = ::socket(family, SOCK_DGRAM, IPPROTO_UDP);
  if (fd_ == INVALID_SOCKET) fail("cannot create a UDP socket");
  u_long nonblocking = 1;
  ioctlsocket(fd_, FIONBIO, &nonblocking);
#else
  fd_ = ::socket(family, SOCK_DGRAM, 0);
  if (fd_ < 0) fail("cannot create a UDP socket");
  fcntl(fd_, F_SETFL, fcntl(fd_, F_GETFL, 0) | O_NONBLOCK);
  fcntl(fd_, F_SETFD, FD_CLOEXEC);
#endif
  // A larger receive buffer rides out bursts while the receiving thread is descheduled.
  int bytes = 4 << 20;
  setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, reinterpret_cast<const char*>(&bytes), sizeof bytes);
}

UdpSocket::UdpSocket(const std::string& address, uint16_t port) {
  const Endpoint local = make_endpoint(address, port);
  open(local.address.ss_family);
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&local.address), local.length) != 0) {
    const std::string what = "cannot bind UDP " + local.text();
    close();  // the destructor does not run for a constructor that throws
    fail(what);
  }
}

UdpSocket::UdpSocket(const Endpoint& destination_family) { open(destination_family.address.ss_family); }

UdpSocket::~UdpSocket() { close(); }

void UdpSocket::close() {
#ifdef _WIN32
  if (fd_ != INVALID_SOCKET) closesocket(fd_);
  fd_ = INVALID_SOCKET;
#else
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
#endif
}

uint16_t UdpSocket::local_port() const {
  Endpoint e;
  e.length = sizeof e.address;
  if (getsockname(fd_, reinterpret_cast<sockaddr*>(&e.address), &e.length) != 0) return 0;
  return e.address.ss_family == AF_INET ? ntohs(reinterpret_cast<const sockaddr_in*>(&e.address)->sin_port)
                                        : ntohs(reinterpret_cast<const sockaddr_in6*>(&e.address)->sin6_port);
}

bool UdpSocket::wait_readable(int timeout_ms) const {
#ifdef _WIN32
  WSAPOLLFD p{fd_, POLLRDNORM, 0};
  return WSAPoll(&p, 1, timeout_ms) > 0;
#else
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0;
#endif
}

bool UdpSocket::receive(uint8_t* buf, std::size_t capacity, std::size_t& size, Endpoint& from) {
  from.length = sizeof from.address;
#ifdef _WIN32
  const int n = ::recvfrom(fd_, reinterpret_cast<char*>(buf), static_cast<int>(capacity), 0,
                           reinterpret_cast<sockaddr*>(&from.address), &from.length);
  if (n < 0) {
    if (WSAGetLastError() != WSAEMSGSIZE) return false;
    size = capacity + 1;  // Winsock does not say how long: at least longer than the buffer
    return true;
  }
#else
#ifdef __linux__
  const int flags = MSG_TRUNC;  // Linux then reports a truncated datagram's full length
#else
  const int flags = 0;
#endif
  const ssize_t n = ::recvfrom(fd_, buf, capacity, flags, reinterpret_cast<sockaddr*>(&from.address),
                               &from.length);
  if (n < 0) return false;
#endif
  size = static_cast<std::size_t>(n);
  return true;
}

bool UdpSocket::send(const uint8_t* data, std::size_t size, const Endpoint& to) {
#ifdef _WIN32
  const int n = ::sendto(fd_, reinterpret_cast<const char*>(data), static_cast<int>(size), 0,
                         reinterpret_cast<const sockaddr*>(&to.address), to.length);
#else
  const ssize_t n = ::sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&to.address), to.length);
#endif
  return n >= 0 && static_cast<std::size_t>(n) == size;
}

}  // namespace softdeca::stream
