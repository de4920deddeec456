// Particle assemblies: generators and the particle-file reader.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <istream>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "demcal/scene/config.hpp"

namespace demcal {

/// Disks and the box of walls around them.
struct Assembly {
  std::vector<double> x, y, r;
  double left = 0, right = 0, bottom = 0, top = 0;
  /// True when the disks are already a dense, touching packing (regular
  /// lattices, files); false for a random gas that consolidation compresses.
  bool dense = true;
  int size() const { return static_cast<int>(x.size()); }
};

/// Hexagonal: `rows` horizontal rows of `columns` disks, alternate rows
/// offset by one radius, walls touching. Box (2·columns + 1)·r wide and
/// (2 + (rows − 1)·√3)·r high. With `contact_strain` ε > 0 the lattice is
/// pre-compressed: centre spacing 2r(1 − ε), so every lattice contact and
/// each wall overlaps by 2rε (the kernel tests' and benchmarks' scene).
Assembly hexagonal_packing(int columns, int rows, double radius, double contact_strain = 0.0);
/// Square lattice, walls touching.
Assembly square_packing(int columns, int rows, double radius);
/// The grid a random gas of `count` particles is placed on, one particle a
/// cell (aspect = width/height): 2D `across` = ceil(sqrt(count·aspect))
/// columns, `layers` = ceil(count/across) rows; 3D `across` =
/// ceil(cbrt(count·aspect)) cells along x and along y, `layers` =
/// ceil(count/across²) along z. `across` is at most `count` (a wider grid
/// leaves cells empty whatever the aspect). The one home of the grid:
/// random_gas, sphere_gas, gas_of_radii (rev.hpp) and gas_layers_fault.
struct GasGrid {
  int across = 1;
  int layers = 1;
};
GasGrid gas_grid(int dimension, int count, double aspect);
/// Why a random gas of `count` particles at `aspect` never becomes a sample
/// (packing.cpp: fewer than 2 layers along a side, in 3D fewer than 3
/// spheres across, measured): `key` is the one to change, "count" (no
/// aspect works) or "aspect", and `message` says the rule and the bounds.
/// The one home of the rule: the config's assembly.count and
/// assembly.aspect, and every command that generates a gas at another
/// count (scaling's --sizes, rev's --particles, a generated prototype).
/// `count_changed` (the count was given apart from the aspect: a --set of
/// it alone, or a command's count): where some count would consolidate at
/// this aspect, `key` is "count" and the message gives the nearest such
/// counts below and above, and still the aspect's bounds, the aspect named
/// `aspect_name`. `too_few`: no aspect works (`key` "count").
struct GasLayersFault {
  std::string key;
  std::string message;
  bool too_few = false;
};
std::optional<GasLayersFault> gas_layers_fault(int dimension, int count, double aspect,
                                               bool count_changed = false,
                                               const std::string& aspect_name = "aspect");
/// The same as one phrase for a command's error at a count it was given
/// ("" when the gas can consolidate; count_changed): the message, after
/// "the count" when it names the count, or after `aspect_name`
/// ("assembly.aspect") when no count works and it names the aspect.
std::string gas_layers_problem(int dimension, int count, double aspect,
                               const std::string& aspect_name);
/// A loose random gas of polydisperse disks (no overlaps) on a jittered
/// grid (gas_grid); consolidation makes it dense (frictionless compression,
/// then friction on). Deterministic for a seed on every platform.
Assembly random_gas(const AssemblySpec& spec);
/// The comment line that gives a particle file's walls:
/// "# walls left right bottom top: L R B T" (written by particle_csv).
inline constexpr const char kParticleFileWalls[] = "# walls left right bottom top:";
/// CSV x,y,r (header optional, '#' comments); walls at the bounding box, or
/// where a kParticleFileWalls line puts them (none pressing more than 5 %
/// of the smallest radius into the particles' extent, like an overlap).
/// Errors name the file and the line.
Assembly read_particle_file(const std::string& path);
/// The same from a stream; `source` names it in errors.
Assembly read_particles(std::istream& in, const std::string& source);
/// A particle file opened for the 2D and the sphere readers (binary: they
/// drop a CR themselves). A folder, a device, a symlink loop or a file that
/// cannot be opened is one InputError naming it (exit 2).
std::ifstream open_particle_file(const std::string& path);
/// A particle-file line made ready to split, for the 2D and the sphere
/// readers: the UTF-8 BOM of line 1 and a trailing CR dropped. A NUL byte
/// (strtod would stop at it and take "1.5\0garbage" for 1.5) is an
/// InputError naming `path` and the line.
void prepare_particle_line(std::string& line, int line_no, const std::string& path);
/// The distance between the centres of particles i and j of a packing held
/// as coordinate arrays (x, y[, z]): std::hypot for disks, the root of the
/// sum of squares for spheres. The particle files' overlap check and the
/// REV's contact count measure pairs by it.
template <size_t D>
double centre_distance(const std::array<std::span<const double>, D>& x, int i, int j) {
  if constexpr (D == 2) {
    return std::hypot(x[0][j] - x[0][i], x[1][j] - x[1][i]);
  } else {
    double d2 = 0.0;
    for (size_t d = 0; d < D; ++d) d2 += (x[d][j] - x[d][i]) * (x[d][j] - x[d][i]);
    return std::sqrt(d2);
  }
}

/// One content line of a particle file (neither blank nor a comment), for
/// the 2D and the sphere readers: v.size() comma-separated decimal numbers
/// (no hexadecimal, no trailing comma: an InputError naming the line and
/// the column), the position then the radius (x,y,r; x,y,z,r), each
/// finite, the radius > 0,
/// each |coordinate| + 4 r finite (the overlap test adds radii to
/// coordinates), and fewer than kMaxParticles particles read before it
/// (`particles_read`): true, the numbers in `v`. The first content line (`seen_content` still
/// false) whose fields are none of them numbers is the header: false; it
/// must name the columns x,y(,z),r in this order (r or radius, any case,
/// quotes allowed), else an InputError: the reader never guesses an order;
/// a trailing comma after it is one too, as after a particle (the column).
/// Anything else is an InputError naming `path` and `where` (a line with
/// some numbers is a broken particle line, never silently skipped).
bool parse_particle_fields(const std::string& line, std::span<double> v, bool& seen_content,
                           int64_t particles_read, const std::string& path,
                           const std::string& where);
/// Build the assembly a config asks for. `which` names it in the errors
/// about its own positions ("the prototype": a check of the scene also
/// builds the prototype's, a bound for one is not the other's).
Assembly make_assembly(const SceneConfig& config, const std::string& which = "the scene");
/// Refuse (InputError) a sigma3 whose contact overlap, 2*sigma3*t*r_min/kn,
/// the positions of `a` cannot resolve: their round-off, u*max|coordinate|,
/// must stay below a tenth of consolidation_tolerance of it. make_assembly
/// checks its own; a prototype read from a particle `file` (named in the
/// message, with the distance from the origin its positions must keep) is
/// checked by the commands that consolidate it. The error names the field a
/// --set changed (detail::overlap_culprit) with its bound; `which` names the
/// assembly ("the scene", "the prototype"). `tiling` ("2x2": verify --tile)
/// says that `a` is the file's packing mirror-tiled, its positions not the
/// file's.
void check_resolvable(const SceneConfig& config, const Assembly& a, const std::string& which,
                      const std::string& file = "", const std::string& tiling = "");
/// The checks make_assembly gives the assembly it builds, before it is
/// consolidated: the scales its radii derive (masses, inertias, steps,
/// damping: finite, normal doubles; a particle file's radius of 1e-150 m
/// or 1e150 m makes them 0 or inf, and the consolidation "diverged:
/// non-finite state") and check_resolvable. For an assembly read or cut
/// from a particle `file` (a prototype, a REV cut from one, a scaling
/// study's REVs) the errors name the file (a radius as its column r);
/// `tiling` as check_resolvable's.
void check_assembly(const SceneConfig& config, const Assembly& a, const std::string& which,
                    const std::string& file = "", const std::string& tiling = "");

/// The first half of check_assembly (and of check_sphere_assembly, with the
/// config's dimension): the scales that `radii`, read from the particle
/// `file`, derive under the config — masses, inertias, steps, dashpots —
/// must be finite, normal doubles; else an InputError naming the file's
/// column r. For a prototype file whatever is done with it: even a command
/// that never runs it derives its Δt and damping from these radii.
void check_particle_file_scales(const SceneConfig& config, std::span<const double> radii,
                                const std::string& file);

/// σ1/σ3 at sliding failure of a periodic hexagonal packing (horizontal
/// rows) with interparticle friction μ: tan 60°·tan(60° + φ_μ), tan φ_μ = μ.
/// Infinite (no sliding failure) when μ ≥ 1/√3.
double hexagonal_peak_ratio(double friction);
/// The same for the walled columns × rows sample (see the derivation in
/// packing.cpp): the box is wider and higher than the periodic cell that
/// carries the same contact forces.
double hexagonal_peak_ratio_walled(double friction, int columns, int rows);

}  // namespace demcal
