// SHA-256 (FIPS 180-4): the manifest lists one digest per bundle file, checked before use.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace softdeca::bundle {

// Lower-case hex digest of `size` bytes.
std::string sha256_hex(const std::uint8_t* data, std::size_t size);

}  // namespace softdeca::bundle
