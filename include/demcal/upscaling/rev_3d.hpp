// The REV in 3D (issue #18): a box window cut from a prototype of spheres
// (or its radii resampled into a gas), re-consolidated to isotropic σ3 by the
// triaxial consolidation (triaxial.hpp), and compared with the prototype by
// the 2D measures and verdict (rev.hpp: packing_stats, compare, to_json):
// radius distribution (two-sample KS), porosity and coordination number,
// for the whole box and for the interior 2·r_max away from the walls.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "demcal/scene/config.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/upscaling.hpp"

namespace demcal {

/// Volume of the sphere (cx, cy, cz, r) inside the box [lo, hi]. Numerical,
/// to about 1e-11 of the sphere's volume: the cross-section at height z is a
/// disk whose area inside the rectangle is exact (disk_rectangle_area);
/// it is integrated over z = cz + r·sin θ by Gauss–Legendre on the pieces
/// between every kink (where the cross-section's radius reaches a side's or
/// a corner's distance), each piece mapped by a smoothstep so that the
/// (θ − θ_k)^{3/2} of a circle leaving a side is smooth at the nodes.
/// Tested against the full sphere, the cap, the slab, the half, quarter and
/// eighth (to 1e-12), and for additivity under splitting a box (worst
/// 6e-12 over 2000 random boxes; tests/test_rev_3d.cpp).
double sphere_box_volume(double cx, double cy, double cz, double r, const std::array<double, 3>& lo,
                         const std::array<double, 3>& hi);

/// Stats of spheres in their box (lo/hi): PackingStats with dimension 3,
/// volumes for areas, the same contact rule and interior window.
PackingStats packing_stats(const SphereAssembly& assembly,
                           double contact_tolerance = kContactTolerance);
/// Stats of a sphere world state (its six walls are the box).
PackingStats packing_stats(const SphereWorld& world, double contact_tolerance = kContactTolerance);

/// The box cut: the spheres whose centres lie in the axis-aligned box
/// centred on the prototype's box centre with the prototype's proportions
/// (or, with `aspect` > 0, width = depth = aspect·height), sized so that it
/// holds the sphere count closest to `count`; walls at the bounding box of
/// the spheres kept. Throws InputError when the prototype has fewer than
/// `count` spheres.
SphereAssembly cut_rev(const SphereAssembly& prototype, int64_t count, double aspect = 0.0);
/// The aspect of the gas generate_rev makes from `prototype`: its box's
/// sqrt(width·depth)/height (1 for a flat box).
double rev_gas_aspect(const SphereAssembly& prototype);
/// Radii drawn from the prototype's (resample_radii) as a loose gas at
/// rev_gas_aspect (sphere_gas, the random_sphere_gas placement);
/// consolidate it.
SphereAssembly generate_rev(const SphereAssembly& prototype, int64_t count, uint64_t seed = 1);

struct SphereRevResult {
  std::string method;
  SphereAssembly assembly;  ///< consolidated positions, walls where consolidation left them
  TriaxialState state;
  Representativeness representativeness;
};
/// Cut or generate, consolidate to σ3 with the config's material and test
/// (consolidate_triaxial), and compare with the prototype (compare).
SphereRevResult make_rev(const SceneConfig& config, const SphereAssembly& prototype,
                         const RevOptions& options);
/// The same with the consolidation `consolidated(raw)` in place of
/// consolidate_triaxial(config, raw) (it must give that state).
SphereRevResult make_rev(const SphereAssembly& prototype, const RevOptions& options,
                         const std::function<TriaxialState(const SphereAssembly&)>& consolidated);
/// The REV make_rev() consolidates, as it makes it: cut_rev or
/// generate_rev by options.method (another method: InputError).
SphereAssembly unconsolidated_rev(const SphereAssembly& prototype, const RevOptions& options);
/// make_rev() on `raw`, the REV unconsolidated_rev(prototype, options) made
/// (made once, e.g. to be checked before any work): consolidated and
/// compared with the prototype.
SphereRevResult make_rev(const SphereAssembly& prototype, const RevOptions& options,
                         const SphereAssembly& raw,
                         const std::function<TriaxialState(const SphereAssembly&)>& consolidated);

/// A sphere world state as an assembly (positions, radii, walls).
SphereAssembly sphere_assembly_of(const SphereWorld& world);

}  // namespace demcal
