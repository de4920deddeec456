// A command line shown for the user to copy into a shell (the command that
// continues an interrupted run): each word quoted only when it needs it.
#pragma once

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

namespace demcal::cli {

/// `w` as one shell word: as is when plain, else single-quoted.
inline std::string shell_word(const std::string& w) {
  const bool plain = !w.empty() && std::all_of(w.begin(), w.end(), [](unsigned char c) {
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
           std::string_view("_./=:,+-@%").find(static_cast<char>(c)) != std::string_view::npos;
  });
  if (plain) return w;
  std::string q = "'";
  for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// The words joined by spaces, each through shell_word().
inline std::string shell_command(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) {
    if (!out.empty()) out += ' ';
    out += shell_word(w);
  }
  return out;
}

}  // namespace demcal::cli
