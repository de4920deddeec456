// Export in 3D (issue #18, "Export"): the triaxial test of a sphere
// assembly as an input deck for LAMMPS or LIGGGHTS, the counterpart of the
// 2D decks of export.hpp (same ExportOptions and ExportResult, same mapping
// rules, one deck per format):
//
//   lammps   — LAMMPS (checked with the Debian 12 build, 29 Sep 2021,
//              GRANULAR package): units si, dimension 3, atom_style sphere
//              (m = f_ms·ρ·(4/3)πr³, I = (2/5)m r², as the kernel), pair_style
//              gran/hooke/history kn kt γn 0 μ 0 (γn = 0 unless the material
//              asks for contact damping), fix nve/sphere, fix viscous per
//              radius class, six walls (bottom fix wall/gran zplane; the top
//              a wall/gran/region plane moving down at the loading speed; the
//              four lateral ones wall/gran/region planes moved by demcal's
//              per-step servo law, triaxial.hpp servo_velocity, kept by one
//              fix ave/time), run length Nstep. It writes the monitoring
//              series (b and σ, 3×3, from the walls' contact arrays and the
//              identity V(b − σ) = Σ x_p ⊗ F_p; energies, wall pressures and
//              positions, servo errors, contacts) and, at the end, the peak
//              axial stress and the peak σ1/σ3 over every step. With
//              consolidate_in_deck a stage 1 first consolidates the
//              prototype as generated to isotropic σ3 (all six walls
//              servoed; demcal's law, friction phases, damping and static
//              criterion; the 2D deck's stage 1 with six walls).
//   liggghts — LIGGGHTS-PUBLIC 3.8: gran model hooke/stiffness, per-type-pair
//              kn/kt/μ, the six walls STL meshes (bottom fixed, top moved
//              by move/mesh, lateral ones by fix mesh/surface/stress/servo
//              holding the force σ3·A0 with the gain of demcal's servo law);
//              thermo rows with the axial stress (mean of top and bottom, as
//              demcal's) and the mean lateral stress, every
//              `thermo_every` steps (-var thermo_every 1: every step).
//
// Both run at α·f·Δt_crit for Nstep/f steps, f = dashpot_step_factor(ζ_t)
// (their fix viscous is explicit; demcal's damping is semi-implicit), with
// Δt_crit = 2·sqrt(m_min/kn) of the lightest sphere (the one of
// integration_for in triaxial.hpp). Rotational damping: LAMMPS 29 Sep 2021
// and LIGGGHTS 3.8 have no rotational viscous fix; ζ_r is not applied (the
// LAMMPS deck carries a commented `fix viscous/sphere` line for releases
// that have it) and the header says so.
#pragma once

#include "demcal/kernel/sphere_world.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/export.hpp"

namespace demcal {

/// ExportOptions (format, deck_name, max_types, provenance, uncertified) and one 3D
/// switch.
struct Export3dOptions : ExportOptions {
  /// true: the four lateral walls are servo-controlled at σ3 (the triaxial
  /// test). false: they stay where the state has them (a plain compression
  /// between fixed walls; the kernel cross-check, tests/test_sphere_lammps.cpp).
  bool lateral_servo = true;
};

/// The 3D deck (options.format: lammps | liggghts) for loading `state` (a
/// consolidated triaxial state: its walls are the starting wall positions,
/// its particles the data file) with `params` (the prototype's: Nstep
/// upscaled) and the config's material and test (test.vertical_strain,
/// lateral_stress, servo_gain, monitor_points). Returns the deck text and
/// the files it reads, by name (data file, meshes), for the caller to write
/// next to it (the same contract as export_deck: nothing is written here);
/// dt and steps are what the deck runs (α·f·Δt_crit, Nstep/f), notes what
/// could not be mapped exactly. The LAMMPS deck's outputs:
///   - its series, deck_files(options.deck_name).series (variable `series`),
///     one row every max(1, ⌊Nstep'/M⌋) steps and at the start, the columns
///     of series_csv(TriaxialPoint) (run_output.hpp) that LAMMPS can
///     measure: step, strain_zz, b_ij, s_ij (row by row), kinetic_energy,
///     kinetic_energy_rotation, lateral_stress_error, servo_error_xmin..ymax,
///     wall_xmin..zmax, then p_xmin..p_zmax (compressive wall pressures) and
///     contacts (particle–particle);
///   - at the end, on screen and in the log, `peak_axial_stress = P` (the
///     largest (p_zmin + p_zmax)/2 over every step, compressive positive:
///     −TriaxialResult::peak_stress_zz) and `peak_ratio = R` (the largest
///     axial/mean lateral wall pressure, TriaxialResult::peak_ratio); and
///     appended to the series, the axial peak in SeriesMetadata's keys
///     (series_result_lines): `# peak_stress_zz = -P` and `# peak_strain_zz`,
///     the strain of its first step, which `demcal score` takes as it takes
///     demcal's own tracked peak.
/// Throws InputError for an unknown format, an empty state or a config that
/// is not 3D.
ExportResult export_3d_decks(const SceneConfig& config, const AlgorithmSpec& params,
                             const TriaxialState& state, const Export3dOptions& options);
/// The same from a sphere world in any state (particles and walls as they
/// are; velocities and tangential histories are not carried over).
ExportResult export_3d_decks(const SceneConfig& config, const AlgorithmSpec& params,
                             const SphereWorld& world, const Export3dOptions& options);
/// The same from an assembly (walls at its box): with
/// options.consolidate_in_deck, the prototype as generated, which the
/// LAMMPS deck's stage 1 consolidates (ExportOptions::consolidate_in_deck:
/// demcal's consolidation, consolidate_triaxial, with six servo walls).
ExportResult export_3d_decks(const SceneConfig& config, const AlgorithmSpec& params,
                             const SphereAssembly& assembly, const Export3dOptions& options);

}  // namespace demcal
