#include "bundle/json.h"

#include <cmath>
#include <cstdlib>

#include "core/error.h"

namespace softdeca::bundle {

namespace {
[[noreturn]] void fail(const std::string& message) { throw Error(SOFTDECA_ERROR_FORMAT, message); }

const char* type_name(Json::Type t) {
  switch (t) {
    case Json::Type::Null: return "null";
    case Json::Type::Bool: return "a boolean";
    case Json::Type::Number: return "a number";
    case Json::Type::String: return "a string";
    case Json::Type::Array: return "an array";
    case Json::Type::Object: return "an object";
  }
  return "?";
}
}  // namespace

class JsonParser {
 public:
  JsonParser(const std::string& text, const JsonLimits& limits) : s_(text), limits_(limits) {}

  Json document() {
    Json v = value(0);
    skip_space();
    if (pos_ != s_.size()) error("unexpected text after the JSON value");
    return v;
  }

 private:
  const std::string& s_;
  const JsonLimits limits_;
  std::size_t pos_ = 0;
  std::size_t values_ = 0;

  [[noreturn]] void error(const std::string& what) const {
    fail("JSON: " + what + " at byte " + std::to_string(pos_));
  }
  void skip_space() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\n' || s_[pos_] == '\r' || s_[pos_] == '\t'))
      ++pos_;
  }
  // After the opening '{' or '[': true (and past it) when `close` follows at once.
  bool empty_list(char close) {
    ++pos_;
    skip_space();
    if (pos_ < s_.size() && s_[pos_] == close) {
      ++pos_;
      return true;
    }
    return false;
  }
  // After an object member or array element: true at ',' (another follows), false at `close`.
  bool another_item(char close) {
    skip_space();
    if (pos_ < s_.size() && s_[pos_] == ',') {
      ++pos_;
      return true;
    }
    if (pos_ < s_.size() && s_[pos_] == close) {
      ++pos_;
      return false;
    }
    error(std::string("expected ',' or '") + close + "'");
  }
  bool consume(const char* word) {
    std::size_t n = 0;
    while (word[n]) ++n;
    if (s_.compare(pos_, n, word) != 0) return false;
    pos_ += n;
    return true;
  }

  Json value(int depth) {
    if (depth > limits_.max_depth) error("nesting deeper than " + std::to_string(limits_.max_depth));
    if (++values_ > limits_.max_values) error("more than the " + std::to_string(limits_.max_values) + " values a document may have");
    skip_space();
    if (pos_ >= s_.size()) error("unexpected end");
    Json v;
    const char c = s_[pos_];
    if (c == '{') {
      v.type_ = Json::Type::Object;
      if (empty_list('}')) return v;
      for (;;) {
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] != '"') error("expected a member name");
        std::string key = string_literal();
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] != ':') error("expected ':'");
        ++pos_;
        v.object_.emplace_back(std::move(key), value(depth + 1));
        if (!another_item('}')) return v;
      }
    }
    if (c == '[') {
      v.type_ = Json::Type::Array;
      if (empty_list(']')) return v;
      for (;;) {
        v.array_.push_back(value(depth + 1));
        if (!another_item(']')) return v;
      }
    }
    if (c == '"') {
      v.type_ = Json::Type::String;
      v.string_ = string_literal();
      return v;
    }
    if (consume("true")) { v.type_ = Json::Type::Bool; v.bool_ = true; return v; }
    if (consume("false")) { v.type_ = Json::Type::Bool; return v; }
    if (consume("null")) return v;
    if (c == '-' || (c >= '0' && c <= '9')) {
      const char* begin = s_.c_str() + pos_;
      char* end = nullptr;
      const double d = std::strtod(begin, &end);
      if (end == begin || !std::isfinite(d)) error("bad number");
      pos_ += static_cast<std::size_t>(end - begin);
      v.type_ = Json::Type::Number;
      v.number_ = d;
      return v;
    }
    error("unexpected character");
  }

  static void append_utf8(std::string& out, unsigned cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  unsigned hex4() {
    if (pos_ + 4 > s_.size()) error("short \\u escape");
    unsigned cp = 0;
    for (int i = 0; i < 4; ++i) {
      const char h = s_[pos_++];
      cp <<= 4;
      if (h >= '0' && h <= '9') cp |= static_cast<unsigned>(h - '0');
      else if (h >= 'a' && h <= 'f') cp |= static_cast<unsigned>(h - 'a' + 10);
      else if (h >= 'A' && h <= 'F') cp |= static_cast<unsigned>(h - 'A' + 10);
      else error("bad \\u escape");
    }
    return cp;
  }

  std::string string_literal() {
    ++pos_;  // opening quote
    std::string out;
    while (pos_ < s_.size()) {
      const char c = s_[pos_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) error("control character in a string");
      if (c != '\\') { out += c; continue; }
      if (pos_ >= s_.size()) break;
      const char e = s_[pos_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          unsigned cp = hex4();
          if (cp >= 0xD800 && cp < 0xDC00 && pos_ + 1 < s_.size() && s_[pos_] == '\\' && s_[pos_ + 1] == 'u') {
            pos_ += 2;
            const unsigned lo = hex4();
            if (lo < 0xDC00 || lo > 0xDFFF) error("bad surrogate pair");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
          }
          append_utf8(out, cp);
          break;
        }
        default: error("bad escape");
      }
    }
    error("unterminated string");
  }
};

const char* Json::kind() const { return type_name(type_); }

Json Json::parse(const std::string& text, const JsonLimits& limits) { return JsonParser(text, limits).document(); }

namespace {
void expect(const Json& j, Json::Type t, const std::string& what) {
  if (j.type() != t) fail(what + " must be " + type_name(t) + ", not " + type_name(j.type()));
}
}  // namespace

double Json::number(const std::string& what) const {
  expect(*this, Type::Number, what);
  return number_;
}

long long Json::integer(const std::string& what) const {
  expect(*this, Type::Number, what);
  if (number_ != std::floor(number_) || std::fabs(number_) > 9.0e15) fail(what + " must be a whole number");
  return static_cast<long long>(number_);
}

bool Json::boolean(const std::string& what) const {
  expect(*this, Type::Bool, what);
  return bool_;
}

const std::string& Json::string(const std::string& what) const {
  expect(*this, Type::String, what);
  return string_;
}

const std::vector<Json>& Json::array(const std::string& what) const {
  expect(*this, Type::Array, what);
  return array_;
}

bool Json::has(const std::string& key) const {
  if (type_ != Type::Object) return false;
  for (const auto& [k, v] : object_)
    if (k == key) return true;
  return false;
}

const std::vector<std::pair<std::string, Json>>& Json::members(const std::string& what) const {
  expect(*this, Type::Object, what);
  return object_;
}

const Json& Json::at(const std::string& key, const std::string& what) const {
  expect(*this, Type::Object, what);
  for (const auto& [k, v] : object_)
    if (k == key) return v;
  fail(what + " has no member \"" + key + "\"");
}

}  // namespace softdeca::bundle
