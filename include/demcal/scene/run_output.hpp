// The files of one run a user opens elsewhere: series.csv (a spreadsheet,
// gnuplot) and final.vtk (ParaView).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "demcal/kernel/sphere_world.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/triaxial.hpp"

namespace demcal {

/// What a monitoring series says of its run ahead of its columns, the
/// facts `demcal score` reads (scoring/external_series.hpp) to score it as
/// `demcal run` scores its own: the one home of the keys and of the line
/// format, "# key = value". demcal's own series.csv (series_metadata()) and
/// the LAMMPS and LIGGGHTS decks' (upscaling, print lines) are written from
/// here. Values are text: a number as its writer formats it, or an
/// engine's variable (${sigma3}); an empty optional is left out.
struct SeriesMetadata {
  std::string writer;  ///< who wrote the series, e.g. "LAMMPS deck"
  std::string scene;   ///< the scene's name
  int particles = 0;
  std::string lateral_stress;  ///< σ3 [Pa]
  std::string steps;           ///< Nstep, the steps planned
  std::string dt;              ///< [s]
  std::optional<std::string> dt_crit;
  std::string damping_ratio_translation, damping_ratio_rotation;  ///< as applied
  std::optional<std::string> mass_scaling;
  /// Where the engine applies a contact's tangential force: "radius"
  /// (LAMMPS), "radius - overlap/2" (demcal, LIGGGHTS).
  std::string moment_lever_arm;
  /// 2D, demcal only: the peak tracked at every step (LoadingResult's
  /// peak_stress_yy [Pa] and peak_strain_yy), which the monitoring points
  /// can miss.
  std::optional<std::string> peak_stress_yy, peak_strain_yy;
  /// 3D, demcal only: the same for σ_zz (TriaxialResult's peak_stress_zz
  /// and peak_strain_zz).
  std::optional<std::string> peak_stress_zz, peak_strain_zz;
  /// The reference peak [Pa] the run's peak error was taken against.
  std::optional<std::string> reference_peak;
  /// A diverged run (demcal's divergence checks; an engine's run that blew
  /// up writes non-finite values instead): the step and the reason
  /// (to_string(Divergence)).
  std::optional<std::string> divergence_step, divergence;
};

/// The metadata's lines, each "# key = value" without the line end, after
/// a first line "# demcal.series/1: WRITER written by demcal VERSION,
/// scene SCENE"; they end with series_result_lines(m).
std::vector<std::string> series_metadata_lines(const SeriesMetadata& m);
/// The lines of what the run found (its tracked peak, the reference peak,
/// its divergence), in series_metadata_lines' form and order: the end of
/// that list, and what an engine's deck appends to its series once its run
/// is over (a reader takes "# key = value" lines anywhere in the file).
std::vector<std::string> series_result_lines(const SeriesMetadata& m);
/// The keys of series_result_lines(), in its order: the only metadata a
/// series may give after its column header (`demcal score`).
inline constexpr std::array<const char*, 7> kSeriesResultKeys = {
    "peak_stress_yy", "peak_strain_yy",  "peak_stress_zz", "peak_strain_zz",
    "reference_peak", "divergence_step", "divergence"};

/// The metadata of a run of demcal (2D, 3D): every value written to
/// round-trip the double (the scores of `demcal score` and `demcal run`
/// then agree), σ3 from `test`, the writer "demcal run"; the peak tracked
/// at every step, and the reference peak the run was scored against, if
/// any.
SeriesMetadata series_metadata(const std::string& scene, const TestSpec& test,
                               const LoadingResult& run,
                               std::optional<double> reference_peak = std::nullopt);
SeriesMetadata series_metadata(const std::string& scene, const TestSpec& test,
                               const TriaxialResult& run,
                               std::optional<double> reference_peak = std::nullopt);

/// series.csv with its metadata: the lines of series_metadata_lines(), then
/// series_csv(series).
std::string series_csv(const SeriesMetadata& metadata, const std::vector<MonitorPoint>& series);
std::string series_csv(const SeriesMetadata& metadata, const std::vector<TriaxialPoint>& series);

/// series.csv: step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy,
/// kinetic_energy,unbalanced_force_ratio,lateral_stress_error, then extras.
std::string series_csv(const std::vector<MonitorPoint>& series);
/// Legacy VTK polydata that ParaView opens: particles as vertices (radius,
/// velocity, rotation, angular velocity) and the contact force network as
/// lines (normal and tangential force).
std::string world_vtk(const World& world, const std::string& title);

/// series.csv of a triaxial run (z the axial axis): step,strain_zz, the
/// nine components of b row by row (b_xx,b_xy,b_xz,b_yx,...,b_zz), the nine
/// of σ (s_xx,...,s_zz; s_ij = σ_ij), kinetic_energy,
/// unbalanced_force_ratio, lateral_stress_error (mean of the four lateral
/// walls), kinetic_energy_rotation, elastic_energy, inertial_number,
/// coordination_number, servo_error_xmin,servo_error_xmax,servo_error_ymin,
/// servo_error_ymax ((p − σ3)/σ3 of each lateral wall), then the six wall
/// positions wall_xmin,wall_xmax,wall_ymin,wall_ymax,wall_zmin,wall_zmax, then
/// damping_power_translation, damping_power_rotation and axial_power [W]
/// (the drag criteria of triaxial_scoring.hpp).
std::string series_csv(const std::vector<TriaxialPoint>& series);
/// Legacy VTK polydata of a sphere world: the spheres as vertices with
/// point data radius, diameter, velocity and angular_velocity (vectors), and
/// the contact network as lines with cell data normal_force and
/// tangential_force (magnitude; 0 on the vertex cells). In ParaView: Glyph,
/// type Sphere, Scale Array "diameter", Scale Factor 1 (the Sphere glyph has
/// radius 0.5), or "radius" with factor 2.
std::string world_vtk(const SphereWorld& world, const std::string& title);

}  // namespace demcal
