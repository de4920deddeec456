// Sphere assemblies for the 3D kernel: the face-centred cubic lattice and
// its analytical peak under axisymmetric compression.
#pragma once

#include <array>
#include <istream>
#include <random>
#include <string>
#include <vector>

#include "demcal/scene/config.hpp"

namespace demcal {

/// Spheres and the box of six walls around them (lo/hi per axis).
struct SphereAssembly {
  std::vector<double> x, y, z, r;
  std::array<double, 3> lo{}, hi{};
  int size() const { return static_cast<int>(x.size()); }
};

/// Face-centred cubic lattice of uniform spheres, cube axes along the box:
/// nx × ny × nz unit cells of edge a = 2√2·r, 4 spheres each, at the sites
/// (i, j, k)·a/2 with i + j + k even, i < 2·nx, j < 2·ny, k < 2·nz; walls
/// touching the outermost spheres. Box edge (2 + (2n − 1)·√2)·r along an
/// axis of n cells. With `contact_strain` ε > 0 the lattice is
/// pre-compressed: every length shrinks by (1 − ε), so every lattice
/// contact and each wall overlaps by 2rε.
SphereAssembly fcc_packing(int nx, int ny, int nz, double radius, double contact_strain = 0.0);

/// A loose random gas of polydisperse spheres, no two overlapping: radii
/// from spec.distribution as for the 2D gas (random_radii.hpp: uniform in
/// [radius_min, radius_max] or lognormal with radius_mean, radius_std), one
/// sphere per cell of a grid of spacing 2.2·r_max jittered within its cell,
/// nx = ny = ceil(cbrt(count·aspect)) cells across, as many layers as needed
/// (aspect = width/height); walls at the grid's faces. Deterministic for
/// spec.seed on every platform. Consolidation (compression) makes it dense.
SphereAssembly random_sphere_gas(const AssemblySpec& spec);
/// The placement of random_sphere_gas for given radii: one sphere per
/// jittered cell (jitter drawn from `rng`), no overlaps. random_sphere_gas
/// is sample() then this, draw for draw.
SphereAssembly sphere_gas(std::vector<double> radii, double aspect, std::mt19937_64& rng);
/// CSV x,y,z,r (header optional, '#' comments, blank lines skipped); walls at
/// the bounding box of the spheres. Bad lines, non-finite values, radii
/// ≤ 0 and overlaps beyond 5 % of the smaller radius are an InputError
/// naming the file and the line.
SphereAssembly read_sphere_file(const std::string& path);
/// The same from a stream; `source` names it in errors.
SphereAssembly read_spheres(std::istream& in, const std::string& source);
/// CSV x,y,z,r with a header, full precision: read_sphere_file reads it
/// back bit for bit (walls then at the spheres' bounding box).
std::string sphere_csv(const SphereAssembly& assembly);

/// σ_zz/σ_xx at sliding failure of a periodic FCC array of uniform spheres
/// (cube axes along the box) under axisymmetric compression along z with
/// friction μ, the horizontal contacts open (Thornton 1979):
/// 2·(1 + μ)/(1 − μ); infinite for μ ≥ 1. Derivation in sphere_packing.cpp.
double fcc_peak_ratio(double friction);
/// The same for the walled nx × ny × nz sample of fcc_packing (the box holds
/// fewer contacts per unit area of each wall than the periodic cell).
double fcc_peak_ratio_walled(double friction, int nx, int ny, int nz);

}  // namespace demcal
