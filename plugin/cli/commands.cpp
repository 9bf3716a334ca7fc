// The registry of sub-commands, in the order `softdeca --help` lists them.
#include "command.h"

namespace softdeca::cli {

int run_receive(const Args&);
int run_play(const Args&);
int run_convert(const Args&);
int run_info(const Args&);
int run_bench_streaming(const Args&);
int run_bench_reliability(const Args&);
int run_fit(const Args&);
int run_replay(const Args&);
int run_bench_runtime(const Args&);

const std::vector<Command>& commands() {
  static const std::vector<Command> kCommands = {
      {"receive", "receive a live face stream over UDP (ours, Live Link Face, iFacialMocap), optionally recording it",
       run_receive},
      {"play", "play a recording in real time: print its frames or stream them over UDP", run_play},
      {"convert", "convert a Live Link Face CSV take into a recording, or a recording into one", run_convert},
      {"info", "describe a recording: header, frames, duration, damage recovered", run_info},
      {"bench-streaming", "measure receiver throughput and latency and recording rates -> JSON",
       run_bench_streaming},
      {"bench-reliability", "measure the receiver and recording reader under hostile input -> JSON",
       run_bench_reliability},
      {"fit", "fit a user's own ARKit-rigged avatar (glTF, FBX, avatar folder) to a bundle's template once", run_fit},
      {"replay", "replay a take through linear blendshapes, SoftDECA and SparseSoftDECA onto an avatar", run_replay},
      {"bench-runtime", "measure the runtime per frame (both models, 1 and 2 threads) -> JSON", run_bench_runtime},
  };
  return kCommands;
}

}  // namespace softdeca::cli
