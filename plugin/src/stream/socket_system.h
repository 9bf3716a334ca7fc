// The system socket headers: Winsock on Windows, BSD sockets elsewhere. The one place that
// chooses; included by the socket_*.cpp files only.
#pragma once

#ifdef _WIN32
#include <winsock2.h>
#include <ws2tcpip.h>
#else
#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#endif
