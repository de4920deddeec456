#include "demcal/scene/run_output.hpp"

#include <iomanip>
#include <sstream>

namespace demcal {

std::string series_csv(const std::vector<MonitorPoint>& series) {
  std::ostringstream s;
  s << std::setprecision(10);
  s << "step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy,kinetic_energy,"
       "unbalanced_force_ratio,lateral_stress_error,kinetic_energy_rotation,elastic_energy,"
       "inertial_number,coordination_number,wall_left,wall_right,wall_bottom,wall_top\n";
  for (const auto& p : series) {
    s << p.step << ',' << p.strain_yy << ',' << p.b(0, 0) << ',' << p.b(0, 1) << ',' << p.b(1, 0)
      << ',' << p.b(1, 1) << ',' << p.sigma(0, 0) << ',' << p.sigma(0, 1) << ',' << p.sigma(1, 0)
      << ',' << p.sigma(1, 1) << ',' << p.kinetic_energy << ',' << p.unbalanced_force_ratio << ','
      << p.lateral_stress_error << ',' << p.kinetic_energy_rotation << ',' << p.elastic_energy
      << ',' << p.inertial_number << ',' << p.coordination_number << ',' << p.left << ',' << p.right
      << ',' << p.bottom << ',' << p.top << '\n';
  }
  return s.str();
}

std::string world_vtk(const World& world, const std::string& title) {
  const int n = world.size();
  const auto contacts = world.contacts();
  const size_t nc = contacts.size();
  std::ostringstream s;
  s << std::setprecision(10);
  s << "# vtk DataFile Version 3.0\n" << title << "\nASCII\nDATASET POLYDATA\n";
  s << "POINTS " << n << " double\n";
  for (int i = 0; i < n; ++i) s << world.x()[i] << ' ' << world.y()[i] << " 0\n";
  s << "VERTICES " << n << ' ' << 2 * n << '\n';
  for (int i = 0; i < n; ++i) s << "1 " << i << '\n';
  s << "LINES " << nc << ' ' << 3 * nc << '\n';
  for (const auto& c : contacts) s << "2 " << c.i << ' ' << c.j << '\n';
  s << "POINT_DATA " << n << '\n';
  s << "SCALARS radius double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << world.radius()[i] << '\n';
  s << "SCALARS rotation double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << world.rotation()[i] << '\n';
  s << "SCALARS angular_velocity double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << world.omega()[i] << '\n';
  s << "VECTORS velocity double\n";
  for (int i = 0; i < n; ++i) s << world.vx()[i] << ' ' << world.vy()[i] << " 0\n";
  s << "CELL_DATA " << n + nc << '\n';
  s << "SCALARS normal_force double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << "0\n";
  for (const auto& c : contacts) s << c.fn << '\n';
  s << "SCALARS tangential_force double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << "0\n";
  for (const auto& c : contacts) s << c.ft << '\n';
  return s.str();
}

std::string series_csv(const std::vector<TriaxialPoint>& series) {
  static const char* kAxis = "xyz";
  std::ostringstream s;
  s << std::setprecision(10);
  s << "step,strain_zz";
  for (const char* t : {"b_", "s_"})
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s << ',' << t << kAxis[i] << kAxis[j];
  s << ",kinetic_energy,unbalanced_force_ratio,lateral_stress_error,kinetic_energy_rotation,"
       "elastic_energy,inertial_number,coordination_number,servo_error_xmin,servo_error_xmax,"
       "servo_error_ymin,servo_error_ymax,wall_xmin,wall_xmax,wall_ymin,wall_ymax,wall_zmin,"
       "wall_zmax\n";
  for (const auto& p : series) {
    s << p.step << ',' << p.strain_zz;
    for (const Eigen::Matrix3d* m : {&p.b, &p.sigma})
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s << ',' << (*m)(i, j);
    s << ',' << p.kinetic_energy << ',' << p.unbalanced_force_ratio << ',' << p.lateral_stress_error
      << ',' << p.kinetic_energy_rotation << ',' << p.elastic_energy << ',' << p.inertial_number
      << ',' << p.coordination_number;
    for (double e : p.servo_error) s << ',' << e;
    for (double w : p.walls) s << ',' << w;
    s << '\n';
  }
  return s.str();
}

std::string world_vtk(const SphereWorld& world, const std::string& title) {
  const int n = world.size();
  const auto contacts = world.contacts();
  const size_t nc = contacts.size();
  std::ostringstream s;
  s << std::setprecision(10);
  s << "# vtk DataFile Version 3.0\n" << title << "\nASCII\nDATASET POLYDATA\n";
  s << "POINTS " << n << " double\n";
  for (int i = 0; i < n; ++i)
    s << world.x()[i] << ' ' << world.y()[i] << ' ' << world.z()[i] << '\n';
  s << "VERTICES " << n << ' ' << 2 * n << '\n';
  for (int i = 0; i < n; ++i) s << "1 " << i << '\n';
  s << "LINES " << nc << ' ' << 3 * nc << '\n';
  for (const auto& c : contacts) s << "2 " << c.i << ' ' << c.j << '\n';
  s << "POINT_DATA " << n << '\n';
  s << "SCALARS radius double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << world.radius()[i] << '\n';
  s << "SCALARS diameter double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << 2.0 * world.radius()[i] << '\n';
  s << "VECTORS velocity double\n";
  for (int i = 0; i < n; ++i)
    s << world.vx()[i] << ' ' << world.vy()[i] << ' ' << world.vz()[i] << '\n';
  s << "VECTORS angular_velocity double\n";
  for (int i = 0; i < n; ++i)
    s << world.omega_x()[i] << ' ' << world.omega_y()[i] << ' ' << world.omega_z()[i] << '\n';
  s << "CELL_DATA " << n + nc << '\n';
  s << "SCALARS normal_force double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << "0\n";
  for (const auto& c : contacts) s << c.fn << '\n';
  s << "SCALARS tangential_force double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << "0\n";
  for (const auto& c : contacts) s << c.tangential.norm() << '\n';
  return s.str();
}

}  // namespace demcal
