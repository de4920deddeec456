// The one error type for bad input: every command catches it, prints its
// message (file, key, what is wrong) and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace demcal {

/// Bad user input: a config, a particle file, a parameter file. Carries the
/// file and the field (key or line) so the message names both.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(file + ": " + (field.empty() ? "" : field + ": ") + what),
        file_(file),
        field_(field),
        message_(what) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  /// What is wrong, without the file and the field.
  const std::string& message() const { return message_; }

 private:
  std::string file_, field_, message_;
};

/// A user's value quoted in a message, cut to `limit` characters (a 7 MB
/// array echoed whole buries the message): "abc…" (1234567 characters).
/// Control characters (a NUL byte, a newline) are shown as \xNN so the
/// message stays one readable line.
inline std::string quoted_value(std::string_view text, size_t limit = 80) {
  std::string out = "\"";
  size_t shown = 0;
  for (char ch : text) {
    if (shown == limit) break;
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += ch;
    }
    ++shown;
  }
  out += "\"";
  if (text.size() > limit)
    out.insert(out.size() - 1, "...").append(" (" + std::to_string(text.size()) + " characters)");
  return out;
}

}  // namespace demcal
