// Assembly generators, the particle-file reader and the hexagonal peak.
#include "demcal/scene/packing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>

#include "demcal/scene/random_radii.hpp"

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

Assembly random_gas(const AssemblySpec& spec) {
  std::mt19937_64 rng(spec.seed);
  Assembly a;
  a.dense = false;
  const int n = spec.count;
  a.r = random_radii::sample(spec, rng);
  const double r_max = *std::max_element(a.r.begin(), a.r.end());
  const double spacing = 2.2 * r_max;
  const int columns = std::max(1, static_cast<int>(std::ceil(std::sqrt(n * spec.aspect))));
  const int rows = (n + columns - 1) / columns;
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
bool parse_number(const std::string& field, double& value) {
  const char* s = field.c_str();
  char* end = nullptr;
  value = std::strtod(s, &end);
  if (end == s) return false;
  while (*end == ' ' || *end == '\t') ++end;
  return *end == '\0';
}

}  // namespace

Assembly read_particle_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open particle file");
  return read_particles(in, path);
}

Assembly read_particles(std::istream& in, const std::string& path) {
  Assembly a;
  std::vector<int> lines;  // line of each particle, for the overlap error
  std::string line;
  int line_no = 0;
  bool seen_content = false;  // a header or a particle
  auto where = [&]() { return "line " + std::to_string(line_no); };
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 BOM
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    double v[3];
    int numbers = 0;
    for (size_t k = 0; k < fields.size() && k < 3; ++k) numbers += parse_number(fields[k], v[k]);
    if (fields.size() != 3 || numbers != 3) {
      // A header is the first line that is not blank or a comment, and has
      // three fields none of which is a number ("x,y,r"); a line with some
      // numbers is a broken particle line, never silently skipped.
      if (!seen_content && fields.size() == 3 && numbers == 0) {
        seen_content = true;
        continue;
      }
      throw InputError(path, where(), "expected three numbers x,y,r, got \"" + line + "\"");
    }
    seen_content = true;
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw InputError(path, where(), "values must be finite, got \"" + line + "\"");
    if (!(v[2] > 0.0)) throw InputError(path, where(), "radius must be > 0, got \"" + line + "\"");
    a.x.push_back(v[0]);
    a.y.push_back(v[1]);
    a.r.push_back(v[2]);
    lines.push_back(line_no);
  }
  if (in.bad()) throw InputError(path, "", "cannot read particle file");
  if (a.size() < 2)
    throw InputError(path, "", "needs at least two particles, found " + std::to_string(a.size()));
  // Overlaps beyond 5 % of the smaller radius are not a packing but an error
  // (a cell grid keeps the check O(N)).
  const int n = a.size();
  const double r_max = *std::max_element(a.r.begin(), a.r.end());
  double x0 = a.x[0], y0 = a.y[0], x1 = a.x[0], y1 = a.y[0];
  for (int i = 0; i < n; ++i) {
    x0 = std::min(x0, a.x[i]);
    y0 = std::min(y0, a.y[i]);
    x1 = std::max(x1, a.x[i]);
    y1 = std::max(y1, a.y[i]);
  }
  // Cells of at least 2·r_max, and never more than 2^20 a side (a sparse,
  // huge domain would otherwise overflow the integer cell keys); larger
  // cells only cost time, never a missed pair.
  const double extent = std::max(x1 - x0, y1 - y0);
  const double cell = std::max(2.0 * r_max, extent / static_cast<double>(1 << 20));
  if (!std::isfinite(extent) || !std::isfinite(cell) || !(cell > 0.0))
    throw InputError(path, "", "coordinates span more than a double can hold");
  std::vector<std::pair<int64_t, int>> keyed(n);
  auto cell_of = [&](int i) {
    return std::pair<int64_t, int64_t>(static_cast<int64_t>((a.x[i] - x0) / cell),
                                       static_cast<int64_t>((a.y[i] - y0) / cell));
  };
  constexpr int64_t kStride = 1 << 30;
  for (int i = 0; i < n; ++i) {
    auto [cx, cy] = cell_of(i);
    keyed[i] = {cy * kStride + cx, i};
  }
  std::sort(keyed.begin(), keyed.end());
  for (int i = 0; i < n; ++i) {
    auto [cx, cy] = cell_of(i);
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx) {
        const int64_t key = (cy + dy) * kStride + (cx + dx);
        auto it = std::lower_bound(keyed.begin(), keyed.end(), std::pair<int64_t, int>(key, -1));
        for (; it != keyed.end() && it->first == key; ++it) {
          const int j = it->second;
          if (j <= i) continue;
          const double d = std::hypot(a.x[j] - a.x[i], a.y[j] - a.y[i]);
          const double overlap = a.r[i] + a.r[j] - d;
          if (overlap > 0.05 * std::min(a.r[i], a.r[j]))
            throw InputError(path, "line " + std::to_string(lines[std::max(i, j)]),
                             "particle overlaps the one on line " +
                                 std::to_string(lines[std::min(i, j)]) + " by " +
                                 std::to_string(100.0 * overlap / std::min(a.r[i], a.r[j])) +
                                 " % of the smaller radius (limit 5 %)");
        }
      }
  }
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
  return a;
}

Assembly make_assembly(const SceneConfig& config) {
  const auto& s = config.assembly;
  if (s.type == "hexagonal") return hexagonal_packing(s.columns, s.rows, s.radius);
  if (s.type == "square") return square_packing(s.columns, s.rows, s.radius);
  if (s.type == "random") return random_gas(s);
  return read_particle_file(s.file);
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
