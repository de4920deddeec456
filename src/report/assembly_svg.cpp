#include "assembly_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

#include "demcal/io/format.hpp"

namespace demcal::report {

namespace {

std::string rotation_colour(double t) {  // t in [−1, 1]: blue, white, red
  t = std::clamp(t, -1.0, 1.0);
  const double white[3] = {247, 247, 247}, red[3] = {178, 24, 43}, blue[3] = {33, 102, 172};
  const double* end = t >= 0 ? red : blue;
  const double a = std::abs(t);
  char b[16];
  std::snprintf(b, sizeof b, "#%02x%02x%02x",
                static_cast<int>(std::lround(white[0] + a * (end[0] - white[0]))),
                static_cast<int>(std::lround(white[1] + a * (end[1] - white[1]))),
                static_cast<int>(std::lround(white[2] + a * (end[2] - white[2]))));
  return b;
}

}  // namespace

std::string assembly_svg(const AssemblyPicture& p) {
  const double W = p.right - p.left, H = p.top - p.bottom;
  if (!(W > 0 && H > 0)) return "";
  const double pad = 14, img_w = 560, scale = img_w / W, img_h = H * scale;
  const double legend_x = pad + img_w + 36;
  const double total_w = legend_x + 150, total_h = std::max(img_h + 2 * pad, 300.0);
  auto X = [&](double x) { return fixed(pad + (x - p.left) * scale, 2); };
  auto Y = [&](double y) { return fixed(pad + (p.top - y) * scale, 2); };
  double tmax = 0.0, fmax = 0.0, rmean = 0.0;
  for (double t : p.rotation) tmax = std::max(tmax, std::abs(t));
  for (const auto& f : p.forces) fmax = std::max(fmax, f.fn);
  for (double r : p.r) rmean += r;
  rmean = p.r.empty() ? 0.0 : rmean / static_cast<double>(p.r.size());
  const double wmax = std::max(1.0, 0.45 * rmean * scale);  // line width at the largest force
  std::ostringstream s;
  s << "<svg class=\"assembly\" viewBox=\"0 0 " << fixed(total_w, 0) << ' ' << fixed(total_h, 0)
    << "\" role=\"img\" aria-label=\"assembly at the peak\">\n";
  s << "<defs><linearGradient id=\"asm-rot\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">"
    << "<stop offset=\"0\" stop-color=\"" << rotation_colour(-1) << "\"/>"
    << "<stop offset=\"0.5\" stop-color=\"" << rotation_colour(0) << "\"/>"
    << "<stop offset=\"1\" stop-color=\"" << rotation_colour(1) << "\"/>"
    << "</linearGradient></defs>\n";
  s << "<rect x=\"0\" y=\"0\" width=\"" << fixed(total_w, 0) << "\" height=\"" << fixed(total_h, 0)
    << "\" fill=\"#ffffff\"/>\n";
  s << "<g stroke=\"#777777\" stroke-width=\"0.6\">\n";
  for (size_t i = 0; i < p.x.size(); ++i)
    s << "<circle cx=\"" << X(p.x[i]) << "\" cy=\"" << Y(p.y[i]) << "\" r=\""
      << fixed(p.r[i] * scale, 2) << "\" fill=\""
      << rotation_colour(tmax > 0 ? p.rotation[i] / tmax : 0.0) << "\"/>\n";
  s << "</g>\n<g stroke-linecap=\"round\">\n";
  for (const auto& f : p.forces) {
    if (fmax <= 0) break;
    const double w = wmax * f.fn / fmax;
    if (w < 0.15) continue;
    s << "<line x1=\"" << X(f.x1) << "\" y1=\"" << Y(f.y1) << "\" x2=\"" << X(f.x2) << "\" y2=\""
      << Y(f.y2) << "\" stroke=\"" << (f.wall ? "#6b4f1d\" stroke-linecap=\"butt" : "#111111")
      << "\" stroke-width=\"" << fixed(w, 2) << "\"/>\n";
  }
  s << "</g>\n";
  // Walls.
  s << "<rect x=\"" << X(p.left) << "\" y=\"" << Y(p.top) << "\" width=\"" << fixed(img_w, 2)
    << "\" height=\"" << fixed(img_h, 2)
    << "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"2.5\"/>\n";
  // Legend: rotation colour bar and force scale.
  const double bar_y = pad + 22, bar_h = 150;
  const double deg = tmax * 180.0 / std::numbers::pi;
  s << "<g font-family=\"sans-serif\" font-size=\"12\" fill=\"#222222\">\n";
  s << "<text x=\"" << fixed(legend_x - 10, 1) << "\" y=\"" << fixed(pad + 8, 1)
    << "\">rotation [°]</text>\n";
  s << "<rect x=\"" << fixed(legend_x, 1) << "\" y=\"" << fixed(bar_y, 1)
    << "\" width=\"18\" height=\"" << fixed(bar_h, 1)
    << "\" fill=\"url(#asm-rot)\" stroke=\"#555555\" stroke-width=\"0.6\"/>\n";
  s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + 5, 1) << "\">+"
    << num(deg, 3) << " (ccw)</text>\n";
  s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + bar_h / 2 + 4, 1)
    << "\">0</text>\n";
  s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + bar_h + 4, 1) << "\">−"
    << num(deg, 3) << " (cw)</text>\n";
  const double fy = bar_y + bar_h + 40;
  s << "<text x=\"" << fixed(legend_x - 10, 1) << "\" y=\"" << fixed(fy, 1)
    << "\">normal force</text>\n";
  for (int k = 0; k < 2; ++k) {
    const double frac = k == 0 ? 1.0 : 0.5;
    const double ly = fy + 22 + 24 * k;
    s << "<line x1=\"" << fixed(legend_x, 1) << "\" y1=\"" << fixed(ly, 1) << "\" x2=\""
      << fixed(legend_x + 30, 1) << "\" y2=\"" << fixed(ly, 1)
      << "\" stroke=\"#111111\" stroke-linecap=\"round\" stroke-width=\"" << fixed(wmax * frac, 2)
      << "\"/>\n";
    s << "<text x=\"" << fixed(legend_x + 40, 1) << "\" y=\"" << fixed(ly + 4, 1) << "\">"
      << num(fmax * frac, 3) << " N</text>\n";
  }
  s << "</g>\n</svg>";
  return s.str();
}

}  // namespace demcal::report
