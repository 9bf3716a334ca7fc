// BSD sockets (Linux, macOS, iOS, Android) behind socket_platform.h.
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cstring>

#include "stream/socket_platform.h"
#include "stream/socket_system.h"

namespace softdeca::stream::platform {

std::intptr_t open_udp(int family) {
  const int fd = ::socket(family, SOCK_DGRAM, 0);
  if (fd < 0) return -1;
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL, 0) | O_NONBLOCK);
  fcntl(fd, F_SETFD, FD_CLOEXEC);
  // A larger receive buffer rides out bursts while the receiving thread is descheduled.
  const int bytes = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes);
  return fd;
}

void close_socket(std::intptr_t fd) {
  if (fd >= 0) ::close(static_cast<int>(fd));
}

bool bind_socket(std::intptr_t fd, const Endpoint& local) {
  return ::bind(static_cast<int>(fd), reinterpret_cast<const sockaddr*>(local.address), local.length) == 0;
}

bool local_address(std::intptr_t fd, Endpoint& out) {
  socklen_t length = sizeof out.address;
  if (getsockname(static_cast<int>(fd), reinterpret_cast<sockaddr*>(out.address), &length) != 0) return false;
  out.length = static_cast<uint32_t>(length);
  return true;
}

bool wait_readable(std::intptr_t fd, int timeout_ms) {
  pollfd p{static_cast<int>(fd), POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0;
}

long receive_from(std::intptr_t fd, uint8_t* buf, std::size_t capacity, Endpoint& from, bool& truncated) {
#ifdef MSG_TRUNC
  const int flags = MSG_TRUNC;  // Linux then reports a truncated datagram's full length
#else
  const int flags = 0;
#endif
  socklen_t length = sizeof from.address;
  const ssize_t n = ::recvfrom(static_cast<int>(fd), buf, capacity, flags, reinterpret_cast<sockaddr*>(from.address), &length);
  from.length = static_cast<uint32_t>(length);
  truncated = n > static_cast<ssize_t>(capacity);
  return static_cast<long>(n);
}

long send_to(std::intptr_t fd, const uint8_t* data, std::size_t size, const Endpoint& to) {
  return static_cast<long>(::sendto(static_cast<int>(fd), data, size, 0, reinterpret_cast<const sockaddr*>(to.address), to.length));
}

std::string last_error() { return std::strerror(errno); }

}  // namespace softdeca::stream::platform
