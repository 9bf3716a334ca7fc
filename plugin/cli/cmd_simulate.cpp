// softdeca simulate: the physics model φ† on a Live Link Face take. The simulation of a real
// head needs the layered head model, which the training package builds (python), so this
// command runs `python -m softdeca_train simulate` with the same arguments: one
// implementation, reachable from both tools. `softdeca simulate --help` prints its options.
//
// The interpreter is $SOFTDECA_PYTHON, else the checkout's .venv/bin/python when this binary
// runs from the build tree (build/<config>/plugin/cli/softdeca), else python3. The build
// tree's native module and the checkout's training/ are added to PYTHONPATH when they exist.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "command.h"

namespace softdeca::cli {
namespace {
std::string executable_dir() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return {};
  std::string path(buf, static_cast<std::size_t>(n));
  return path.substr(0, path.find_last_of('/'));
}

bool exists(const std::string& path) { return ::access(path.c_str(), F_OK) == 0; }
}  // namespace

int run_simulate(const Args& args) {
  const std::string dir = executable_dir();  // .../build/<config>/plugin/cli
  const std::string build = dir + "/../..", repo = dir + "/../../../..";
  const char* env = std::getenv("SOFTDECA_PYTHON");
  std::string python = env && *env ? env : exists(repo + "/.venv/bin/python") ? repo + "/.venv/bin/python" : "python3";
  std::string path;
  for (const std::string& p : {build + "/python", repo + "/training"})
    if (exists(p)) path += (path.empty() ? "" : ":") + p;
  if (const char* old = std::getenv("PYTHONPATH"); old && *old) path += (path.empty() ? "" : ":") + std::string(old);
  if (!path.empty()) ::setenv("PYTHONPATH", path.c_str(), 1);

  std::vector<std::string> argv_text = {python, "-m", "softdeca_train", "simulate"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  ::execvp(argv[0], argv.data());  // returns only on failure
  std::fprintf(stderr,
               "softdeca simulate: cannot run %s (%s); set SOFTDECA_PYTHON to the project's .venv/bin/python and "
               "PYTHONPATH to build/release/python:training\n",
               python.c_str(), std::strerror(errno));
  return 127;
}

}  // namespace softdeca::cli
