#include "demcal/upscaling/rev.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <sstream>

#include "cut_window.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/upscaling/rev_3d.hpp"

namespace demcal {

// ---------------------------------------------------------------------------
// Geometry

namespace {
// The 10-point Gauss–Legendre rule on [−1, 1]: nodes ±kNode, weights kWeight.
constexpr std::array<double, 5> kNode{0.1488743389816312, 0.4333953941292472, 0.6794095682990244,
                                      0.8650633666889845, 0.9739065285171717};
constexpr std::array<double, 5> kWeight{0.2955242247147529, 0.2692667193099963, 0.2190863625159820,
                                        0.1494513491505806, 0.0666713443086881};
}  // namespace

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

double sphere_box_volume(double cx, double cy, double cz, double r, const std::array<double, 3>& lo,
                         const std::array<double, 3>& hi) {
  if (r <= 0.0 || hi[0] <= lo[0] || hi[1] <= lo[1] || hi[2] <= lo[2]) return 0.0;
  const double c[3] = {cx, cy, cz};
  bool inside = true;
  for (int d = 0; d < 3; ++d) {
    if (c[d] + r <= lo[d] || c[d] - r >= hi[d]) return 0.0;
    inside = inside && c[d] - r >= lo[d] && c[d] + r <= hi[d];
  }
  if (inside) return 4.0 / 3.0 * std::numbers::pi * r * r * r;
  // z − cz = r·sin θ: the cross-section is the disk of radius ρ = r·cos θ,
  // dz = ρ dθ, and the integrand A(ρ)·ρ is smooth in θ between the kinks
  // where ρ reaches the distance of a side (A gains a (ρ − d)^{3/2} term)
  // or of a corner (a jump in A's second derivative).
  auto angle = [&](double z) { return std::asin(std::clamp((z - cz) / r, -1.0, 1.0)); };
  const double t0 = angle(lo[2]), t1 = angle(hi[2]);
  std::vector<double> cuts{t0, t1};
  auto add_distance = [&](double dist) {
    if (dist < r) {
      const double t = std::acos(dist / r);
      for (double k : {-t, t})
        if (k > t0 && k < t1) cuts.push_back(k);
    }
  };
  const double dx[2] = {std::abs(lo[0] - cx), std::abs(hi[0] - cx)};
  const double dy[2] = {std::abs(lo[1] - cy), std::abs(hi[1] - cy)};
  for (int k = 0; k < 2; ++k) {
    add_distance(dx[k]);
    add_distance(dy[k]);
    for (int m = 0; m < 2; ++m) add_distance(std::hypot(dx[k], dy[m]));
  }
  std::sort(cuts.begin(), cuts.end());
  auto integrand = [&](double t) {
    const double rho = r * std::cos(t);
    return rho > 0.0 ? disk_rectangle_area(cx, cy, rho, lo[0], hi[0], lo[1], hi[1]) * rho : 0.0;
  };
  // Each piece [a, b] mapped by θ = a + (b − a)·(3u² − 2u³): dθ/du vanishes
  // at both ends, which turns an endpoint's (θ − a)^{3/2} into a smooth u⁴.
  // In four parts: 40 nodes a piece (see the accuracy test).
  constexpr int kSplit = 4;
  double volume = 0.0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    if (b <= a) continue;
    double s = 0.0;
    for (int part = 0; part < kSplit; ++part) {
      const double u0 = static_cast<double>(part) / kSplit, h = 0.5 / kSplit;
      const double mid = u0 + h;
      for (int q = 0; q < 5; ++q)
        for (double u : {mid - h * kNode[q], mid + h * kNode[q]}) {
          const double g = u * u * (3.0 - 2.0 * u), dg = 6.0 * u * (1.0 - u);
          s += kWeight[q] * h * dg * integrand(a + (b - a) * g);
        }
    }
    volume += (b - a) * s;
  }
  return volume;
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

// Area of a disk or volume of a sphere inside a box.
template <size_t D>
double inside_measure(const std::array<double, D>& c, double r, const std::array<double, D>& lo,
                      const std::array<double, D>& hi) {
  if constexpr (D == 2)
    return disk_rectangle_area(c[0], c[1], r, lo[0], hi[0], lo[1], hi[1]);
  else
    return sphere_box_volume(c[0], c[1], c[2], r, lo, hi);
}

// The stats of disks (D = 2) or spheres (D = 3) in the box [lo, hi]; the
// loading axis is the last.
template <size_t D>
PackingStats stats_of(const std::array<std::span<const double>, D>& x, std::span<const double> r,
                      const std::array<double, D>& lo, const std::array<double, D>& hi,
                      double tol) {
  PackingStats s;
  s.dimension = static_cast<int>(D);
  const int n = static_cast<int>(r.size());
  s.particles = n;
  s.width = hi[0] - lo[0];
  s.height = hi[D - 1] - lo[D - 1];
  if constexpr (D == 3) s.depth = hi[1] - lo[1];
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
  std::array<double, D> ilo, ihi;
  bool fits = true;
  for (size_t d = 0; d < D; ++d) {
    ilo[d] = lo[d] + 2.0 * s.radius_max;
    ihi[d] = hi[d] - 2.0 * s.radius_max;
    fits = fits && ihi[d] > ilo[d];
  }
  if (!fits) ilo = lo, ihi = hi;
  double solid = 0.0, solid_in = 0.0;
  for (int i = 0; i < n; ++i) {
    std::array<double, D> c;
    for (size_t d = 0; d < D; ++d) c[d] = x[d][i];
    solid += inside_measure<D>(c, r[i], lo, hi);
    solid_in += inside_measure<D>(c, r[i], ilo, ihi);
  }
  double box = 1.0, window = 1.0;
  for (size_t d = 0; d < D; ++d) {
    box *= hi[d] - lo[d];
    window *= ihi[d] - ilo[d];
  }
  s.porosity = box > 0.0 ? 1.0 - solid / box : 0.0;
  s.porosity_interior = window > 0.0 ? 1.0 - solid_in / window : 0.0;

  // Contacts on a cell grid (cells keyed along the first axis fastest).
  std::vector<int> contacts(n, 0);
  const double cell = 2.0 * s.radius_max * (1.0 + tol) * 1.0000001;
  std::array<double, D> origin;
  std::array<int64_t, D> cells, stride;
  int64_t total_cells = 1;
  for (size_t d = 0; d < D; ++d) {
    origin[d] = *std::min_element(x[d].begin(), x[d].end());
    const double top = *std::max_element(x[d].begin(), x[d].end());
    cells[d] = static_cast<int64_t>((top - origin[d]) / cell) + 1;
    stride[d] = total_cells;
    total_cells *= cells[d];
  }
  auto cell_of = [&](int i, size_t d) {
    return static_cast<int64_t>((x[d][i] - origin[d]) / cell);
  };
  std::vector<std::pair<int64_t, int>> keyed(n);
  for (int i = 0; i < n; ++i) {
    int64_t key = 0;
    for (size_t d = 0; d < D; ++d) key += cell_of(i, d) * stride[d];
    keyed[i] = {key, i};
  }
  std::sort(keyed.begin(), keyed.end());
  int64_t neighbourhood = 1;
  for (size_t d = 0; d < D; ++d) neighbourhood *= 3;
  for (int i = 0; i < n; ++i) {
    for (int64_t m = 0; m < neighbourhood; ++m) {
      int64_t key = 0, rest = m;
      bool valid = true;
      for (size_t d = 0; d < D; ++d) {
        const int64_t c = cell_of(i, d) + rest % 3 - 1;
        rest /= 3;
        valid = valid && c >= 0 && c < cells[d];
        key += c * stride[d];
      }
      if (!valid) continue;
      auto it = std::lower_bound(keyed.begin(), keyed.end(), std::pair<int64_t, int>(key, -1));
      for (; it != keyed.end() && it->first == key; ++it) {
        const int j = it->second;
        if (j <= i) continue;
        const double dist = centre_distance<D>(x, i, j);
        if (dist < (r[i] + r[j]) * (1.0 + tol)) {
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
    bool in = true;
    for (size_t d = 0; d < D; ++d) in = in && x[d][i] >= ilo[d] && x[d][i] <= ihi[d];
    if (in) {
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
  return stats_of<2>({std::span<const double>(a.x), std::span<const double>(a.y)}, a.r,
                     {a.left, a.bottom}, {a.right, a.top}, tol);
}

PackingStats packing_stats(const World& w, double tol) {
  return stats_of<2>({w.x(), w.y()}, w.radius(), {w.wall(kLeft).position, w.wall(kBottom).position},
                     {w.wall(kRight).position, w.wall(kTop).position}, tol);
}

PackingStats packing_stats(const SphereAssembly& a, double tol) {
  return stats_of<3>(
      {std::span<const double>(a.x), std::span<const double>(a.y), std::span<const double>(a.z)},
      a.r, a.lo, a.hi, tol);
}

PackingStats packing_stats(const SphereWorld& w, double tol) {
  return stats_of<3>({w.x(), w.y(), w.z()}, w.radius(),
                     {w.wall(kXMin).position, w.wall(kYMin).position, w.wall(kZMin).position},
                     {w.wall(kXMax).position, w.wall(kYMax).position, w.wall(kZMax).position}, tol);
}

// Thresholds of the verdict. They are choices, stated here and in every
// report: the radius distributions must not differ at the 5 % level of the
// two-sample Kolmogorov–Smirnov test; the interior porosity within 0.02
// (absolute) and the interior coordination number within 0.3 contacts per
// particle (about 10 % of the Z ≈ 3–4 of dense 2D packings) of the
// prototype's. The same in 3D (rev_3d.hpp): porosity is then a volume
// fraction, and 0.3 contacts is about 5–7 % of the Z ≈ 4.5–6 of dense
// random sphere packings (12 in FCC).
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
  nlohmann::json j{{"particles", s.particles},
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
  if (s.dimension == 3) {
    j["dimension"] = 3;
    j["depth"] = s.depth;
  }
  return j;
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
  const GasGrid grid = gas_grid(2, n, aspect);
  const int columns = grid.across, rows = grid.layers;
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
  detail::check_rev_count(count, n, "particles");
  const double cx = 0.5 * (proto.left + proto.right), cy = 0.5 * (proto.bottom + proto.top);
  const double w = proto.right - proto.left, h = proto.top - proto.bottom;
  if (!(aspect > 0.0)) aspect = h > 0.0 ? w / h : 1.0;
  // The window is s·aspect wide and s high, centred on the box centre:
  // centre i is inside from the scale critical(i) on.
  auto critical = [&](int i) {
    return std::max(2.0 * std::abs(proto.x[i] - cx) / aspect, 2.0 * std::abs(proto.y[i] - cy));
  };
  const double s = detail::window_scale(n, count, critical);
  Assembly a;
  for (int i = 0; i < n; ++i) {
    if (critical(i) > s) continue;
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

double rev_gas_aspect(const Assembly& proto) {
  const double w = proto.right - proto.left, h = proto.top - proto.bottom;
  return h > 0.0 ? w / h : 1.0;
}

Assembly generate_rev(const Assembly& proto, int64_t count, uint64_t seed) {
  if (count < 2) throw InputError("REV", "particles", "needs at least 2 particles");
  return gas_of_radii(resample_radii(proto.r, count, seed), rev_gas_aspect(proto), seed);
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
  return make_rev(prototype, o, [&](const Assembly& raw) { return consolidate(config, raw); });
}

RevResult make_rev(const Assembly& prototype, const RevOptions& o,
                   const std::function<ConsolidatedState(const Assembly&)>& consolidated) {
  return make_rev(prototype, o, unconsolidated_rev(prototype, o), consolidated);
}

Assembly unconsolidated_rev(const Assembly& prototype, const RevOptions& o) {
  if (o.method != "cut" && o.method != "generate")
    throw InputError("REV", "method", "must be cut or generate, got \"" + o.method + "\"");
  return o.method == "cut" ? cut_rev(prototype, o.particles, o.aspect)
                           : generate_rev(prototype, o.particles, o.seed);
}

RevResult make_rev(const Assembly& prototype, const RevOptions& o, const Assembly& raw,
                   const std::function<ConsolidatedState(const Assembly&)>& consolidated) {
  RevResult out{o.method, {}, consolidated(raw), {}};
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
