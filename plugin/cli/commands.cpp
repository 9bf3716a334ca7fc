// The registry of sub-commands, in the order `softdeca --help` lists them.
#include "command.h"

namespace softdeca::cli {

int run_replay(const Args&);
int run_bench_runtime(const Args&);

const std::vector<Command>& commands() {
  static const std::vector<Command> kCommands = {
      {"replay", "replay a take through linear blendshapes, SoftDECA and SparseSoftDECA onto an avatar", run_replay},
      {"bench-runtime", "measure the runtime per frame (both models, 1 and 2 threads) -> JSON", run_bench_runtime},
  };
  return kCommands;
}

}  // namespace softdeca::cli
