// The scales a run derives from the material, the algorithm and the radii,
// checked before any computing (private to the scene: make_assembly and
// make_sphere_assembly call it).
#pragma once

#include <optional>
#include <span>
#include <string>

#include "demcal/scene/config.hpp"

namespace demcal::detail {

/// Every scale the kernels derive from the config and the radii: the
/// smallest and the largest particle's mass and inertia, the critical step
/// 2·sqrt(m_min/kn) against a particle and against a wall, the loading's
/// and the consolidation's step, the critical dashpots. Each must be a
/// finite, normal double (not inf, not 0, not subnormal): each value passes
/// its own range check, yet ρ = 1e308 makes the mass overflow, a radius of
/// 1e-150 the inertia underflow, and the kernel then refuses its step
/// ("dt must be finite") or its state turns non-finite after the first
/// step. Else an InputError naming the config (or the --set that gave it)
/// and the field that pushed the scale furthest in the direction it left
/// the range (exit status 2). Computed through particle_scales.hpp, the
/// formulas' one home. Radii read from a particle file other than the
/// config's assembly.file (a prototype, a REV cut from one) are named as
/// `radii_file`'s column r.
void check_derived_scales(const SceneConfig& config, std::span<const double> radii,
                          const std::string& radii_file = "");

/// The field an overlap-at-sigma3 check names (check_lateral_stress in
/// config.cpp, check_resolvable in packing.cpp, check_sphere_overlap in
/// triaxial.cpp). The overlap grows as sigma3/kn (2D: sigma3*t/kn), so
/// the physics cannot tell which is out of range (their messages give the
/// bounds): the one named is the stiffness
/// (`kn_field`, material.kn or material.wall.kn: the one the check used)
/// when a --set gave it and none gave sigma3 (the value the user just
/// changed), else in 2D material.thickness when a --set gave it and none
/// gave sigma3 or the stiffness, else, for the round-off bound
/// (check_resolvable, check_sphere_overlap's lower bound, whose input
/// consolidation_tolerance is too: `tolerance`, resolving_tolerance()),
/// test.consolidation_tolerance when a --set gave it and none gave the
/// others, else test.lateral_stress. A tolerance whose bound is none
/// (nullopt: no tolerance below 1 resolves the overlap) is never named.
std::string overlap_culprit(const SceneConfig& config, const std::string& kn_field,
                            const std::optional<double>& tolerance = std::nullopt);

/// The smallest test.consolidation_tolerance at which positions of
/// round-off `roundoff` [m] resolve the overlap `delta` [m] (the round-off
/// a tenth of the tolerance of it: 10*roundoff/delta), when that is a valid
/// tolerance (below kConsolidationToleranceBelow); else nullopt: the
/// round-off message then leaves the tolerance out.
std::optional<double> resolving_tolerance(double roundoff, double delta);

/// The softer of the particles' and the walls' normal stiffness, and its
/// field (material.kn or material.wall.kn; the particles' on a tie): the
/// largest overlap at sigma3 is on the softer contact (check_lateral_stress
/// in 2D, check_sphere_overlap in 3D).
struct NamedStiffness {
  double kn = 0.0;
  std::string field;
};
NamedStiffness softer_normal_stiffness(const Material& material);

}  // namespace demcal::detail
