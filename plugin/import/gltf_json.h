// The glTF reader's view of the file's JSON (bundle/json.h parses it): typed reads of one object
// whose every problem names its place the way the file spells it ("accessors[3].byteOffset"),
// sizes combined in 64 bits without wrapping, and the budget of bytes one import may decode.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bundle/json.h"
#include "import_limits.h"

namespace softdeca::avatar_import::gltf {

using bundle::Json;

// A problem at one place in the file; read_gltf puts the file's path in front.
class Problem : public std::runtime_error {
 public:
  Problem(const std::string& where, const std::string& what) : std::runtime_error(where.empty() ? what : where + ": " + what) {}
};

// The largest whole number a JSON number holds exactly: no index, count or size in a glTF is larger.
constexpr std::uint64_t kMaxExactInteger = std::uint64_t{1} << 53;

// A non-negative whole number at most 2^53 (an index, a count, a byte size).
std::uint64_t as_size(const Json& value, const std::string& where);
// An index into one of the file's arrays of `count` items ("accessors").
std::size_t as_index(const Json& value, std::size_t count, const char* array, const std::string& where);
std::string as_string(const Json& value, const std::string& where);

// One JSON object of the file and its place there.
class Object {
 public:
  // Throws Problem unless `value` is an object. The root object's place is "".
  Object(const Json& value, std::string where);
  const std::string& where() const { return where_; }
  std::string at(const std::string& key) const { return where_.empty() ? key : where_ + "." + key; }
  [[noreturn]] void fail(const std::string& what) const { throw Problem(where_, what); }

  // The member `key` (the last one where a key repeats, as the glTF specification asks), or null.
  const Json* find(const std::string& key) const;
  bool has(const std::string& key) const { return find(key) != nullptr; }
  const std::vector<std::pair<std::string, Json>>& members() const;

  std::uint64_t size(const std::string& key) const;  // required
  std::uint64_t size_or(const std::string& key, std::uint64_t absent) const;
  std::optional<std::uint64_t> optional_size(const std::string& key) const;
  std::size_t index(const std::string& key, std::size_t count, const char* array) const;  // required
  std::optional<std::size_t> optional_index(const std::string& key, std::size_t count, const char* array) const;
  double number_or(const std::string& key, double absent) const;
  bool boolean_or(const std::string& key, bool absent) const;
  std::string string_or(const std::string& key, const std::string& absent) const;
  Object object(const std::string& key) const;  // required
  std::optional<Object> optional_object(const std::string& key) const;
  const std::vector<Json>& array(const std::string& key) const;  // required
  const std::vector<Json>* optional_array(const std::string& key) const;
  // Exactly `count` numbers, or `absent` when the member is missing.
  std::vector<double> numbers_or(const std::string& key, std::size_t count, std::vector<double> absent) const;

 private:
  const Json* value_;
  std::string where_;
};

// a + b and a * b, or nothing where the exact result does not fit 64 bits.
std::optional<std::uint64_t> checked_sum(std::uint64_t a, std::uint64_t b);
std::optional<std::uint64_t> checked_product(std::uint64_t a, std::uint64_t b);
// Whether [offset, offset + length) lies within [0, size), computed without wrapping.
inline bool range_within(std::uint64_t offset, std::uint64_t length, std::uint64_t size) {
  return offset <= size && length <= size - offset;
}

// The bytes one import decodes (accessors' values, decompressed views, Draco's tables, the
// meshes it returns), against ImportLimits::decoded_budget of what it has read: taken before
// each allocation, so a file cannot make the reader allocate more however it shares, repeats or
// compresses its data. Each external buffer read raises the budget by what it allows.
class DecodeBudget {
 public:
  DecodeBudget(const ImportLimits& limits, std::uint64_t input_bytes) : limits_(limits), input_(input_bytes) {}
  void add_input(std::uint64_t bytes) { input_ += bytes; }
  void take(std::uint64_t bytes, const std::string& where);
  std::uint64_t used() const { return used_; }

 private:
  const ImportLimits& limits_;
  std::uint64_t input_, used_ = 0;
};

}  // namespace softdeca::avatar_import::gltf
