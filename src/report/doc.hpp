// Writing HTML and Markdown side by side, so both files of the report carry
// the same facts. Private to the report.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace demcal::report {

/// Text escaped for HTML (&, <, >, quotes).
std::string esc(const std::string& s);

class Doc {
 public:
  std::ostringstream html, md;

  void heading(int level, const std::string& text, const std::string& id = "");
  void para(const std::string& text, const std::string& cls = "");
  void bullets(const std::vector<std::string>& items);
  void code(const std::string& text);
  /// Cells reading pass/yes, FAIL/diverged/no and "stopped early" are
  /// coloured in the HTML.
  void table(const std::vector<std::string>& head,
             const std::vector<std::vector<std::string>>& rows, const std::string& cls = "");
  /// A figure: inline SVG in the HTML (or a note when it is missing); in
  /// the Markdown a pointer to report.html (the numbers are in the tables).
  void figure(const std::string& svg, const std::string& caption, const std::string& missing);
  void raw_html(const std::string& s) { html << s; }
  void details_begin(const std::string& summary);
  void details_end();
};

}  // namespace demcal::report
