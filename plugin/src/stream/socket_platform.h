// The system's socket calls behind one interface: socket_posix.cpp (Linux, macOS, iOS, Android)
// or socket_windows.cpp (Winsock); the build compiles one of them. A socket is an intptr_t,
// -1 when invalid. Internal to udp_socket.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "stream/udp_socket.h"

namespace softdeca::stream::platform {

// A non-blocking, non-inherited UDP socket of `family` (AF_INET, AF_INET6), or -1.
std::intptr_t open_udp(int family);
void close_socket(std::intptr_t fd);
bool bind_socket(std::intptr_t fd, const Endpoint& local);
bool local_address(std::intptr_t fd, Endpoint& out);
bool wait_readable(std::intptr_t fd, int timeout_ms);
// -1 when nothing is waiting. Returns the datagram's full length where the system reports it for
// a truncated datagram (Linux), else at most capacity; `truncated` says whether it was cut.
long receive_from(std::intptr_t fd, uint8_t* buf, std::size_t capacity, Endpoint& from, bool& truncated);
long send_to(std::intptr_t fd, const uint8_t* data, std::size_t size, const Endpoint& to);
// The last socket error of this thread, as text.
std::string last_error();
// The address family of an endpoint (AF_INET or AF_INET6), its port, and its host as text.
int family(const Endpoint& e);
uint16_t port(const Endpoint& e);
std::string host_text(const Endpoint& e);
// Fills `out` from a numeric host and port; false when the host is not a numeric address.
bool resolve_numeric(const std::string& host, uint16_t port, Endpoint& out);

}  // namespace softdeca::stream::platform
