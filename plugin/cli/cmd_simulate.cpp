// softdeca simulate: the physics model φ† on a Live Link Face take. The simulation of a real
// head needs the layered head model, which the training package builds (python), so this
// command runs `python -m softdeca_train simulate` with the same arguments: one
// implementation, reachable from both tools. The interpreter is $SOFTDECA_PYTHON (default
// python3), as for `softdeca replay --seed`; PYTHONPATH must reach training/ and the native
// module (the Makefile exports both). `softdeca simulate --help` prints its options.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "command.h"

namespace softdeca::cli {

int run_simulate(const Args& args) {
  const char* env = std::getenv("SOFTDECA_PYTHON");
  const std::string python = env && *env ? env : "python3";
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
