// The `softdeca` command line: one sub-command per job. A command is a name, a one-line summary
// and a function of its arguments (everything after its name) returning the exit status.
// To add one, write cmd_<name>.cpp with a `run_<name>` function and list it in commands.cpp
// (the bench-* commands are in plugin/bench).
#pragma once

#include <string>
#include <vector>

namespace softdeca::cli {

using Args = std::vector<std::string>;

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const Args& args);
};

const std::vector<Command>& commands();

}  // namespace softdeca::cli
