// Winsock behind socket_platform.h.
#include <mutex>

#include "stream/socket_platform.h"
#include "stream/socket_system.h"

namespace softdeca::stream::platform {
namespace {
// Winsock must be started before the first socket; WSAStartup counts its users itself, so one
// start per process that is never undone is enough (the process exit releases it).
bool start_winsock() {
  static std::once_flag once;
  static bool started = false;
  std::call_once(once, [] {
    WSADATA data;
    started = WSAStartup(MAKEWORD(2, 2), &data) == 0;
  });
  return started;
}
SOCKET native(std::intptr_t fd) { return static_cast<SOCKET>(fd); }
}  // namespace

std::intptr_t open_udp(int family) {
  if (!start_winsock()) return -1;
  const SOCKET s = ::socket(family, SOCK_DGRAM, IPPROTO_UDP);
  if (s == INVALID_SOCKET) return -1;
  u_long nonblocking = 1;
  ioctlsocket(s, FIONBIO, &nonblocking);
  SetHandleInformation(reinterpret_cast<HANDLE>(s), HANDLE_FLAG_INHERIT, 0);
  // A larger receive buffer rides out bursts while the receiving thread is descheduled.
  const int bytes = 4 << 20;
  setsockopt(s, SOL_SOCKET, SO_RCVBUF, reinterpret_cast<const char*>(&bytes), sizeof bytes);
  return static_cast<std::intptr_t>(s);
}

void close_socket(std::intptr_t fd) {
  if (fd != -1) closesocket(native(fd));
}

bool bind_socket(std::intptr_t fd, const Endpoint& local) {
  return ::bind(native(fd), reinterpret_cast<const sockaddr*>(local.address), static_cast<int>(local.length)) == 0;
}

bool local_address(std::intptr_t fd, Endpoint& out) {
  int length = sizeof out.address;
  if (getsockname(native(fd), reinterpret_cast<sockaddr*>(out.address), &length) != 0) return false;
  out.length = static_cast<uint32_t>(length);
  return true;
}

bool wait_readable(std::intptr_t fd, int timeout_ms) {
  WSAPOLLFD p{native(fd), POLLRDNORM, 0};
  return WSAPoll(&p, 1, timeout_ms) > 0;
}

long receive_from(std::intptr_t fd, uint8_t* buf, std::size_t capacity, Endpoint& from, bool& truncated) {
  int length = sizeof from.address;
  const int n = ::recvfrom(native(fd), reinterpret_cast<char*>(buf), static_cast<int>(capacity), 0,
                           reinterpret_cast<sockaddr*>(from.address), &length);
  from.length = static_cast<uint32_t>(length);
  truncated = n < 0 && WSAGetLastError() == WSAEMSGSIZE;  // Winsock does not say how long it was
  return truncated ? static_cast<long>(capacity) : n;
}

long send_to(std::intptr_t fd, const uint8_t* data, std::size_t size, const Endpoint& to) {
  return ::sendto(native(fd), reinterpret_cast<const char*>(data), static_cast<int>(size), 0,
                  reinterpret_cast<const sockaddr*>(to.address), static_cast<int>(to.length));
}

std::string last_error() { return "Winsock error " + std::to_string(WSAGetLastError()); }

}  // namespace softdeca::stream::platform
