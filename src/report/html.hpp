// The HTML page around the report's sections: head with the inline CSS,
// end, and gnuplot's SVG made fit to sit inline. Private to the report.
#pragma once

#include <string>

namespace demcal::report {

/// From <!DOCTYPE html> to the opening <main>, the style sheet inline.
std::string page_head(const std::string& title);
/// Closes what page_head() opened.
std::string page_end();

/// gnuplot's SVG made fit to sit inline in HTML: no XML prolog, no
/// namespace declarations (the HTML parser supplies them), ids made unique
/// per figure with `prefix`; "" when `svg` has no <svg> element.
std::string inline_svg(std::string svg, const std::string& prefix, const std::string& label,
                       const std::string& css_class);

}  // namespace demcal::report
