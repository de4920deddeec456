#include "doc.hpp"

namespace demcal::report {

std::string esc(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

namespace {

/// A Markdown table cell: '|' escaped, on one line.
std::string md_cell(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '|')
      o += "\\|";
    else if (c == '\n')
      o += ' ';
    else
      o += c;
  }
  return o;
}

std::string cell_class(const std::string& c) {
  if (c == "pass" || c == "yes") return "ok";
  if (c == "FAIL" || c == "diverged" || c == "no") return "bad";
  if (c == "stopped early") return "warn";
  return "";
}

}  // namespace

void Doc::heading(int level, const std::string& text, const std::string& id) {
  html << "<h" << level << (id.empty() ? "" : " id=\"" + id + "\"") << ">" << esc(text) << "</h"
       << level << ">\n";
  md << std::string(level, '#') << ' ' << text << "\n\n";
}

void Doc::para(const std::string& text, const std::string& cls) {
  html << "<p" << (cls.empty() ? "" : " class=\"" + cls + "\"") << ">" << esc(text) << "</p>\n";
  md << text << "\n\n";
}

void Doc::bullets(const std::vector<std::string>& items) {
  html << "<ul>\n";
  for (const auto& i : items) html << "<li>" << esc(i) << "</li>\n";
  html << "</ul>\n";
  for (const auto& i : items) md << "- " << i << "\n";
  md << "\n";
}

void Doc::code(const std::string& text) {
  html << "<pre><code>" << esc(text) << "</code></pre>\n";
  md << "```sh\n" << text << "\n```\n\n";
}

void Doc::table(const std::vector<std::string>& head,
                const std::vector<std::vector<std::string>>& rows, const std::string& cls) {
  html << "<table" << (cls.empty() ? "" : " class=\"" + cls + "\"") << ">\n<thead><tr>";
  for (const auto& h : head) html << "<th>" << esc(h) << "</th>";
  html << "</tr></thead>\n<tbody>\n";
  for (const auto& r : rows) {
    html << "<tr>";
    for (const auto& c : r) {
      const std::string klass = cell_class(c);
      html << "<td" << (klass.empty() ? "" : " class=\"" + klass + "\"") << ">" << esc(c)
           << "</td>";
    }
    html << "</tr>\n";
  }
  html << "</tbody>\n</table>\n";
  md << '|';
  for (const auto& h : head) md << ' ' << md_cell(h) << " |";
  md << "\n|";
  for (size_t k = 0; k < head.size(); ++k) md << " --- |";
  md << '\n';
  for (const auto& r : rows) {
    md << '|';
    for (const auto& c : r) md << ' ' << md_cell(c) << " |";
    md << '\n';
  }
  md << '\n';
}

void Doc::figure(const std::string& svg, const std::string& caption, const std::string& missing) {
  html << "<figure>\n";
  if (!svg.empty())
    html << svg << "\n";
  else
    html << "<div class=\"noplot\">" << esc(missing) << "</div>\n";
  html << "<figcaption>" << esc(caption) << "</figcaption>\n</figure>\n";
  md << "*Figure (in report.html): " << caption << "*\n\n";
}

void Doc::details_begin(const std::string& summary) {
  html << "<details>\n<summary>" << esc(summary) << "</summary>\n<div class=\"scroll\">\n";
}

void Doc::details_end() { html << "</div>\n</details>\n"; }

}  // namespace demcal::report
