// The files of one run a user opens elsewhere: series.csv (a spreadsheet,
// gnuplot) and final.vtk (ParaView).
#pragma once

#include <string>
#include <vector>

#include "demcal/kernel/sphere_world.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/triaxial.hpp"

namespace demcal {

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
