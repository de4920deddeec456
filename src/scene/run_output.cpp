#include "demcal/scene/run_output.hpp"

#include <charconv>
#include <iomanip>
#include <sstream>

namespace demcal {

namespace {
/// The one format of a metadata line.
std::string metadata_line(const char* key, const std::string& value) {
  return std::string("# ") + key + " = " + value;
}
}  // namespace

std::vector<std::string> series_metadata_lines(const SeriesMetadata& m) {
  std::vector<std::string> out{"# demcal.series/1: " + m.writer + " written by demcal " +
                               DEMCAL_VERSION + ", scene " + m.scene};
  auto line = [&](const char* key, const std::string& value) {
    out.push_back(metadata_line(key, value));
  };
  auto optional = [&](const char* key, const std::optional<std::string>& value) {
    if (value) line(key, *value);
  };
  line("particles", std::to_string(m.particles));
  line("lateral_stress", m.lateral_stress);
  line("steps", m.steps);
  line("dt", m.dt);
  optional("dt_crit", m.dt_crit);
  line("damping_ratio_translation", m.damping_ratio_translation);
  line("damping_ratio_rotation", m.damping_ratio_rotation);
  optional("mass_scaling", m.mass_scaling);
  line("moment_lever_arm", m.moment_lever_arm);
  const std::vector<std::string> results = series_result_lines(m);
  out.insert(out.end(), results.begin(), results.end());
  return out;
}

std::vector<std::string> series_result_lines(const SeriesMetadata& m) {
  // The values of kSeriesResultKeys, in its order.
  const std::optional<std::string>* const values[] = {
      &m.peak_stress_yy, &m.peak_strain_yy,  &m.peak_stress_zz, &m.peak_strain_zz,
      &m.reference_peak, &m.divergence_step, &m.divergence};
  static_assert(std::size(values) == kSeriesResultKeys.size());
  std::vector<std::string> out;
  for (size_t k = 0; k < kSeriesResultKeys.size(); ++k)
    if (*values[k]) out.push_back(metadata_line(kSeriesResultKeys[k], **values[k]));
  return out;
}

namespace {

/// A double as the shortest text that reads back as the same double.
std::string round_trip(double v) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
  return std::string(buffer, end);
}

/// The metadata LoadingResult and TriaxialResult share (their fields are
/// named alike).
template <class Run>
SeriesMetadata run_metadata(const std::string& scene, const TestSpec& test, const Run& run) {
  SeriesMetadata m;
  m.writer = "demcal run";
  m.scene = scene;
  m.particles = run.particles;
  m.lateral_stress = round_trip(test.lateral_stress);
  m.steps = std::to_string(run.steps_planned);
  m.dt = round_trip(run.integration.dt);
  m.dt_crit = round_trip(run.scales.dt_crit);
  m.damping_ratio_translation = round_trip(run.integration.damping_ratio_translation);
  m.damping_ratio_rotation = round_trip(run.integration.damping_ratio_rotation);
  m.mass_scaling = round_trip(run.integration.mass_scaling);
  m.moment_lever_arm = "radius - overlap/2";
  if (run.diverged) {
    m.divergence_step = std::to_string(run.divergence_step);
    m.divergence = to_string(run.divergence);
  }
  return m;
}

std::string metadata_text(const SeriesMetadata& m) {
  std::string out;
  for (const std::string& line : series_metadata_lines(m)) out += line + "\n";
  return out;
}

}  // namespace

SeriesMetadata series_metadata(const std::string& scene, const TestSpec& test,
                               const LoadingResult& run, std::optional<double> reference_peak) {
  SeriesMetadata m = run_metadata(scene, test, run);
  m.peak_stress_yy = round_trip(run.peak_stress_yy);
  m.peak_strain_yy = round_trip(run.peak_strain_yy);
  if (reference_peak) m.reference_peak = round_trip(*reference_peak);
  return m;
}

SeriesMetadata series_metadata(const std::string& scene, const TestSpec& test,
                               const TriaxialResult& run, std::optional<double> reference_peak) {
  SeriesMetadata m = run_metadata(scene, test, run);
  if (run.peak_stress_zz < 0.0) {  // tracked (compute_triaxial_criteria takes it then)
    m.peak_stress_zz = round_trip(run.peak_stress_zz);
    m.peak_strain_zz = round_trip(run.peak_strain_zz);
  }
  if (reference_peak) m.reference_peak = round_trip(*reference_peak);
  return m;
}

std::string series_csv(const SeriesMetadata& metadata, const std::vector<MonitorPoint>& series) {
  return metadata_text(metadata) + series_csv(series);
}

std::string series_csv(const SeriesMetadata& metadata, const std::vector<TriaxialPoint>& series) {
  return metadata_text(metadata) + series_csv(series);
}

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

namespace {

// The legacy-VTK polydata both dimensions write: particles as vertices,
// contacts as lines, then per-particle and per-cell fields (a vertex cell
// per particle, then a line per contact; particles carry 0 in the contact
// fields).
template <class Contacts, class Point>
void vtk_geometry(std::ostream& s, const std::string& title, int n, const Contacts& contacts,
                  Point point) {
  const size_t nc = contacts.size();
  s << "# vtk DataFile Version 3.0\n" << title << "\nASCII\nDATASET POLYDATA\n";
  s << "POINTS " << n << " double\n";
  for (int i = 0; i < n; ++i) s << point(i) << '\n';
  s << "VERTICES " << n << ' ' << 2 * n << '\n';
  for (int i = 0; i < n; ++i) s << "1 " << i << '\n';
  s << "LINES " << nc << ' ' << 3 * nc << '\n';
  for (const auto& c : contacts) s << "2 " << c.i << ' ' << c.j << '\n';
  s << "POINT_DATA " << n << '\n';
}

template <class Value>
void vtk_point_scalar(std::ostream& s, const char* name, int n, Value value) {
  s << "SCALARS " << name << " double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << value(i) << '\n';
}

template <class Value>
void vtk_point_vector(std::ostream& s, const char* name, int n, Value value) {
  s << "VECTORS " << name << " double\n";
  for (int i = 0; i < n; ++i) s << value(i) << '\n';
}

// The contacts' normal and tangential force magnitudes as cell fields.
template <class Contacts, class Tangential>
void vtk_contact_forces(std::ostream& s, int n, const Contacts& contacts, Tangential ft) {
  s << "CELL_DATA " << n + contacts.size() << '\n';
  s << "SCALARS normal_force double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << "0\n";
  for (const auto& c : contacts) s << c.fn << '\n';
  s << "SCALARS tangential_force double 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < n; ++i) s << "0\n";
  for (const auto& c : contacts) s << ft(c) << '\n';
}

// "x y z" of a point or vector, at the stream's precision.
struct Triple {
  double x, y, z;
};
std::ostream& operator<<(std::ostream& s, const Triple& t) {
  return s << t.x << ' ' << t.y << ' ' << t.z;
}
// A 2D point or vector in 3D: z written as the integer 0, as ever (the
// files compare byte for byte).
struct Planar {
  double x, y;
};
std::ostream& operator<<(std::ostream& s, const Planar& p) {
  return s << p.x << ' ' << p.y << " 0";
}

}  // namespace

std::string world_vtk(const World& world, const std::string& title) {
  const int n = world.size();
  const auto contacts = world.contacts();
  const auto x = world.x(), y = world.y(), r = world.radius();
  const auto vx = world.vx(), vy = world.vy(), rot = world.rotation(), w = world.omega();
  std::ostringstream s;
  s << std::setprecision(10);
  vtk_geometry(s, title, n, contacts, [&](int i) { return Planar{x[i], y[i]}; });
  vtk_point_scalar(s, "radius", n, [&](int i) { return r[i]; });
  vtk_point_scalar(s, "rotation", n, [&](int i) { return rot[i]; });
  vtk_point_scalar(s, "angular_velocity", n, [&](int i) { return w[i]; });
  vtk_point_vector(s, "velocity", n, [&](int i) { return Planar{vx[i], vy[i]}; });
  vtk_contact_forces(s, n, contacts, [](const auto& c) { return c.ft; });
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
       "wall_zmax,damping_power_translation,damping_power_rotation,axial_power\n";
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
    s << ',' << p.damping_power_translation << ',' << p.damping_power_rotation << ','
      << p.axial_power << '\n';
  }
  return s.str();
}

std::string world_vtk(const SphereWorld& world, const std::string& title) {
  const int n = world.size();
  const auto contacts = world.contacts();
  const auto x = world.x(), y = world.y(), z = world.z(), r = world.radius();
  const auto vx = world.vx(), vy = world.vy(), vz = world.vz();
  const auto wx = world.omega_x(), wy = world.omega_y(), wz = world.omega_z();
  std::ostringstream s;
  s << std::setprecision(10);
  vtk_geometry(s, title, n, contacts, [&](int i) { return Triple{x[i], y[i], z[i]}; });
  vtk_point_scalar(s, "radius", n, [&](int i) { return r[i]; });
  vtk_point_scalar(s, "diameter", n, [&](int i) { return 2.0 * r[i]; });
  vtk_point_vector(s, "velocity", n, [&](int i) { return Triple{vx[i], vy[i], vz[i]}; });
  vtk_point_vector(s, "angular_velocity", n, [&](int i) { return Triple{wx[i], wy[i], wz[i]}; });
  vtk_contact_forces(s, n, contacts, [](const auto& c) { return c.tangential.norm(); });
  return s.str();
}

}  // namespace demcal
