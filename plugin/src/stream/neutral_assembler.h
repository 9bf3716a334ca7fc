// Puts a neutral mesh back together from its chunks (any order, duplicates harmless) and
// checks it against its id before handing it out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "stream/wire_format.h"

namespace softdeca::stream {

class NeutralAssembler {
 public:
  // True when this chunk completed a mesh whose checksum matches its id; `out` then holds it.
  bool add(const wire::NeutralChunk& chunk, std::vector<float>& out);

 private:
  uint32_t id_ = 0;
  std::size_t total_ = 0;
  std::vector<float> xyz_;
  std::vector<bool> have_;
  std::size_t have_count_ = 0;
};

}  // namespace softdeca::stream
