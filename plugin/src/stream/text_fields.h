#pragma once
// Splitting text into separated fields without copying: the line-by-line CSV reader and the
// '|'-separated iFacialMocap packet walk their input the same way.
#include <string_view>

namespace softdeca::stream {

class TextFields {
 public:
  TextFields(std::string_view text, char separator) : text_(text), separator_(separator) {}
  // Fields end at any of `separators` (lines: "\r\n" reads LF, CRLF and CR-only text alike,
  // CRLF giving an empty field between the two).
  TextFields(std::string_view text, std::string_view separators) : text_(text), separators_(separators) {}

  // The next field (possibly empty) into `field`; false once the text is used up.
  bool next(std::string_view& field) {
    if (begin_ >= text_.size()) return false;
    std::size_t end = separators_.empty() ? text_.find(separator_, begin_) : text_.find_first_of(separators_, begin_);
    if (end == std::string_view::npos) end = text_.size();
    field = text_.substr(begin_, end - begin_);
    begin_ = end + 1;
    return true;
  }

 private:
  std::string_view text_;
  char separator_ = 0;
  std::string_view separators_;  // when set, instead of separator_
  std::size_t begin_ = 0;
};

}  // namespace softdeca::stream
