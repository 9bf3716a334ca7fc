#include "bench_child_memory.h"

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace softdeca::cli {
namespace {

// A line of /proc/self/status in bytes ("VmRSS", "VmHWM").
std::uint64_t status_bytes(const char* key) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  std::uint64_t kib = 0;
  const std::size_t n = std::strlen(key);
  while (std::fgets(line, sizeof line, f))
    if (std::strncmp(line, key, n) == 0 && line[n] == ':') kib = std::strtoull(line + n + 1, nullptr, 10);
  std::fclose(f);
  return kib * 1024;
}

// Resets VmHWM to the current RSS; false where that is refused.
bool reset_peak() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

// The child: "<increase> <p><report>", p '1' when prepared, '0' when not, 'R' when the peak
// could not be reset.
[[noreturn]] void child(int out, const std::function<std::string()>& prepare, const std::function<std::string()>& work,
                        const ChildLimits& limits) {
  if (limits.address_space) {
    const rlimit cap{limits.address_space, limits.address_space};
    ::setrlimit(RLIMIT_AS, &cap);
  }
  std::string report;
  try {
    report = prepare();
  } catch (const std::exception& e) {
    report = e.what();
  }
  std::uint64_t increase = 0;
  if (!report.empty()) {
    report = "0" + report;
  } else if (!reset_peak()) {
    report = "R";
  } else {
    const std::uint64_t before = status_bytes("VmRSS");
    try {
      report = "1" + work();
    } catch (const std::exception& e) {
      report = std::string("1") + e.what();
    }
    const std::uint64_t peak = status_bytes("VmHWM");
    increase = peak > before ? peak - before : 0;
  }
  report = std::to_string(increase) + " " + report;
  const ssize_t written = ::write(out, report.data(), report.size());
  ::_exit(written == static_cast<ssize_t>(report.size()) ? 0 : 1);
}
}  // namespace

ChildPeak peak_in_child(const std::string& what, const std::function<std::string()>& prepare,
                        const std::function<std::string()>& work, const ChildLimits& limits) {
  int ends[2];
  if (::pipe(ends) != 0) throw std::runtime_error("bench-reliability: cannot make a pipe");
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("bench-reliability: cannot fork");
  if (pid == 0) {
    ::close(ends[0]);
    child(ends[1], prepare, work, limits);
  }
  ::close(ends[1]);
  std::string report;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limits.seconds);
  bool late = false;
  for (char buf[4096];;) {
    pollfd p{ends[0], POLLIN, 0};
    if (std::chrono::steady_clock::now() > deadline) {
      late = true;
      break;
    }
    if (::poll(&p, 1, 100) <= 0) continue;
    const ssize_t n = ::read(ends[0], buf, sizeof buf);
    if (n <= 0) break;
    report.append(buf, static_cast<std::size_t>(n));
  }
  ::close(ends[0]);
  if (late) ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (late) throw std::runtime_error("bench-reliability: " + what + " did not return within " + std::to_string(limits.seconds) + " s");
  if (WIFSIGNALED(status))
    throw std::runtime_error("bench-reliability: " + what + " killed its process (signal " + std::to_string(WTERMSIG(status)) + ")");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || report.empty())
    throw std::runtime_error("bench-reliability: " + what + " ended its process without a report");
  ChildPeak out;
  char* rest = nullptr;
  out.increase = std::strtoull(report.c_str(), &rest, 10);
  if (rest[0] != ' ' || rest[1] == '\0') throw std::runtime_error("bench-reliability: " + what + ": a garbled report");
  if (rest[1] == 'R') throw std::runtime_error("bench-reliability: cannot reset the peak RSS (/proc/self/clear_refs)");
  out.prepared = rest[1] == '1';
  out.report = rest + 2;
  return out;
}

}  // namespace softdeca::cli
