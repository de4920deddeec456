// The FCC lattice and its analytical peak (sphere_packing.hpp).
#include "demcal/scene/sphere_packing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "demcal/io/files.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/random_radii.hpp"
#include "overlap_check.hpp"

namespace demcal {

SphereAssembly fcc_packing(int nx, int ny, int nz, double radius, double contact_strain) {
  if (nx < 1 || ny < 1 || nz < 1 || !(radius > 0.0))
    throw std::invalid_argument("fcc_packing: cells must be >= 1 and radius > 0");
  SphereAssembly a;
  // Every length shrinks by (1 − ε) about the lower corner, which is then
  // 2rε inside the walls (at ε = 0 the touching lattice, bit for bit).
  const double shrink = 1.0 - contact_strain;
  const double half = std::sqrt(2.0) * radius;  // a/2, the site spacing
  const int n[3] = {nx, ny, nz};
  for (int k = 0; k < 2 * nz; ++k)
    for (int j = 0; j < 2 * ny; ++j)
      for (int i = 0; i < 2 * nx; ++i) {
        if ((i + j + k) % 2 != 0) continue;
        a.x.push_back(radius + half * shrink * i);
        a.y.push_back(radius + half * shrink * j);
        a.z.push_back(radius + half * shrink * k);
        a.r.push_back(radius);
      }
  for (int axis = 0; axis < 3; ++axis) {
    a.lo[axis] = 2.0 * radius * contact_strain;
    a.hi[axis] = (2.0 * radius + (2 * n[axis] - 1) * half) * shrink;
  }
  return a;
}

SphereAssembly random_sphere_gas(const AssemblySpec& spec) {
  if (spec.count < 1) throw std::invalid_argument("random_sphere_gas: count must be >= 1");
  std::mt19937_64 rng(spec.seed);
  std::vector<double> radii = random_radii::sample(spec, rng);
  return sphere_gas(std::move(radii), spec.aspect, rng);
}

SphereAssembly sphere_gas(std::vector<double> radii, double aspect, std::mt19937_64& rng) {
  SphereAssembly a;
  const int n = static_cast<int>(radii.size());
  if (n == 0) return a;
  if (!(aspect > 0.0)) aspect = 1.0;
  a.r = std::move(radii);
  const double r_max = *std::max_element(a.r.begin(), a.r.end());
  const double spacing = 2.2 * r_max;
  const GasGrid grid = gas_grid(3, n, aspect);
  const int across = grid.across, layers = grid.layers;
  a.x.resize(n);
  a.y.resize(n);
  a.z.resize(n);
  for (int i = 0; i < n; ++i) {
    const int cx = i % across, cy = (i / across) % across, cz = i / (across * across);
    // Jitter that keeps each sphere inside its own cell: no overlaps.
    const double room = 0.5 * spacing - a.r[i];
    a.x[i] = (cx + 0.5) * spacing + room * (2.0 * random_radii::uniform01(rng) - 1.0);
    a.y[i] = (cy + 0.5) * spacing + room * (2.0 * random_radii::uniform01(rng) - 1.0);
    a.z[i] = (cz + 0.5) * spacing + room * (2.0 * random_radii::uniform01(rng) - 1.0);
  }
  a.hi = {across * spacing, across * spacing, layers * spacing};
  return a;
}

std::string sphere_csv(const SphereAssembly& a) {
  std::string s = "x,y,z,r\n";
  char line[128];
  for (int i = 0; i < a.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g\n", a.x[i], a.y[i], a.z[i], a.r[i]);
    s += line;
  }
  return s;
}

SphereAssembly read_sphere_file(const std::string& path) {
  std::ifstream in = open_particle_file(path);
  return read_spheres(in, path);
}

SphereAssembly read_spheres(std::istream& in, const std::string& path) {
  SphereAssembly a;
  std::vector<int> lines;  // line of each sphere, for the overlap error
  std::string line;
  int line_no = 0;
  bool seen_content = false;  // a header or a sphere
  auto where = [&]() { return "line " + std::to_string(line_no); };
  while (std::getline(in, line)) {
    ++line_no;
    prepare_particle_line(line, line_no, path);  // the 2D reader's: BOM, CR, NUL
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    double v[4];
    // The 2D reader's checks: fields, finite, radius > 0, |coordinate| + 4 r
    // finite, at most kMaxParticles.
    if (!parse_particle_fields(line, v, seen_content, a.size(), path, where()))
      continue;  // the header
    a.x.push_back(v[0]);
    a.y.push_back(v[1]);
    a.z.push_back(v[2]);
    a.r.push_back(v[3]);
    lines.push_back(line_no);
  }
  if (in.bad()) throw InputError(path, "", "cannot read particle file");
  if (a.size() < 2)
    throw InputError(path, "", "needs at least two spheres, found " + std::to_string(a.size()));
  const int n = a.size();
  const std::vector<double>* pos[3] = {&a.x, &a.y, &a.z};
  for (int axis = 0; axis < 3; ++axis) {
    a.lo[axis] = std::numeric_limits<double>::infinity();
    a.hi[axis] = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      a.lo[axis] = std::min(a.lo[axis], (*pos[axis])[i] - a.r[i]);
      a.hi[axis] = std::max(a.hi[axis], (*pos[axis])[i] + a.r[i]);
    }
  }
  detail::check_overlaps<3>(
      {std::span<const double>(a.x), std::span<const double>(a.y), std::span<const double>(a.z)},
      a.r, lines, path, "sphere");
  return a;
}

// Thornton (1979). An FCC sphere has 12 contacts along <110>: 4 horizontal
// (normals (±1, ±1, 0)/√2) and 8 inclined ((±1, 0, ±1)/√2, (0, ±1, ±1)/√2).
// With σ_ij = (1/V_p)·Σ_c 2r·n_i·f_j over the 6 contacts of one sphere
// counted once, take an inclined contact n = (1, 0, 1)/√2 with normal force
// N and tangential force T in its vertical plane, t = (−1, 0, 1)/√2
// (resisting the upper sphere sliding down): f = N·n + T·t, so
// f_x = (N − T)/√2 and f_z = (N + T)/√2; by symmetry all 8 inclined contacts
// carry the same N and T, the horizontal ones N_h. Then
//   σ_zz ∝ Σ n_z f_z = 4·(N + T)/2 = 2(N + T),
//   σ_xx ∝ Σ n_x f_x = 2·(N − T)/2 + 2·N_h/2 = N − T + N_h.
// Under axial compression at constant σ_xx the ratio grows with T/N and as
// N_h falls; an upper sphere can slide down into the gap of the four below
// only by pushing them apart, which opens the horizontal contacts. At
// failure T = μN and N_h = 0:
//   σ_zz/σ_xx = 2·(1 + μ)/(1 − μ)   (3.714 for μ = 0.3).
double fcc_peak_ratio(double friction) {
  if (friction >= 1.0) return std::numeric_limits<double>::infinity();
  return 2.0 * (1.0 + friction) / (1.0 - friction);
}

// Walled sample. With the inclined contacts carrying equal forces, count
// those crossing a cut. Sites of a plane k: (i, j) with i + j + k even, of
// which ny have i = 0 and ny have i = 2nx − 1. Each sphere has two xz
// neighbours in the plane above ((i ± 1, j, k + 1)) except those on the x
// walls, which have one: a horizontal cut crosses 2·ny·(2nx − 1) xz
// contacts and 2·nx·(2ny − 1) yz contacts, each carrying (N + T)/√2
// vertically, over the area Lx·Ly. A cut normal to x crosses 2·ny·(2nz − 1)
// xz contacts (the open horizontal ones carry nothing), each carrying
// (N − T)/√2, over Ly·Lz. Hence
//   σ_zz/σ_xx = (1 + μ)/(1 − μ) · [2ny(2nx − 1) + 2nx(2ny − 1)]·Lz
//                                  / [2ny(2nz − 1)·Lx],
// L = (2 + (2n − 1)·√2)·r. The periodic cell is the limit n → ∞ (factor 2).
// For a cube (nx = ny = nz) the walls change nothing: the factor is 2
// exactly, the contacts lost at the x walls balancing those lost at the top.
double fcc_peak_ratio_walled(double friction, int nx, int ny, int nz) {
  if (friction >= 1.0) return std::numeric_limits<double>::infinity();
  const double s2 = std::sqrt(2.0);
  const double lx = 2.0 + (2 * nx - 1) * s2, lz = 2.0 + (2 * nz - 1) * s2;
  const double vertical = 2.0 * ny * (2 * nx - 1) + 2.0 * nx * (2 * ny - 1);
  const double lateral = 2.0 * ny * (2 * nz - 1);
  return (1.0 + friction) / (1.0 - friction) * vertical * lz / (lateral * lx);
}

}  // namespace demcal
