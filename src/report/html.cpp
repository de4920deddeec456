#include "html.hpp"

#include "doc.hpp"

namespace demcal::report {

namespace {

const char* kCss = R"(
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:#1b1b1b;background:#fafafa;margin:0}
main{max-width:1120px;margin:0 auto;padding:18px 28px 60px;background:#ffffff}
h1{font-size:1.6em;margin:0.4em 0 0.2em}
h2{font-size:1.25em;margin-top:1.8em;border-bottom:2px solid #e3e3e3;padding-bottom:4px}
h3{font-size:1.05em;margin-top:1.3em}
p,li{line-height:1.45}
table{border-collapse:collapse;margin:8px 0 14px;font-size:0.92em}
th,td{border:1px solid #d6d6d6;padding:4px 8px;text-align:left;vertical-align:top}
th{background:#f1f3f5}
td.ok{color:#176b2c;font-weight:600}
td.bad{color:#b3261e;font-weight:600}
td.warn{color:#8a5a00}
.banner{padding:10px 14px;border-radius:6px;font-weight:600;margin:10px 0}
.banner.ok{background:#e6f4ea;border:1px solid #9ad0a8;color:#0f5223}
.banner.bad{background:#fdecea;border:1px solid #f1a7a1;color:#8c1d18}
.grid{display:flex;flex-wrap:wrap;gap:24px;align-items:flex-start}
.grid > div{flex:1 1 440px}
pre{background:#f4f4f4;border:1px solid #e0e0e0;padding:8px 10px;overflow-x:auto;white-space:pre-wrap;word-break:break-all}
figure{margin:12px 0 20px}
figcaption{font-size:0.9em;color:#444444;margin-top:4px}
svg.plot{width:100%;height:auto;display:block}
svg.narrow{max-width:720px}
svg.assembly{width:100%;max-width:780px;height:auto;display:block}
.noplot{border:1px dashed #b0b0b0;background:#fbfbfb;padding:14px;color:#555555}
.small{font-size:0.88em;color:#444444}
details{margin:10px 0}
summary{cursor:pointer;font-weight:600}
table.trials td,table.trials th{font-size:0.82em;padding:2px 5px;white-space:nowrap}
table.trials td:last-child{white-space:normal;min-width:220px}
.scroll{overflow-x:auto}
nav a{margin-right:12px}
)";

}  // namespace

std::string page_head(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta "
         "name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         esc(title) + "</title>\n<style>" + kCss + "</style>\n</head>\n<body>\n<main>\n";
}

std::string page_end() { return "</main>\n</body>\n</html>\n"; }

std::string inline_svg(std::string svg, const std::string& prefix, const std::string& label,
                       const std::string& css_class) {
  const size_t start = svg.find("<svg");
  if (start == std::string::npos) return "";
  svg = svg.substr(start);
  auto erase_all = [&](const std::string& what) {
    for (size_t k; (k = svg.find(what)) != std::string::npos;) svg.erase(k, what.size());
  };
  erase_all(" xmlns=\"http://www.w3.org/2000/svg\"");
  erase_all(" xmlns:xlink=\"http://www.w3.org/1999/xlink\"");
  erase_all("\n xmlns=\"http://www.w3.org/2000/svg\"");
  erase_all("\n xmlns:xlink=\"http://www.w3.org/1999/xlink\"");
  auto erase_element = [&](const std::string& open, const std::string& close) {
    const size_t a = svg.find(open);
    if (a == std::string::npos) return;
    const size_t b = svg.find(close, a);
    if (b != std::string::npos) svg.erase(a, b + close.size() - a);
  };
  erase_element("<title>", "</title>");
  erase_element("<desc>", "</desc>");
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (size_t k = 0; (k = svg.find(from, k)) != std::string::npos; k += to.size())
      svg.replace(k, from.size(), to);
  };
  replace_all("id='", "id='" + prefix);
  replace_all("id=\"", "id=\"" + prefix);
  replace_all("href='#", "href='#" + prefix);
  replace_all("href=\"#", "href=\"#" + prefix);
  replace_all("url(#", "url(#" + prefix);
  const size_t open_end = svg.find("<svg") + 4;
  svg.insert(open_end,
             " class=\"" + css_class + "\" role=\"img\" aria-label=\"" + esc(label) + "\"");
  while (!svg.empty() && (svg.back() == '\n' || svg.back() == ' ')) svg.pop_back();
  return svg;
}

}  // namespace demcal::report
