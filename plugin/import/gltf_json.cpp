#include "gltf_json.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace softdeca::avatar_import::gltf {

namespace {
std::string shown(double number) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", number);
  return text;
}
}  // namespace

std::uint64_t as_size(const Json& value, const std::string& where) {
  if (!value.is_number()) throw Problem(where, std::string("is ") + value.kind() + ", not a number");
  const double number = value.number(where);
  if (number < 0 || number != std::floor(number)) throw Problem(where, shown(number) + " is not a whole number of at least 0");
  if (number > static_cast<double>(kMaxExactInteger))
    throw Problem(where, shown(number) + " is more than 2^53, the most a glTF index or size may be");
  return static_cast<std::uint64_t>(number);
}

std::size_t as_index(const Json& value, std::size_t count, const char* array, const std::string& where) {
  const std::uint64_t index = as_size(value, where);
  if (index >= count)
    throw Problem(where, std::to_string(index) + " is not one of the file's " + std::to_string(count) + " " + array);
  return static_cast<std::size_t>(index);
}

std::string as_string(const Json& value, const std::string& where) {
  if (!value.is_string()) throw Problem(where, std::string("is ") + value.kind() + ", not a string");
  return value.string(where);
}

Object::Object(const Json& value, std::string where) : value_(&value), where_(std::move(where)) {
  if (!value.is_object()) throw Problem(where_, std::string(where_.empty() ? "its JSON is " : "is ") + value.kind() + ", not an object");
}

const Json* Object::find(const std::string& key) const {
  const Json* found = nullptr;
  for (const auto& [name, member] : value_->members(where_))
    if (name == key) found = &member;
  return found;
}

const std::vector<std::pair<std::string, Json>>& Object::members() const { return value_->members(where_); }

std::uint64_t Object::size(const std::string& key) const {
  const Json* v = find(key);
  if (!v) fail("has no " + key);
  return as_size(*v, at(key));
}

std::uint64_t Object::size_or(const std::string& key, std::uint64_t absent) const {
  const Json* v = find(key);
  return v ? as_size(*v, at(key)) : absent;
}

std::optional<std::uint64_t> Object::optional_size(const std::string& key) const {
  const Json* v = find(key);
  if (!v) return std::nullopt;
  return as_size(*v, at(key));
}

std::size_t Object::index(const std::string& key, std::size_t count, const char* array) const {
  const Json* v = find(key);
  if (!v) fail("has no " + key);
  return as_index(*v, count, array, at(key));
}

std::optional<std::size_t> Object::optional_index(const std::string& key, std::size_t count, const char* array) const {
  const Json* v = find(key);
  if (!v) return std::nullopt;
  return as_index(*v, count, array, at(key));
}

double Object::number_or(const std::string& key, double absent) const {
  const Json* v = find(key);
  if (!v) return absent;
  if (!v->is_number()) throw Problem(at(key), std::string("is ") + v->kind() + ", not a number");
  return v->number(key);
}

bool Object::boolean_or(const std::string& key, bool absent) const {
  const Json* v = find(key);
  if (!v) return absent;
  if (v->type() != Json::Type::Bool) throw Problem(at(key), std::string("is ") + v->kind() + ", not true or false");
  return v->boolean(key);
}

std::string Object::string_or(const std::string& key, const std::string& absent) const {
  const Json* v = find(key);
  return v ? as_string(*v, at(key)) : absent;
}

Object Object::object(const std::string& key) const {
  const Json* v = find(key);
  if (!v) fail("has no " + key);
  return Object(*v, at(key));
}

std::optional<Object> Object::optional_object(const std::string& key) const {
  const Json* v = find(key);
  if (!v) return std::nullopt;
  return Object(*v, at(key));
}

const std::vector<Json>& Object::array(const std::string& key) const {
  const std::vector<Json>* a = optional_array(key);
  if (!a) fail("has no " + key);
  return *a;
}

const std::vector<Json>* Object::optional_array(const std::string& key) const {
  const Json* v = find(key);
  if (!v) return nullptr;
  if (!v->is_array()) throw Problem(at(key), std::string("is ") + v->kind() + ", not an array");
  return &v->array(key);
}

std::vector<double> Object::numbers_or(const std::string& key, std::size_t count, std::vector<double> absent) const {
  const std::vector<Json>* a = optional_array(key);
  if (!a) return absent;
  if (a->size() != count) throw Problem(at(key), "has " + std::to_string(a->size()) + " numbers, not " + std::to_string(count));
  std::vector<double> out;
  for (std::size_t i = 0; i < count; ++i) {
    if (!(*a)[i].is_number()) throw Problem(at(key) + "[" + std::to_string(i) + "]", std::string("is ") + (*a)[i].kind() + ", not a number");
    out.push_back((*a)[i].number(key));
  }
  return out;
}

std::optional<std::uint64_t> checked_sum(std::uint64_t a, std::uint64_t b) {
  if (b > std::numeric_limits<std::uint64_t>::max() - a) return std::nullopt;
  return a + b;
}

std::optional<std::uint64_t> checked_product(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return std::nullopt;
  return a * b;
}

void DecodeBudget::take(std::uint64_t bytes, const std::string& where) {
  const std::uint64_t max = limits_.decoded_budget(input_);
  if (used_ > max || bytes > max - used_)
    throw Problem(where, "decoding it would take the file's decoded data past the " + std::to_string(max) + " bytes an avatar of " +
                             std::to_string(input_) + " bytes may decode to (twice its size plus " +
                             std::to_string(limits_.decoded_base_bytes) + ", at most " + std::to_string(limits_.max_decoded_bytes) +
                             "; " + std::to_string(used_) + " already)");
  used_ += bytes;
}

}  // namespace softdeca::avatar_import::gltf
