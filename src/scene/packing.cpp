// Assembly generators, the particle-file reader and the hexagonal peak.
#include "demcal/scene/packing.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <utility>

#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/scene/random_radii.hpp"
#include "derived_scales.hpp"
#include "overlap_check.hpp"

namespace demcal {

Assembly hexagonal_packing(int columns, int rows, double radius, double contact_strain) {
  Assembly a;
  // Every length of the lattice shrinks by (1 − ε) about the lower-left
  // corner, which is then 2rε inside the walls (at ε = 0 the factors are
  // exactly 1: the touching lattice, bit for bit).
  const double shrink = 1.0 - contact_strain;
  const double h0 = std::sqrt(3.0) * radius;
  const double h = h0 * shrink, spacing = 2.0 * radius * shrink;
  for (int k = 0; k < rows; ++k) {
    const double offset = (k % 2) ? radius * shrink : 0.0;
    for (int i = 0; i < columns; ++i) {
      a.x.push_back(radius + offset + spacing * i);
      a.y.push_back(radius + h * k);
      a.r.push_back(radius);
    }
  }
  a.left = 2.0 * radius * contact_strain;
  a.right = (2.0 * columns + (rows > 1 ? 1.0 : 0.0)) * radius * shrink;
  a.bottom = a.left;
  a.top = (2.0 * radius + (rows - 1) * h0) * shrink;
  return a;
}

Assembly square_packing(int columns, int rows, double radius) {
  Assembly a;
  for (int k = 0; k < rows; ++k)
    for (int i = 0; i < columns; ++i) {
      a.x.push_back(radius + 2.0 * radius * i);
      a.y.push_back(radius + 2.0 * radius * k);
      a.r.push_back(radius);
    }
  a.right = 2.0 * columns * radius;
  a.top = 2.0 * rows * radius;
  return a;
}

GasGrid gas_grid(int dimension, int count, double aspect) {
  const double n = static_cast<double>(std::max(1, count));
  // Capped at count before the cast (aspect 1e300 would overflow an int).
  const double across =
      std::min(std::ceil(dimension == 3 ? std::cbrt(n * aspect) : std::sqrt(n * aspect)), n);
  GasGrid g;
  g.across = std::max(1, static_cast<int>(across));
  const int64_t per_layer =
      dimension == 3 ? int64_t{g.across} * g.across : static_cast<int64_t>(g.across);
  g.layers = static_cast<int>((std::max(1, count) + per_layer - 1) / per_layer);
  return g;
}

// A random gas is consolidated by walls closing in on its grid (gas_grid:
// `across` cells wide, `layers` high, 2.2·r_max apart), and keeps about as
// many particle layers. A gas one particle thick along a side (one row,
// column or layer) never becomes a sample: measured with a 2e6-step budget,
// random_400 at aspect 1e6 (one row) and 0.0025 (one column) stall and
// random_500_3d at 1e6 (one row in a layer 500 cells wide) diverges
// ("overlap beyond limit"). Two layers do consolidate: 3D 30 spheres at
// aspect 1 (4 x 4 x 2, 25 200 steps) and 500 at aspect 8 (16 x 16 x 2,
// 335 800 steps); 2D 40 disks at aspect 10 (20 x 2), 100 at 25 (50 x 2),
// 400 at 100 (200 x 2, 1 000 200 steps) and at 0.01 (2 x 200, 854 600
// steps; seed 3 of 3 ended at an unbalanced-force ratio 1.03x its tolerance).
// Hence layers >= kMinGasLayers = 2, and across >= 2 in 2D.
//
// In 3D `across` counts two sides (the grid is across x across): a gas 2
// across is a column 2 x 2 spheres across, every sphere against two of its
// four side walls, a chain of four-sphere layers rather than a packing, and
// it creeps at isotropic sigma3 instead of coming to rest. Measured on
// random_500_3d at aspect 0.01 (2 x 2 x 125): the side walls hold sigma3
// within 1e-5 while the end walls creep in at the servo's lag (their
// stress 0.25 % short of sigma3, the unbalanced-force ratio 0.0036 the
// global damping's drag on the moving column) until the 2e6-step budget
// ends, and an 8e6-step budget too (0.030 %, 0.00038); seeds 1-4 all
// fail. With its end walls held still the column does not come to rest
// either: its axial stress falls to about 0.76·sigma3 within 8e5 steps
// while the side walls hold sigma3 (the cross-section shears, x wider, y
// narrower). 200 spheres 2 x 2 x 50: one seed of two failed; 3 x 3 x 56
// (aspect 0.03) consolidates in 506 000 steps. Short 2 x 2 columns (8, 20,
// 60 spheres) did come to rest, but whether a chain holds depends on its
// weakest layer, so on its length: no count-free bound but the
// geometry's, kMinGasAcross3D = 3.
//
// With n = count, k = kMinGasLayers, m the least `across` (2 in 2D, 3 in
// 3D) and D the dimension: across = ceil((n·a)^(1/D)) >= m iff a >
// (m − 1)^D/n, and layers = ceil(n/across^(D−1)) >= k iff across <= c =
// ceil((n/(k − 1))^(1/(D−1))) − 1, iff a <= c^D/n. No aspect works when
// c < m: fewer than 3 disks, 10 spheres. The check is gas_grid itself; the
// bounds are the message's.
namespace {
constexpr int kMinGasLayers = 2;
constexpr int kMinGasAcross3D = 3;
}  // namespace

namespace {

// The least cells across a gas needs: 2 disks, 3 spheres.
int min_gas_across(int dimension) { return dimension == 3 ? kMinGasAcross3D : kMinGasLayers; }

bool grid_consolidates(const GasGrid& grid, int dimension) {
  return grid.layers >= kMinGasLayers && grid.across >= min_gas_across(dimension);
}

bool gas_consolidates(int dimension, int count, double aspect) {
  return grid_consolidates(gas_grid(dimension, count, aspect), dimension);
}

// The counts nearest `count` below and above it (up to kMaxParticles) whose
// gas at `aspect` consolidates, 0 where none. A scan, not a bound: the set
// of such counts has holes (3D, aspect 1.79: 15 does, 16 does not, 17 does:
// at 16, gas_grid's cells across step up from 3 to 4, and 16 spheres fill
// one layer of 4 x 4).
std::pair<int64_t, int64_t> nearest_consolidating_counts(int dimension, int count, double aspect) {
  int64_t below = count - 1, above = int64_t{count} + 1;
  while (below > 0 && !gas_consolidates(dimension, static_cast<int>(below), aspect)) --below;
  while (above <= kMaxParticles && !gas_consolidates(dimension, static_cast<int>(above), aspect))
    ++above;
  return {below, above <= kMaxParticles ? above : 0};
}

}  // namespace

std::optional<GasLayersFault> gas_layers_fault(int dimension, int count, double aspect,
                                               bool count_changed, const std::string& aspect_name) {
  const GasGrid grid = gas_grid(dimension, count, aspect);
  if (grid_consolidates(grid, dimension)) return std::nullopt;
  const bool three_d = dimension == 3;
  const double n = count, k = kMinGasLayers, m = min_gas_across(dimension),
               dim = three_d ? 3.0 : 2.0;
  const double c = std::ceil(std::pow(n / (k - 1.0), 1.0 / (dim - 1.0))) - 1.0;
  const char* what = three_d ? "spheres" : "disks";
  std::ostringstream msg;
  if (c < m) {
    msg << "too few " << what << " for a random gas with " << kMinGasLayers
        << " layers along every side"
        << (three_d ? " and " + std::to_string(kMinGasAcross3D) + " spheres across" : "")
        << ": at least " << (three_d ? 10 : 3) << "; got " << count;
    return GasLayersFault{"count", msg.str(), true};
  }
  const double lo = std::pow(m - 1.0, dim) / n, hi = std::pow(c, dim) / n;
  const auto [below, above] = count_changed ? nearest_consolidating_counts(dimension, count, aspect)
                                            : std::pair<int64_t, int64_t>{0, 0};
  const bool blame_count = below > 0 || above > 0;
  msg << "gives a gas of " << grid.across
      << (three_d ? " x " + std::to_string(grid.across) + " cells across and " : " columns and ")
      << grid.layers << (three_d ? " layers" : " rows") << " of " << count << " " << what
      << ": a sample needs at least " << kMinGasLayers << " along every side";
  if (three_d)
    msg << " and " << kMinGasAcross3D << " spheres across (a gas one particle thick never comes "
        << "to a static state between the servo walls, and a column 2 x 2 spheres across, every "
           "sphere against two side walls, is a chain, not a sample: it creeps at isotropic "
           "sigma3 instead of coming to rest)";
  else
    msg << " (a gas one particle thick never comes to a static state between the servo walls)";
  if (blame_count) {
    // The count changed and the aspect did not: the count is named, with
    // the nearest counts that consolidate at this aspect.
    msg << "; at " << aspect_name << " " << aspect;
    if (below > 0 && above > 0)
      msg << " the nearest counts that give a sample are " << below << " and " << above;
    else
      msg << " the nearest count that gives a sample is " << (below > 0 ? below : above);
    msg << " (or " << aspect_name << " above " << lo << " and up to about " << hi << " for count "
        << count << "); got " << count;
    return GasLayersFault{"count", msg.str(), false};
  }
  msg << ", i.e. " << aspect_name << " above " << lo << " and up to about " << hi << " for count "
      << count << "; got " << aspect;
  return GasLayersFault{"aspect", msg.str(), false};
}

std::string gas_layers_problem(int dimension, int count, double aspect,
                               const std::string& aspect_name) {
  const auto fault = gas_layers_fault(dimension, count, aspect, true, aspect_name);
  if (!fault) return "";
  if (fault->too_few) return fault->message;
  return (fault->key == "aspect" ? aspect_name : "the count") + " " + fault->message;
}

Assembly random_gas(const AssemblySpec& spec) {
  std::mt19937_64 rng(spec.seed);
  Assembly a;
  a.dense = false;
  const int n = spec.count;
  a.r = random_radii::sample(spec, rng);
  const double r_max = *std::max_element(a.r.begin(), a.r.end());
  const double spacing = 2.2 * r_max;
  const GasGrid grid = gas_grid(2, n, spec.aspect);
  const int columns = grid.across, rows = grid.layers;
  a.x.resize(n);
  a.y.resize(n);
  for (int i = 0; i < n; ++i) {
    const int cx = i % columns, cy = i / columns;
    const double room = 0.5 * spacing - a.r[i];  // jitter that keeps cells disjoint
    a.x[i] = (cx + 0.5) * spacing + room * (2.0 * random_radii::uniform01(rng) - 1.0);
    a.y[i] = (cy + 0.5) * spacing + room * (2.0 * random_radii::uniform01(rng) - 1.0);
  }
  a.left = 0.0;
  a.right = columns * spacing;
  a.bottom = 0.0;
  a.top = rows * spacing;
  return a;
}

namespace {

/// The whole of `field` (blanks around it allowed) as a number.
bool parse_particle_number(const std::string& field, double& value) {
  const char* s = field.c_str();
  char* end = nullptr;
  value = std::strtod(s, &end);
  if (end == s) return false;
  while (*end == ' ' || *end == '\t') ++end;
  return *end == '\0';
}

/// The position columns of a particle file, then the radius, r.
constexpr const char* kAxes[] = {"x", "y", "z"};

/// Where a hexadecimal number starts in `field` (after blanks and a sign),
/// or npos. strtod reads "0x1p-3" as 0.125, but no DEM tool writes one:
/// in a particle file it is a file that is not what it seems.
size_t hexadecimal_at(const std::string& field) {
  const size_t start = field.find_first_not_of(" \t");
  if (start == std::string::npos) return std::string::npos;
  const size_t digits = start + (field[start] == '+' || field[start] == '-');
  const bool hex = field.size() > digits + 1 && field[digits] == '0' &&
                   (field[digits + 1] == 'x' || field[digits + 1] == 'X');
  return hex ? start : std::string::npos;
}

/// A header field's name: blanks and double quotes around it dropped, in
/// lower case ("X", " \"x\" " and "x" are one name).
std::string header_name(const std::string& field) {
  const auto first = field.find_first_not_of(" \t\"");
  if (first == std::string::npos) return {};
  const auto last = field.find_last_not_of(" \t\"");
  std::string name = field.substr(first, last - first + 1);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

/// Whether a header names the columns the reader takes them for: x, y (z)
/// and the radius (r or radius), in this order. A file whose header says
/// another order ("z,y,x,r", "r,x,y,z") would otherwise be read with its
/// axes swapped: a sample loaded on its side, and no error.
bool header_names_the_columns(const std::vector<std::string>& fields) {
  const size_t n = fields.size();
  for (size_t k = 0; k + 1 < n; ++k)
    if (header_name(fields[k]) != kAxes[k]) return false;
  const std::string r = header_name(fields[n - 1]);
  return r == "r" || r == "radius";
}

}  // namespace

bool parse_particle_fields(const std::string& line, std::span<double> v, bool& seen_content,
                           int64_t particles_read, const std::string& path,
                           const std::string& where) {
  const size_t n = v.size();
  // for the errors (built there: this runs once per line of a large file)
  const char* const columns = n == 3 ? "x,y,r" : "x,y,z,r";
  const auto expected = [&] {
    return std::string(n == 3 ? "three" : "four") + " numbers " + columns;
  };
  std::vector<std::string> fields;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
  size_t numbers = 0;
  for (size_t k = 0; k < fields.size() && k < n; ++k)
    numbers += parse_particle_number(fields[k], v[k]);
  // Refused, not read: a trailing comma ("0,0,0.5,", which getline reads
  // as n fields) usually means a column is missing, and a hexadecimal
  // number is no DEM tool's output. The column is the character's in the
  // line.
  const auto name = [&](size_t k) { return k + 1 == n ? "r" : kAxes[k]; };
  const auto at = [&](size_t column) { return where + ", column " + std::to_string(column + 1); };
  if (fields.size() != n || numbers != n) {
    if (!seen_content && fields.size() == n && numbers == 0) {
      if (!header_names_the_columns(fields))
        throw InputError(path, where,
                         std::string("header: the columns must be ") + columns +
                             " in this order (the radius may be called radius), got " +
                             quoted_value(line));
      // A header's trailing comma ("x,y,r,") as a particle's.
      if (line.back() == ',')
        throw InputError(
            path, at(line.size() - 1),
            std::string("a trailing comma in the header: expected the columns ") + columns +
                " (a trailing comma usually means a column is missing), got " + quoted_value(line));
      seen_content = true;
      return false;  // the header ("x,y,r")
    }
    throw InputError(path, where, "expected " + expected() + ", got " + quoted_value(line));
  }
  if (line.back() == ',')
    throw InputError(
        path, at(line.size() - 1),
        std::string("a trailing comma after ") + name(n - 1) + ": expected " + expected() +
            " (a trailing comma usually means a column is missing), got " + quoted_value(line));
  for (size_t k = 0, column = 0; k < n; column += fields[k].size() + 1, ++k)
    if (const size_t hex = hexadecimal_at(fields[k]); hex != std::string::npos)
      throw InputError(path, at(column + hex),
                       std::string("a hexadecimal number for ") + name(k) +
                           ": particle files hold decimal numbers (0.125, 1.25e-1), got " +
                           quoted_value(line));
  seen_content = true;
  if (!std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }))
    throw InputError(path, where, "values must be finite, got " + quoted_value(line));
  if (!(v[n - 1] > 0.0))
    throw InputError(path, where, "radius must be > 0, got " + quoted_value(line));
  // The overlap test adds a few radii to a coordinate: that must stay finite.
  for (size_t k = 0; k + 1 < n; ++k)
    if (!std::isfinite(std::abs(v[k]) + 4.0 * v[n - 1]))
      throw InputError(
          path, where,
          "values too large (|coordinate| + 4 r overflows a double), got " + quoted_value(line));
  if (particles_read >= kMaxParticles)
    throw InputError(path, where, std::string("more particles than the limit ") + kMaxParticlesWhy);
  return true;
}

void prepare_particle_line(std::string& line, int line_no, const std::string& path) {
  if (line_no == 1) drop_utf8_bom(line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  // strtod would stop at a NUL and take "1.5\0garbage" for 1.5.
  if (const auto nul = line.find('\0'); nul != std::string::npos)
    throw InputError(
        path, "line " + std::to_string(line_no),
        "holds a NUL byte at column " + std::to_string(nul + 1) + " (not a text line)");
}

std::ifstream open_particle_file(const std::string& path) {
  require_readable_file(path);  // a folder, a device, a symlink loop: one line, exit 2
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open particle file");
  return in;
}

Assembly read_particle_file(const std::string& path) {
  std::ifstream in = open_particle_file(path);
  return read_particles(in, path);
}

Assembly read_particles(std::istream& in, const std::string& path) {
  Assembly a;
  std::vector<int> lines;  // line of each particle, for the overlap error
  std::string line;
  int line_no = 0;
  bool seen_content = false;                   // a header or a particle
  std::optional<std::array<double, 4>> walls;  // from a kParticleFileWalls line
  int walls_line = 0;
  auto where = [&]() { return "line " + std::to_string(line_no); };
  while (std::getline(in, line)) {
    ++line_no;
    prepare_particle_line(line, line_no, path);
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos &&
        line.compare(first, std::strlen(kParticleFileWalls), kParticleFileWalls) == 0) {
      std::istringstream w(line.substr(first + std::strlen(kParticleFileWalls)));
      std::array<double, 4> v{};
      std::string rest;
      if (!(w >> v[0] >> v[1] >> v[2] >> v[3]) || (w >> rest) ||
          !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }) ||
          !(v[0] < v[1] && v[2] < v[3]))
        throw InputError(path, where(),
                         "walls: expected four finite numbers left < right, bottom < top, got " +
                             quoted_value(line));
      walls = v;
      walls_line = line_no;
      continue;
    }
    if (first == std::string::npos || line[first] == '#') continue;
    double v[3];
    if (!parse_particle_fields(line, v, seen_content, a.size(), path, where()))
      continue;  // the header
    a.x.push_back(v[0]);
    a.y.push_back(v[1]);
    a.r.push_back(v[2]);
    lines.push_back(line_no);
  }
  if (in.bad()) throw InputError(path, "", "cannot read particle file");
  if (a.size() < 2)
    throw InputError(path, "", "needs at least two particles, found " + std::to_string(a.size()));
  detail::check_overlaps<2>({std::span<const double>(a.x), std::span<const double>(a.y)}, a.r,
                            lines, path, "particle");
  const int n = a.size();
  a.left = a.x[0] - a.r[0];
  a.right = a.x[0] + a.r[0];
  a.bottom = a.y[0] - a.r[0];
  a.top = a.y[0] + a.r[0];
  for (int i = 0; i < n; ++i) {
    a.left = std::min(a.left, a.x[i] - a.r[i]);
    a.right = std::max(a.right, a.x[i] + a.r[i]);
    a.bottom = std::min(a.bottom, a.y[i] - a.r[i]);
    a.top = std::max(a.top, a.y[i] + a.r[i]);
  }
  if (walls) {
    // A wall may press into the particles as a contact does (a consolidated
    // state), never further; it may stand off them (a gas in its box).
    const double r_min = *std::min_element(a.r.begin(), a.r.end());
    const double slack = 0.05 * r_min;
    const auto [l, r, b, t] = *walls;
    const bool ok =
        l <= a.left + slack && r >= a.right - slack && b <= a.bottom + slack && t >= a.top - slack;
    if (!ok)
      throw InputError(path, "line " + std::to_string(walls_line),
                       "walls press into the particles by more than 5 % of the smallest radius "
                       "(their extent is [" +
                           num(a.left, 6) + ", " + num(a.right, 6) + "] x [" + num(a.bottom, 6) +
                           ", " + num(a.top, 6) + "])");
    a.left = l;
    a.right = r;
    a.bottom = b;
    a.top = t;
  }
  return a;
}

// The smallest sigma3 the kernel can resolve. A contact's overlap at sigma3
// is delta = 2*sigma3*t*r/kn (force sigma3*2r*t on the disk), computed from
// positions whose round-off is u*|x| (u = 2^-53). The consolidation asks the
// wall stress within consolidation_tolerance of sigma3; unless that round-off
// is below a tenth of it, the stress is noise (hex_5x5: 1e-3 Pa runs,
// 1e-4 Pa "diverges" in the energy ledger, 1e-9 Pa fails the same way).
void check_resolvable(const SceneConfig& config, const Assembly& a, const std::string& which,
                      const std::string& file, const std::string& tiling) {
  if (a.size() == 0) return;
  const double coordinate =
      std::max({std::abs(a.left), std::abs(a.right), std::abs(a.bottom), std::abs(a.top)});
  const double r_min = *std::min_element(a.r.begin(), a.r.end());
  const Material& m = config.material;
  const bool wall = m.wall.kn > m.particle.kn;
  const double kn = wall ? m.wall.kn : m.particle.kn;
  const std::string kn_field = wall ? "material.wall.kn" : "material.kn";
  const double sigma3 = config.test.lateral_stress;
  const double delta = 2.0 * sigma3 * m.thickness * r_min / kn;
  const double roundoff = 0.5 * std::numeric_limits<double>::epsilon() * coordinate;
  const double tolerance = config.test.consolidation_tolerance;
  const double wanted = 0.1 * tolerance;  // relative
  if (roundoff <= wanted * delta) return;
  const double minimum = roundoff / wanted * kn / (2.0 * m.thickness * r_min);
  const double kn_max = 2.0 * sigma3 * m.thickness * r_min * wanted / roundoff;
  // sigma3 or t too low, kn too high, or the tolerance too fine (when a
  // tolerance below 1 resolves it): the error names the one a --set changed
  // (detail::overlap_culprit) and the --set or file that gave it.
  const std::optional<double> tolerance_min = detail::resolving_tolerance(roundoff, delta);
  const std::string field = detail::overlap_culprit(config, kn_field, tolerance_min);
  std::ostringstream msg;
  msg << "the overlap at sigma3, 2*sigma3*t*r_min/kn = " << delta << " m (sigma3 = " << sigma3
      << " Pa, thickness " << m.thickness << " m, " << kn_field << " = " << kn
      << " N/m), is not resolved by positions up to " << coordinate << " m (round-off " << roundoff
      << " m must stay below a tenth of "
      << "consolidation_tolerance of it): test.lateral_stress must be at least " << minimum
      << " Pa for " << which << "'s assembly (" << a.size() << " particles"
      << (file.empty() ? "" : ", from " + file) << (tiling.empty() ? "" : " mirror-tiled " + tiling)
      << "), or " << kn_field << " at most " << kn_max << " N/m";
  if (!file.empty())
    msg << ", or " << (tiling.empty() ? file + "'s positions" : "the tiled positions of " + file)
        << " within " << wanted * delta / (roundoff / coordinate) << " m of the origin";
  if (field == "material.thickness")
    msg << ", or material.thickness at least " << roundoff / wanted * kn / (2.0 * sigma3 * r_min)
        << " m; got " << m.thickness;
  else if (field == "test.consolidation_tolerance")
    msg << ", or test.consolidation_tolerance at least " << *tolerance_min << "; got " << tolerance;
  else
    msg << "; got " << (field == kn_field ? kn : sigma3);
  throw InputError(source_of(config, field), field, msg.str());
}

Assembly make_assembly(const SceneConfig& config, const std::string& which) {
  const auto& s = config.assembly;
  Assembly a;
  if (s.type == "hexagonal")
    a = hexagonal_packing(s.columns, s.rows, s.radius);
  else if (s.type == "square")
    a = square_packing(s.columns, s.rows, s.radius);
  else if (s.type == "random")
    a = random_gas(s);
  else {
    require_config_file(config, "assembly.file", s.file);
    a = read_particle_file(s.file);
  }
  check_assembly(config, a, which);
  return a;
}

void check_assembly(const SceneConfig& config, const Assembly& a, const std::string& which,
                    const std::string& file, const std::string& tiling) {
  detail::check_derived_scales(config, a.r, file);
  check_resolvable(config, a, which, file, tiling);
}

void check_particle_file_scales(const SceneConfig& config, std::span<const double> radii,
                                const std::string& file) {
  detail::check_derived_scales(config, radii, file);
}

double hexagonal_peak_ratio(double friction) {
  const double phi = std::atan(friction);
  const double theta = std::numbers::pi / 3.0;
  if (theta + phi >= std::numbers::pi / 2.0) return std::numeric_limits<double>::infinity();
  return std::tan(theta) * std::tan(theta + phi);
}

// Walled sample: with the inclined contacts carrying equal forces (f_v, f_h
// components), a horizontal cut crosses 2c − 1 of them and a vertical cut
// R − 1, so σ1 = (2c − 1)·f_v/(W·t) and σ3 = (R − 1)·f_h/(H·t) with
// W = (2c + 1)·r and H = (2 + (R − 1)·√3)·r. The periodic cell has
// σ1 = f_v/(r·t), σ3 = f_h/(√3·r·t). Sliding fixes f_v/f_h = tan(60° + φ).
double hexagonal_peak_ratio_walled(double friction, int columns, int rows) {
  const double periodic = hexagonal_peak_ratio(friction);
  if (rows < 2 || columns < 1) return periodic;
  const double s3 = std::sqrt(3.0);
  const double width_factor = (2.0 * columns - 1.0) / (2.0 * columns + 1.0);
  const double height_factor = (2.0 + (rows - 1) * s3) / ((rows - 1) * s3);
  return periodic * width_factor * height_factor;
}

}  // namespace demcal
