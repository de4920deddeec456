// The files of one run a user opens elsewhere: series.csv (a spreadsheet,
// gnuplot) and final.vtk (ParaView).
#pragma once

#include <string>
#include <vector>

#include "demcal/kernel/world.hpp"
#include "demcal/scene/biaxial.hpp"

namespace demcal {

/// series.csv: step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy,
/// kinetic_energy,unbalanced_force_ratio,lateral_stress_error, then extras.
std::string series_csv(const std::vector<MonitorPoint>& series);
/// Legacy VTK polydata that ParaView opens: particles as vertices (radius,
/// velocity, rotation, angular velocity) and the contact force network as
/// lines (normal and tangential force).
std::string world_vtk(const World& world, const std::string& title);

}  // namespace demcal
