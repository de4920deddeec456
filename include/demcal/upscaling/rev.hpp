// The representative elementary volume (REV): a small sample of the user's
// prototype that the calibration runs on (issue #6 §1): as small as still
// representative, so that every trial of the search is cheap.
//
// Two ways to get one from a prototype assembly (a particle file):
//   cut      — a rectangular window around the prototype's centre holding
//              about the requested number of particle centres; walls are
//              placed at the bounding box of the disks kept, and the REV is
//              re-consolidated to σ3 (biaxial.hpp) before it is used;
//   generate — the same radius distribution (radii drawn from the
//              prototype's), placed as a loose gas and consolidated to σ3.
// Either way, how representative the REV is gets measured against the
// prototype: radius distribution (moments, quantiles, two-sample
// Kolmogorov–Smirnov distance), porosity and coordination number, each for
// the whole box and for the interior away from the walls.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"

namespace demcal {

/// Geometry of a packing of disks (2D) or spheres (3D, rev_3d.hpp).
/// Contacts are geometric: centre distance below (r_i + r_j)·(1 +
/// contact_tolerance), so a file and a simulated state are judged alike.
struct PackingStats {
  int dimension = 2;
  int particles = 0;
  double radius_mean = 0.0, radius_std = 0.0, radius_min = 0.0, radius_max = 0.0;
  double radius_d10 = 0.0, radius_d50 = 0.0, radius_d90 = 0.0;  ///< number quantiles
  /// Box edges: width along x; height along the loading axis (y in 2D, z in
  /// 3D); depth along y in 3D (0 in 2D).
  double width = 0.0, height = 0.0, depth = 0.0;
  /// 1 − (disk area inside the box)/(box area), in 3D 1 − (sphere volume
  /// inside the box)/(box volume): what a user measures.
  double porosity = 0.0;
  /// The same in the box inset by 2·r_max on every side, away from the wall
  /// voids (the particles are clipped to that window: disks exactly,
  /// spheres by sphere_box_volume).
  double porosity_interior = 0.0;
  /// Mean contacts per particle (particle–particle contacts only), over all
  /// particles and over those centred in the inset window.
  double coordination = 0.0;
  double coordination_interior = 0.0;
  int interior_particles = 0;
};
inline constexpr double kContactTolerance = 1e-4;
/// Stats of an assembly inside its box (left/right/bottom/top).
PackingStats packing_stats(const Assembly& assembly, double contact_tolerance = kContactTolerance);
/// Stats of a world state (its walls are the box).
PackingStats packing_stats(const World& world, double contact_tolerance = kContactTolerance);

/// Area of the disk (cx, cy, r) inside the rectangle [x0,x1]×[y0,y1].
double disk_rectangle_area(double cx, double cy, double r, double x0, double x1, double y0,
                           double y1);
/// Two-sample Kolmogorov–Smirnov statistic sup|F_a − F_b|.
double ks_distance(std::vector<double> a, std::vector<double> b);

/// How a REV compares with its prototype, 2D or 3D alike, with the
/// thresholds used for the verdict (chosen, not derived: see rev.cpp).
struct Representativeness {
  PackingStats rev, prototype;
  double ks = 0.0;                       ///< radius distributions, KS distance
  double ks_critical = 0.0;              ///< 5 % level of the two-sample KS test
  double porosity_difference = 0.0;      ///< interior, REV − prototype
  double coordination_difference = 0.0;  ///< interior, REV − prototype
  double radius_mean_difference = 0.0;   ///< relative
  bool size_distribution_ok = false, porosity_ok = false, coordination_ok = false;
  bool representative = false;
  std::string verdict;  ///< one paragraph for a user
};
/// Thresholds: |Δporosity| ≤ 0.02 (interior), |ΔZ| ≤ 0.25·Z_prototype... see rev.cpp.
Representativeness compare(const PackingStats& rev, const PackingStats& prototype,
                           std::span<const double> rev_radii, std::span<const double> proto_radii);
nlohmann::json to_json(const PackingStats& stats);
nlohmann::json to_json(const Representativeness& r);

/// `count` radii drawn with replacement from `radii` (deterministic for a seed).
std::vector<double> resample_radii(std::span<const double> radii, int64_t count, uint64_t seed);
/// A loose gas of the given disks on a jittered grid (gas_grid, no
/// overlaps), box width/height ≈ `aspect`; consolidation makes it dense.
Assembly gas_of_radii(std::vector<double> radii, double aspect, uint64_t seed);

/// The window cut: the particles whose centres lie in the axis-aligned
/// window centred on the prototype's box centre with the prototype's aspect
/// ratio (or `aspect` when > 0), sized so that it holds the particle count
/// closest to `count`; walls at the bounding box of the disks kept.
/// Throws InputError when the prototype has fewer than `count` particles.
Assembly cut_rev(const Assembly& prototype, int64_t count, double aspect = 0.0);
/// The aspect (width/height) of the gas generate_rev makes from
/// `prototype`: its box's (1 for an empty box).
double rev_gas_aspect(const Assembly& prototype);
/// Radii drawn from the prototype's, as a loose gas at rev_gas_aspect
/// (consolidate it).
Assembly generate_rev(const Assembly& prototype, int64_t count, uint64_t seed = 1);

struct RevOptions {
  int64_t particles = 400;
  std::string method = "cut";  ///< cut | generate
  double aspect = 0.0;         ///< 0: the prototype's
  uint64_t seed = 1;
};
struct RevResult {
  std::string method;
  Assembly assembly;  ///< consolidated positions, walls where consolidation left them
  ConsolidatedState state;
  Representativeness representativeness;
};
/// Cut or generate, consolidate to σ3 with the config's material and test,
/// and compare with the prototype.
RevResult make_rev(const SceneConfig& config, const Assembly& prototype, const RevOptions& options);
/// The same with the consolidation `consolidated(raw)` in place of
/// consolidate(config, raw) (it must give that state: `demcal rev`'s says
/// "consolidating ..." only when it consolidates, not before a cache read).
RevResult make_rev(const Assembly& prototype, const RevOptions& options,
                   const std::function<ConsolidatedState(const Assembly&)>& consolidated);
/// The REV make_rev() consolidates, as it makes it: cut_rev or
/// generate_rev by options.method (another method: InputError).
Assembly unconsolidated_rev(const Assembly& prototype, const RevOptions& options);
/// make_rev() on `raw`, the REV unconsolidated_rev(prototype, options) made
/// (made once, e.g. to be checked before any work): consolidated and
/// compared with the prototype.
RevResult make_rev(const Assembly& prototype, const RevOptions& options, const Assembly& raw,
                   const std::function<ConsolidatedState(const Assembly&)>& consolidated);

/// `nx`×`ny` copies of a packing, every other copy mirrored, so that the
/// disks along a seam meet their own mirror images (a seam is in contact,
/// not a gap). Builds a large test prototype from a smaller consolidated
/// one: a large loose gas consolidates far more slowly.
Assembly tile_mirrored(const Assembly& assembly, int nx, int ny);

/// A world state as an assembly (positions, radii, walls).
Assembly assembly_of(const World& world);
/// CSV x,y,r with a header, full precision (read_particle_file reads it).
std::string particle_csv(const Assembly& assembly);

}  // namespace demcal
