#include "demcal/upscaling/rev.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <sstream>

namespace demcal {

// ---------------------------------------------------------------------------
// Geometry

double disk_rectangle_area(double cx, double cy, double r, double x0, double x1, double y0,
                           double y1) {
  if (r <= 0.0 || x1 <= x0 || y1 <= y0) return 0.0;
  if (cx - r >= x0 && cx + r <= x1 && cy - r >= y0 && cy + r <= y1) return std::numbers::pi * r * r;
  if (cx + r <= x0 || cx - r >= x1 || cy + r <= y0 || cy - r >= y1) return 0.0;
  // x − cx = r·sin θ: the chord length times dx becomes a smooth function
  // of θ between the kinks where a chord end meets y0 or y1, so a
  // Gauss–Legendre rule per piece is exact to rounding.
  auto angle = [&](double x) { return std::asin(std::clamp((x - cx) / r, -1.0, 1.0)); };
  const double t0 = angle(x0), t1 = angle(x1);
  std::vector<double> cuts{t0, t1};
  for (double y : {y0, y1}) {
    const double c = std::abs(y - cy) / r;
    if (c < 1.0) {
      const double t = std::acos(c);
      for (double k : {-t, t})
        if (k > t0 && k < t1) cuts.push_back(k);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  static constexpr std::array<double, 5> kNode{0.1488743389816312, 0.4333953941292472,
                                               0.6794095682990244, 0.8650633666889845,
                                               0.9739065285171717};
  static constexpr std::array<double, 5> kWeight{0.2955242247147529, 0.2692667193099963,
                                                 0.2190863625159820, 0.1494513491505806,
                                                 0.0666713443086881};
  auto integrand = [&](double t) {
    const double h = r * std::cos(t);
    const double len = std::min(cy + h, y1) - std::max(cy - h, y0);
    return len > 0.0 ? len * h : 0.0;
  };
  double area = 0.0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    if (b <= a) continue;
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    double s = 0.0;
    for (int q = 0; q < 5; ++q)
      s += kWeight[q] * (integrand(mid - half * kNode[q]) + integrand(mid + half * kNode[q]));
    area += half * s;
  }
  return area;
}

double ks_distance(std::vector<double> a, std::vector<double> b) {
  if (a.empty() || b.empty()) return 1.0;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  size_t i = 0, j = 0;
  double d = 0.0;
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  while (i < a.size() && j < b.size()) {
    const double v = std::min(a[i], b[j]);
    while (i < a.size() && a[i] <= v) ++i;
    while (j < b.size() && b[j] <= v) ++j;
    d = std::max(d, std::abs(i / na - j / nb));
  }
  return d;
}

namespace {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t k = static_cast<size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(k);
  return k + 1 < v.size() ? v[k] * (1.0 - f) + v[k + 1] * f : v[k];
}

PackingStats stats_of(std::span<const double> x, std::span<const double> y,
                      std::span<const double> r, double left, double right, double bottom,
                      double top, double tol) {
  PackingStats s;
  const int n = static_cast<int>(r.size());
  s.particles = n;
  s.width = right - left;
  s.height = top - bottom;
  if (n == 0) return s;
  std::vector<double> radii(r.begin(), r.end());
  double sum = 0.0, sum2 = 0.0;
  for (double v : radii) sum += v;
  s.radius_mean = sum / n;
  for (double v : radii) sum2 += (v - s.radius_mean) * (v - s.radius_mean);
  s.radius_std = std::sqrt(sum2 / n);
  s.radius_min = *std::min_element(radii.begin(), radii.end());
  s.radius_max = *std::max_element(radii.begin(), radii.end());
  s.radius_d10 = quantile(radii, 0.1);
  s.radius_d50 = quantile(radii, 0.5);
  s.radius_d90 = quantile(radii, 0.9);

  // Interior window: 2·r_max in from every side (the whole box when the
  // sample is too small for one).
  double ix0 = left + 2.0 * s.radius_max, ix1 = right - 2.0 * s.radius_max;
  double iy0 = bottom + 2.0 * s.radius_max, iy1 = top - 2.0 * s.radius_max;
  if (ix1 <= ix0 || iy1 <= iy0) {
    ix0 = left;
    ix1 = right;
    iy0 = bottom;
    iy1 = top;
  }
  double solid = 0.0, solid_in = 0.0;
  for (int i = 0; i < n; ++i) {
    solid += disk_rectangle_area(x[i], y[i], r[i], left, right, bottom, top);
    solid_in += disk_rectangle_area(x[i], y[i], r[i], ix0, ix1, iy0, iy1);
  }
  const double box = s.width * s.height;
  s.porosity = box > 0.0 ? 1.0 - solid / box : 0.0;
  const double window = (ix1 - ix0) * (iy1 - iy0);
  s.porosity_interior = window > 0.0 ? 1.0 - solid_in / window : 0.0;

  // Contacts on a cell grid.
  std::vector<int> contacts(n, 0);
  const double cell = 2.0 * s.radius_max * (1.0 + tol) * 1.0000001;
  double x0 = x[0], y0 = y[0], xm = x[0], ym = y[0];
  for (int i = 0; i < n; ++i) {
    x0 = std::min(x0, x[i]);
    y0 = std::min(y0, y[i]);
    xm = std::max(xm, x[i]);
    ym = std::max(ym, y[i]);
  }
  const int64_t cols = static_cast<int64_t>((xm - x0) / cell) + 1;
  const int64_t rows = static_cast<int64_t>((ym - y0) / cell) + 1;
  std::vector<std::pair<int64_t, int>> keyed(n);
  auto cx_of = [&](int i) { return static_cast<int64_t>((x[i] - x0) / cell); };
  auto cy_of = [&](int i) { return static_cast<int64_t>((y[i] - y0) / cell); };
  for (int i = 0; i < n; ++i) keyed[i] = {cy_of(i) * cols + cx_of(i), i};
  std::sort(keyed.begin(), keyed.end());
  for (int i = 0; i < n; ++i) {
    const int64_t cx = cx_of(i), cy = cy_of(i);
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx) {
        const int64_t ncx = cx + dx, ncy = cy + dy;
        if (ncx < 0 || ncy < 0 || ncx >= cols || ncy >= rows) continue;
        const int64_t key = ncy * cols + ncx;
        auto it = std::lower_bound(keyed.begin(), keyed.end(), std::pair<int64_t, int>(key, -1));
        for (; it != keyed.end() && it->first == key; ++it) {
          const int j = it->second;
          if (j <= i) continue;
          const double d = std::hypot(x[j] - x[i], y[j] - y[i]);
          if (d < (r[i] + r[j]) * (1.0 + tol)) {
            ++contacts[i];
            ++contacts[j];
          }
        }
      }
  }
  double total = 0.0, total_in = 0.0;
  int inside = 0;
  for (int i = 0; i < n; ++i) {
    total += contacts[i];
    if (x[i] >= ix0 && x[i] <= ix1 && y[i] >= iy0 && y[i] <= iy1) {
      total_in += contacts[i];
      ++inside;
    }
  }
  s.coordination = total / n;
  s.interior_particles = inside;
  s.coordination_interior = inside > 0 ? total_in / inside : s.coordination;
  return s;
}

}  // namespace

PackingStats packing_stats(const Assembly& a, double tol) {
  return stats_of(a.x, a.y, a.r, a.left, a.right, a.bottom, a.top, tol);
}

PackingStats packing_stats(const World& w, double tol) {
  return stats_of(w.x(), w.y(), w.radius(), w.wall(kLeft).position, w.wall(kRight).position,
                  w.wall(kBottom).position, w.wall(kTop).position, tol);
}

// Thresholds of the verdict. They are choices, stated here and in every
// report: the radius distributions must not differ at the 5 % level of the
// two-sample Kolmogorov–Smirnov test; the interior porosity within 0.02
// (absolute) and the interior coordination number within 0.3 contacts per
// particle (about 10 % of the Z ≈ 3–4 of dense 2D packings) of the
// prototype's.
constexpr double kPorosityTolerance = 0.02;
constexpr double kCoordinationTolerance = 0.3;

Representativeness compare(const PackingStats& rev, const PackingStats& prototype,
                           std::span<const double> rev_radii, std::span<const double> proto_radii) {
  Representativeness out;
  out.rev = rev;
  out.prototype = prototype;
  out.ks = ks_distance(std::vector<double>(rev_radii.begin(), rev_radii.end()),
                       std::vector<double>(proto_radii.begin(), proto_radii.end()));
  const double n = static_cast<double>(rev_radii.size()),
               m = static_cast<double>(proto_radii.size());
  out.ks_critical = n > 0 && m > 0 ? 1.358 * std::sqrt((n + m) / (n * m)) : 0.0;
  out.porosity_difference = rev.porosity_interior - prototype.porosity_interior;
  out.coordination_difference = rev.coordination_interior - prototype.coordination_interior;
  out.radius_mean_difference =
      prototype.radius_mean > 0 ? rev.radius_mean / prototype.radius_mean - 1.0 : 0.0;
  out.size_distribution_ok = out.ks <= out.ks_critical + 1e-12;
  out.porosity_ok = std::abs(out.porosity_difference) <= kPorosityTolerance;
  out.coordination_ok = std::abs(out.coordination_difference) <= kCoordinationTolerance;
  out.representative = out.size_distribution_ok && out.porosity_ok && out.coordination_ok;
  std::ostringstream s;
  s.precision(3);
  s << (out.representative ? "representative" : "NOT representative") << ": radius KS distance "
    << out.ks << " (5 % critical " << out.ks_critical
    << (out.size_distribution_ok ? ", ok" : ", too far") << "), interior porosity "
    << rev.porosity_interior << " vs " << prototype.porosity_interior << " (difference "
    << out.porosity_difference << ", limit " << kPorosityTolerance
    << (out.porosity_ok ? ", ok" : ", too far") << "), interior coordination "
    << rev.coordination_interior << " vs " << prototype.coordination_interior << " (difference "
    << out.coordination_difference << ", limit " << kCoordinationTolerance
    << (out.coordination_ok ? ", ok" : ", too far") << ")";
  out.verdict = s.str();
  return out;
}

nlohmann::json to_json(const PackingStats& s) {
  return {{"particles", s.particles},
          {"radius_mean", s.radius_mean},
          {"radius_std", s.radius_std},
          {"radius_min", s.radius_min},
          {"radius_max", s.radius_max},
          {"radius_d10", s.radius_d10},
          {"radius_d50", s.radius_d50},
          {"radius_d90", s.radius_d90},
          {"width", s.width},
          {"height", s.height},
          {"porosity", s.porosity},
          {"porosity_interior", s.porosity_interior},
          {"coordination", s.coordination},
          {"coordination_interior", s.coordination_interior},
          {"interior_particles", s.interior_particles}};
}

nlohmann::json to_json(const Representativeness& r) {
  return {{"rev", to_json(r.rev)},
          {"prototype", to_json(r.prototype)},
          {"radius_ks_distance", r.ks},
          {"radius_ks_critical_5pct", r.ks_critical},
          {"radius_mean_difference", r.radius_mean_difference},
          {"porosity_interior_difference", r.porosity_difference},
          {"coordination_interior_difference", r.coordination_difference},
          {"thresholds",
           {{"porosity_interior", kPorosityTolerance},
            {"coordination_interior", kCoordinationTolerance},
            {"radius_ks", "two-sample KS test at the 5 % level"},
            {"contact", "centre distance < (r_i + r_j)(1 + 1e-4)"}}},
          {"size_distribution_ok", r.size_distribution_ok},
          {"porosity_ok", r.porosity_ok},
          {"coordination_ok", r.coordination_ok},
          {"representative", r.representative},
          {"verdict", r.verdict}};
}

// ---------------------------------------------------------------------------
// Cutting and generating

namespace {
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
}  // namespace

std::vector<double> resample_radii(std::span<const double> radii, int64_t count, uint64_t seed) {
  std::vector<double> out;
  if (radii.empty() || count <= 0) return out;
  std::mt19937_64 rng(seed ^ 0x5eed5eedULL);
  out.reserve(count);
  for (int64_t k = 0; k < count; ++k) {
    const size_t i = std::min(
        radii.size() - 1, static_cast<size_t>(uniform01(rng) * static_cast<double>(radii.size())));
    out.push_back(radii[i]);
  }
  return out;
}

Assembly gas_of_radii(std::vector<double> radii, double aspect, uint64_t seed) {
  Assembly a;
  a.dense = false;
  const int n = static_cast<int>(radii.size());
  if (n == 0) return a;
  if (!(aspect > 0.0)) aspect = 1.0;
  std::mt19937_64 rng(seed);
  a.r = std::move(radii);
  const double r_max = *std::max_element(a.r.begin(), a.r.end());
  const double spacing = 2.2 * r_max;
  const int columns = std::max(1, static_cast<int>(std::ceil(std::sqrt(n * aspect))));
  const int rows = (n + columns - 1) / columns;
  a.x.resize(n);
  a.y.resize(n);
  for (int i = 0; i < n; ++i) {
    const int cx = i % columns, cy = i / columns;
    const double room = 0.5 * spacing - a.r[i];
    a.x[i] = (cx + 0.5) * spacing + room * (2.0 * uniform01(rng) - 1.0);
    a.y[i] = (cy + 0.5) * spacing + room * (2.0 * uniform01(rng) - 1.0);
  }
  a.left = 0.0;
  a.right = columns * spacing;
  a.bottom = 0.0;
  a.top = rows * spacing;
  return a;
}

Assembly cut_rev(const Assembly& proto, int64_t count, double aspect) {
  const int n = proto.size();
  if (count < 2) throw InputError("REV", "particles", "needs at least 2 particles");
  if (count > n)
    throw InputError("REV", "particles",
                     "asked for " + std::to_string(count) + " particles, the prototype has only " +
                         std::to_string(n));
  const double cx = 0.5 * (proto.left + proto.right), cy = 0.5 * (proto.bottom + proto.top);
  const double w = proto.right - proto.left, h = proto.top - proto.bottom;
  if (!(aspect > 0.0)) aspect = h > 0.0 ? w / h : 1.0;
  // The window is s·aspect wide and s high, centred on the box centre; the
  // count of centres inside is monotone in s.
  auto inside = [&](double s, int i) {
    return std::abs(proto.x[i] - cx) <= 0.5 * s * aspect && std::abs(proto.y[i] - cy) <= 0.5 * s;
  };
  auto count_at = [&](double s) {
    int64_t c = 0;
    for (int i = 0; i < n; ++i) c += inside(s, i);
    return c;
  };
  double lo = 0.0, hi = 2.0 * std::max(h, w / aspect) + 1e-12;
  for (int it = 0; it < 200 && hi - lo > 1e-14 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (count_at(mid) >= count ? hi : lo) = mid;
  }
  const int64_t c_hi = count_at(hi), c_lo = count_at(lo);
  const double s = (c_lo >= 2 && count - c_lo < c_hi - count) ? lo : hi;
  Assembly a;
  for (int i = 0; i < n; ++i) {
    if (!inside(s, i)) continue;
    a.x.push_back(proto.x[i]);
    a.y.push_back(proto.y[i]);
    a.r.push_back(proto.r[i]);
  }
  a.left = a.bottom = std::numeric_limits<double>::infinity();
  a.right = a.top = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < a.size(); ++i) {
    a.left = std::min(a.left, a.x[i] - a.r[i]);
    a.right = std::max(a.right, a.x[i] + a.r[i]);
    a.bottom = std::min(a.bottom, a.y[i] - a.r[i]);
    a.top = std::max(a.top, a.y[i] + a.r[i]);
  }
  a.dense = true;
  return a;
}

Assembly generate_rev(const Assembly& proto, int64_t count, uint64_t seed) {
  if (count < 2) throw InputError("REV", "particles", "needs at least 2 particles");
  const double w = proto.right - proto.left, h = proto.top - proto.bottom;
  return gas_of_radii(resample_radii(proto.r, count, seed), h > 0.0 ? w / h : 1.0, seed);
}

Assembly tile_mirrored(const Assembly& a, int nx, int ny) {
  if (nx < 1 || ny < 1) throw InputError("--tile", "", "needs at least 1x1 copies");
  const double w = a.right - a.left, h = a.top - a.bottom;
  Assembly t;
  t.dense = a.dense;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (int k = 0; k < a.size(); ++k) {
        const double dx = i % 2 == 0 ? a.x[k] - a.left : a.right - a.x[k];
        const double dy = j % 2 == 0 ? a.y[k] - a.bottom : a.top - a.y[k];
        t.x.push_back(a.left + i * w + dx);
        t.y.push_back(a.bottom + j * h + dy);
        t.r.push_back(a.r[k]);
      }
  t.left = a.left;
  t.right = a.left + nx * w;
  t.bottom = a.bottom;
  t.top = a.bottom + ny * h;
  return t;
}

Assembly assembly_of(const World& world) {
  Assembly a;
  a.x.assign(world.x().begin(), world.x().end());
  a.y.assign(world.y().begin(), world.y().end());
  a.r.assign(world.radius().begin(), world.radius().end());
  a.left = world.wall(kLeft).position;
  a.right = world.wall(kRight).position;
  a.bottom = world.wall(kBottom).position;
  a.top = world.wall(kTop).position;
  a.dense = true;
  return a;
}

RevResult make_rev(const SceneConfig& config, const Assembly& prototype, const RevOptions& o) {
  if (o.method != "cut" && o.method != "generate")
    throw InputError("REV", "method", "must be cut or generate, got \"" + o.method + "\"");
  Assembly raw = o.method == "cut" ? cut_rev(prototype, o.particles, o.aspect)
                                   : generate_rev(prototype, o.particles, o.seed);
  RevResult out{o.method, {}, consolidate(config, raw), {}};
  out.assembly = assembly_of(out.state.world);
  out.representativeness = compare(packing_stats(out.state.world), packing_stats(prototype),
                                   out.assembly.r, prototype.r);
  return out;
}

std::string particle_csv(const Assembly& a) {
  // The walls first, as a comment (readers of plain x,y,r skip it;
  // read_particles takes it): a consolidated state read back starts at its
  // walls, not at its bounding box with zero wall stress.
  char walls[160];
  std::snprintf(walls, sizeof walls, "%s %.17g %.17g %.17g %.17g\n", kParticleFileWalls, a.left,
                a.right, a.bottom, a.top);
  std::string s = std::string(walls) + "x,y,r\n";
  char line[96];
  for (int i = 0; i < a.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", a.x[i], a.y[i], a.r[i]);
    s += line;
  }
  return s;
}

}  // namespace demcal
