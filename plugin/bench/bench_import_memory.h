// bench-reliability's import memory run: the peak memory of reading each avatar of a hostile
// corpus (python -m softdeca_train hostile-avatars writes one; its corpus.json lists what each
// attack hands `softdeca fit`), each read in a child process (bench_child_memory.h), against the
// bound the import keeps: 4 x the input's bytes + 500 MB (docs/security.md).
#pragma once

#include <cstdint>
#include <string>

namespace softdeca::cli {

struct ImportMemory {
  // The worst peak RSS increase over (input bytes + 125 MB): at most 4 exactly when every
  // read stayed within 4 x its input + 500 MB.
  double worst_ratio = 0;
  std::string worst;  // "<attack>: +N MiB for M bytes, read|refused"
  int avatars = 0, read = 0, refused = 0;
};

// Throws std::runtime_error when a read kills its process or has not returned within 60 s.
ImportMemory import_memory_run(const std::string& corpus);

}  // namespace softdeca::cli
