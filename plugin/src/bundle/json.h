// A small JSON reader for the bundle manifest and users' glTF files (no third-party dependency
// in the plugin). Numbers are doubles; objects keep their members in file order. What a document
// may cost is bounded: its nesting (the parser recurses once a level) and the number of its
// values (each costs a Json), so memory stays a bounded multiple of the text.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace softdeca::bundle {

struct JsonLimits {
  int max_depth = 64;                                              // how deep a value lies (the document: 0)
  std::size_t max_values = std::numeric_limits<std::size_t>::max();  // values of the document, members and elements included
};

class Json {
 public:
  enum class Type { Null, Bool, Number, String, Array, Object };

  // Throws softdeca::Error(SOFTDECA_ERROR_FORMAT) with the byte offset of the first problem,
  // or of the value past a limit.
  static Json parse(const std::string& text, const JsonLimits& limits = {});

  Type type() const { return type_; }
  const char* kind() const;  // what it is, in words: "a number", "an object", ...
  bool is_null() const { return type_ == Type::Null; }
  bool is_number() const { return type_ == Type::Number; }
  bool is_string() const { return type_ == Type::String; }
  bool is_array() const { return type_ == Type::Array; }
  bool is_object() const { return type_ == Type::Object; }

  // Typed access; `what` names the value in error messages (e.g. "manifest.template").
  double number(const std::string& what) const;
  long long integer(const std::string& what) const;  // a number with no fractional part
  bool boolean(const std::string& what) const;
  const std::string& string(const std::string& what) const;
  const std::vector<Json>& array(const std::string& what) const;
  bool has(const std::string& key) const;
  // The member `key` of an object; throws when absent.
  const Json& at(const std::string& key, const std::string& what) const;
  // An object's members in file order (a key may repeat).
  const std::vector<std::pair<std::string, Json>>& members(const std::string& what) const;

 private:
  Type type_ = Type::Null;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<Json> array_;
  std::vector<std::pair<std::string, Json>> object_;
  friend class JsonParser;
};

}  // namespace softdeca::bundle
