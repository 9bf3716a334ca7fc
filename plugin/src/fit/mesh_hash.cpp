#include "fit/mesh_hash.h"

#include <cstring>
#include <vector>

#include "bundle/sha256.h"

namespace softdeca::fit {

std::string mesh_sha256(const float* neutral, std::size_t n, const std::int32_t* triangles, std::size_t nt) {
  std::vector<std::uint8_t> bytes(n * 3 * sizeof(float) + nt * 3 * sizeof(std::int32_t));
  std::memcpy(bytes.data(), neutral, n * 3 * sizeof(float));
  std::memcpy(bytes.data() + n * 3 * sizeof(float), triangles, nt * 3 * sizeof(std::int32_t));
  return bundle::sha256_hex(bytes.data(), bytes.size());
}

}  // namespace softdeca::fit
