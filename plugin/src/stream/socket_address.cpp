// Endpoint conversions: the same calls on every platform (socket_system.h picks the headers).
#include <cstring>

#include "stream/socket_platform.h"
#include "stream/socket_system.h"

namespace softdeca::stream::platform {
namespace {
const sockaddr_storage& storage(const Endpoint& e) { return *reinterpret_cast<const sockaddr_storage*>(e.address); }
static_assert(sizeof(sockaddr_storage) <= sizeof(Endpoint::address), "Endpoint holds a sockaddr_storage");
}  // namespace

int family(const Endpoint& e) { return storage(e).ss_family; }

uint16_t port(const Endpoint& e) {
  return family(e) == AF_INET ? ntohs(reinterpret_cast<const sockaddr_in*>(e.address)->sin_port)
                              : ntohs(reinterpret_cast<const sockaddr_in6*>(e.address)->sin6_port);
}

std::string host_text(const Endpoint& e) {
  char host[INET6_ADDRSTRLEN] = "?";
  if (family(e) == AF_INET)
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(e.address)->sin_addr, host, sizeof host);
  else
    inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(e.address)->sin6_addr, host, sizeof host);
  return host;
}

bool resolve_numeric(const std::string& host, uint16_t port, Endpoint& out) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICHOST | AI_NUMERICSERV | AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (getaddrinfo(host.c_str(), service.c_str(), &hints, &found) != 0 || !found) return false;
  const bool fits = found->ai_addrlen <= sizeof out.address;
  if (fits) {
    std::memcpy(out.address, found->ai_addr, found->ai_addrlen);
    out.length = static_cast<uint32_t>(found->ai_addrlen);
  }
  freeaddrinfo(found);
  return fits;
}

}  // namespace softdeca::stream::platform
