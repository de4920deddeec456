#include "demcal/output.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace demcal {

void write_file_atomic(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot write (cannot create temporary file)");
    out << content;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename temporary file into place");
  }
}

void append_line_durable(const std::string& path, const std::string& line) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw std::runtime_error(path + ": cannot open for appending");
  const std::string data = line + "\n";
  const ssize_t written = ::write(fd, data.data(), data.size());
  const bool ok = written == static_cast<ssize_t>(data.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw std::runtime_error(path + ": append failed");
}

void make_output_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  // The folder is the user's -o: failing to make it is bad input (exit 2).
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(
        dir, "", "cannot create output folder" + (ec ? " (" + ec.message() + ")" : std::string()));
}

void remove_stale_temporaries(const std::string& dir) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const auto at = name.rfind(".tmp.");
    if (at == std::string::npos || at + 5 >= name.size()) continue;
    const std::string pid_text = name.substr(at + 5);
    if (pid_text.find_first_not_of("0123456789") != std::string::npos || pid_text.size() > 9)
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(pid_text));
    // Alive (or not ours to signal): leave it.
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno == EPERM) continue;
    std::filesystem::remove(entry.path(), ec);
  }
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

}  // namespace demcal
