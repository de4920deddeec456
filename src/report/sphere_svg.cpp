#include "demcal/report/sphere_svg.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

#include "demcal/io/format.hpp"

namespace demcal {

namespace {

/// The view's frame: w toward the viewer, right and up on the screen.
struct Frame {
  Eigen::Vector3d w, right, up;
};

Frame frame_of(const SphereView& view) {
  const double a = view.azimuth_deg * std::numbers::pi / 180.0,
               e = view.elevation_deg * std::numbers::pi / 180.0;
  Frame f;
  f.w = {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
  f.right = Eigen::Vector3d::UnitZ().cross(f.w).normalized();
  f.up = f.w.cross(f.right);
  return f;
}

using Rgb = std::array<double, 3>;

/// A sequential scale (viridis, five anchors) at t in [0, 1].
Rgb scale_colour(double t) {
  static const Rgb anchors[5] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  t = std::clamp(t, 0.0, 1.0) * 4.0;
  const int k = std::min(3, static_cast<int>(t));
  const double a = t - k;
  Rgb c;
  for (int i = 0; i < 3; ++i) c[i] = anchors[k][i] + a * (anchors[k + 1][i] - anchors[k][i]);
  return c;
}

/// `c` mixed with `towards` (white or black) by `a`, as #rrggbb.
std::string hex(const Rgb& c, double towards = 0.0, double a = 0.0) {
  char b[16];
  auto ch = [&](int i) { return static_cast<int>(std::lround(c[i] + a * (towards - c[i]))); };
  std::snprintf(b, sizeof b, "#%02x%02x%02x", ch(0), ch(1), ch(2));
  return b;
}

std::string full(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

/// The middle of bin k on [0, 1].
double bin_centre(int k) { return (k + 0.5) / kSphereColourBins; }

}  // namespace

std::vector<ProjectedSphere> project_spheres(const SpherePicture& p, const SphereView& view) {
  const Frame f = frame_of(view);
  std::vector<ProjectedSphere> out;
  out.reserve(p.x.size());
  for (size_t i = 0; i < p.x.size(); ++i) {
    const Eigen::Vector3d c(p.x[i], p.y[i], p.z[i]);
    out.push_back({c.dot(f.right), c.dot(f.up), p.r[i], c.dot(f.w), static_cast<int>(i)});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.depth < b.depth; });
  return out;
}

int SphereColourScale::bin(double v) const {
  if (!(hi > lo)) return 0;
  const int k = static_cast<int>(std::floor((v - lo) / (hi - lo) * kSphereColourBins));
  return std::clamp(k, 0, kSphereColourBins - 1);
}

SphereColourScale colour_scale(const SpherePicture& p) {
  SphereColourScale s;
  if (p.force.empty()) return s;
  const auto [lo, hi] = std::minmax_element(p.force.begin(), p.force.end());
  s.lo = *lo;
  s.hi = *hi;
  return s;
}

std::string sphere_svg(const SpherePicture& p, const SphereView& view) {
  if (p.x.empty() || p.force.size() != p.x.size()) return "";
  const Frame f = frame_of(view);
  const std::vector<ProjectedSphere> spheres = project_spheres(p, view);
  // The box's corners on the screen, and the picture's extent.
  std::array<Eigen::Vector3d, 8> corner;
  for (int k = 0; k < 8; ++k)
    corner[k] = {(k & 1) ? p.hi[0] : p.lo[0], (k & 2) ? p.hi[1] : p.lo[1],
                 (k & 4) ? p.hi[2] : p.lo[2]};
  double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
  auto extend = [&](double u, double v, double r) {
    u0 = std::min(u0, u - r);
    u1 = std::max(u1, u + r);
    v0 = std::min(v0, v - r);
    v1 = std::max(v1, v + r);
  };
  for (const auto& c : corner) extend(c.dot(f.right), c.dot(f.up), 0.0);
  for (const auto& s : spheres) extend(s.u, s.v, s.r);
  if (!(u1 > u0 && v1 > v0)) return "";
  const double pad = 16, img_w = 560, scale = img_w / (u1 - u0), img_h = (v1 - v0) * scale;
  const double legend_x = pad + img_w + 40;
  const double total_w = legend_x + 190, total_h = std::max(img_h + 2 * pad, 320.0);
  auto X = [&](double u) { return fixed(pad + (u - u0) * scale, 1); };
  auto Y = [&](double v) { return fixed(pad + (v1 - v) * scale, 1); };
  const SphereColourScale cs = colour_scale(p);

  std::ostringstream s;
  s << "<svg class=\"assembly\" viewBox=\"0 0 " << fixed(total_w, 0) << ' ' << fixed(total_h, 0)
    << "\" role=\"img\" aria-label=\"sphere assembly at the peak, isometric view\">\n<defs>";
  for (int k = 0; k < kSphereColourBins; ++k) {
    const Rgb c = scale_colour(bin_centre(k));
    s << "<radialGradient id=\"sph-" << k << "\" cx=\"0.38\" cy=\"0.34\" r=\"0.72\">"
      << "<stop offset=\"0\" stop-color=\"" << hex(c, 255, 0.6) << "\"/>"
      << "<stop offset=\"0.5\" stop-color=\"" << hex(c) << "\"/>"
      << "<stop offset=\"1\" stop-color=\"" << hex(c, 0, 0.55) << "\"/></radialGradient>";
  }
  s << "</defs>\n<rect x=\"0\" y=\"0\" width=\"" << fixed(total_w, 0) << "\" height=\""
    << fixed(total_h, 0) << "\" fill=\"#ffffff\"/>\n";
  // Box edges: those at the corner nearest the viewer in front, the rest behind.
  int nearest = 0;
  for (int k = 1; k < 8; ++k)
    if (corner[k].dot(f.w) > corner[nearest].dot(f.w)) nearest = k;
  std::ostringstream back, front;
  for (int a = 0; a < 8; ++a)
    for (int bit = 1; bit < 8; bit <<= 1) {
      const int b = a | bit;
      if (b == a) continue;
      std::ostringstream& o = (a == nearest || b == nearest) ? front : back;
      o << "<line x1=\"" << X(corner[a].dot(f.right)) << "\" y1=\"" << Y(corner[a].dot(f.up))
        << "\" x2=\"" << X(corner[b].dot(f.right)) << "\" y2=\"" << Y(corner[b].dot(f.up))
        << "\"/>\n";
    }
  s << "<g stroke=\"#9a9a9a\" stroke-width=\"1\" stroke-dasharray=\"4 3\">\n"
    << back.str() << "</g>\n";
  s << "<g class=\"spheres\" stroke=\"#000000\" stroke-opacity=\"0.35\" stroke-width=\"0.4\">\n";
  for (const auto& q : spheres)
    s << "<circle cx=\"" << X(q.u) << "\" cy=\"" << Y(q.v) << "\" r=\"" << fixed(q.r * scale, 1)
      << "\" fill=\"url(#sph-" << cs.bin(p.force[q.index]) << ")\"/>\n";
  s << "</g>\n<g stroke=\"#555555\" stroke-width=\"1\" stroke-opacity=\"0.45\">\n"
    << front.str() << "</g>\n";
  // Axes: x, y, z from the lower left.
  const double ox = pad + 22, oy = total_h - pad - 8;
  s << "<g font-size=\"12\" font-family=\"sans-serif\" fill=\"#333333\" stroke=\"#333333\">\n";
  const char* names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
    const double du = 26 * e.dot(f.right), dv = -26 * e.dot(f.up);
    s << "<line x1=\"" << fixed(ox, 1) << "\" y1=\"" << fixed(oy, 1) << "\" x2=\""
      << fixed(ox + du, 1) << "\" y2=\"" << fixed(oy + dv, 1) << "\" stroke-width=\"1.5\"/>"
      << "<text x=\"" << fixed(ox + 1.35 * du - 4, 1) << "\" y=\"" << fixed(oy + 1.35 * dv + 4, 1)
      << "\" stroke=\"none\">" << names[a] << "</text>\n";
  }
  s << "</g>\n";
  // Legend: the bins from lo (bottom) to hi (top).
  const double bar_h = std::min(240.0, total_h - 2 * pad - 40), bar_y = pad + 26,
               step = bar_h / kSphereColourBins;
  s << "<g class=\"legend\" data-lo=\"" << full(cs.lo) << "\" data-hi=\"" << full(cs.hi)
    << "\" font-size=\"12\" font-family=\"sans-serif\" fill=\"#333333\">\n"
    << "<text x=\"" << fixed(legend_x, 1) << "\" y=\"" << fixed(pad + 10, 1)
    << "\">Σ normal contact force [N]</text>\n";
  for (int k = 0; k < kSphereColourBins; ++k)
    s << "<rect x=\"" << fixed(legend_x, 1) << "\" y=\""
      << fixed(bar_y + (kSphereColourBins - 1 - k) * step, 2) << "\" width=\"18\" height=\""
      << fixed(step + 0.3, 2) << "\" fill=\"" << hex(scale_colour(bin_centre(k))) << "\"/>";
  s << "\n";
  const double mid = 0.5 * (cs.lo + cs.hi);
  const double marks[3] = {cs.hi, mid, cs.lo};
  for (int k = 0; k < 3; ++k)
    s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + k * bar_h / 2 + 4, 1)
      << "\">" << num(marks[k], 3)
      << (k == 0   ? " (max)"
          : k == 2 ? " (min)"
                   : "")
      << "</text>\n";
  s << "</g>\n</svg>";
  return s.str();
}

}  // namespace demcal
