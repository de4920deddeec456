// Stress and equilibrium measures (README.md "Physics in one paragraph"), tension positive:
//   b_ij = (1/V) Σ_{wall contacts} x^c_i f^c_j      (origin at the box centre)
//   σ_ij = (1/V) Σ_p Σ_{c∈p} (x^c − x^p)_i f^c_j   (wall contacts included)
// For a particle pair the two particles' terms add up to (x^j − x^i) ⊗ f_i,
// independent of where the contact point sits; f_i is the force on i.
// Pair normals and normal forces are not stored by the force pass; they are
// re-evaluated here from the positions by the contact law's own formulas
// (WorldImpl::pair_state), the tangential forces read from the list.
#include <cmath>
#include <numbers>

#include "contact_law.hpp"
#include "measure_formulas.hpp"
#include "world_impl.hpp"

namespace demcal {

Eigen::Vector2d WorldImpl::centre() const {
  return {0.5 * (walls_[kLeft].position + walls_[kRight].position),
          0.5 * (walls_[kBottom].position + walls_[kTop].position)};
}

Measures WorldImpl::measure(double strain_rate) const {
  Measures out;
  const int n = size();
  const double volume = this->volume();
  out.volume = volume;
  const Eigen::Vector2d c = centre();
  Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d b = Eigen::Matrix2d::Zero();
  double sum_contact_force = 0.0;
  int contact_count = 0;
  double elastic = 0.0;
  const double kn = material_.particle.kn, kt = material_.particle.kt;

  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const int i = pair_i_[k], j = pair_j_[k];
    const double ft = slot_ft_[pair_slot_[k]];
    const PairState p = pair_state(i, j);
    const double fn = p.fn;
    // The springs' energy, by the contact law: the elastic part of the
    // normal force (with a dashpot, fn is not kn·δ).
    elastic += law::spring_energy(p.fn_elastic, kn) + law::spring_energy(ft, kt);
    if (fn <= 0.0 && ft == 0.0) continue;
    const double nx = p.nx, ny = p.ny;
    const Eigen::Vector2d f(-fn * nx - ft * ny, -fn * ny + ft * nx);  // on i
    const Eigen::Vector2d branch(x_[j] - x_[i], y_[j] - y_[i]);
    sigma += branch * f.transpose();
    sum_contact_force += f.norm();
    ++contact_count;
    ++out.particle_contacts;
  }

  // Wall contacts, re-evaluated from the stored history (the force on each
  // particle exactly as the last compute_forces() applied it).
  const double kw = material_.wall.kn, ktw = material_.wall.kt;
  for (int s = 0; s < 4; ++s) {
    const double gnx = law::kWallNormal[s][0], gny = law::kWallNormal[s][1];
    const bool vertical = (s == kLeft || s == kRight);
    for (int i : wall_candidates_[s]) {
      const double dist =
          vertical ? (x_[i] - walls_[s].position) * gnx : (y_[i] - walls_[s].position) * gny;
      const double fn = wall_fn_[s][i];
      const double ft = wall_ft_[s][i];
      const double overlap = r_[i] - dist;
      if (overlap > 0.0)
        elastic += law::spring_energy(law::elastic_normal_force(kw, overlap), kw) +
                   law::spring_energy(ft, ktw);
      if (fn <= 0.0 && ft == 0.0) continue;
      const Eigen::Vector2d f(fn * gnx - ft * gny, fn * gny + ft * gnx);
      const Eigen::Vector2d xc(x_[i] - dist * gnx, y_[i] - dist * gny);
      const Eigen::Vector2d arm = xc - Eigen::Vector2d(x_[i], y_[i]);
      sigma += arm * f.transpose();
      b += (xc - c) * f.transpose();
      sum_contact_force += f.norm();
      ++contact_count;
      ++out.wall_contacts;
    }
  }
  out.homogenized_stress = sigma / volume;
  out.boundary_stress = b / volume;
  out.elastic_energy = elastic;

  double ke_t = 0.0, ke_r = 0.0, sum_net = 0.0, sum_d = 0.0;
  for (int i = 0; i < n; ++i) {
    ke_t += 0.5 * m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i]);
    ke_r += 0.5 * inertia_[i] * omega_[i] * omega_[i];
    sum_net += std::hypot(fx_[i], fy_[i]);
    sum_d += 2.0 * r_[i];
  }
  out.kinetic_energy_translation = ke_t;
  out.kinetic_energy_rotation = ke_r;
  out.unbalanced_force_ratio =
      detail::unbalanced_force_ratio(sum_net, n, sum_contact_force, contact_count);
  out.mean_pressure = -0.5 * out.homogenized_stress.trace();
  out.coordination_number = detail::coordination_number(out.particle_contacts, n);
  out.inertial_number = detail::inertial_number(
      strain_rate, sum_d, n, material_.density * integration_.mass_scaling, out.mean_pressure);
  return out;
}

Eigen::Matrix2d WorldImpl::net_force_moment() const {
  const Eigen::Vector2d c = centre();
  Eigen::Matrix2d m = Eigen::Matrix2d::Zero();
  for (int i = 0; i < size(); ++i)
    m +=
        Eigen::Vector2d(x_[i] - c.x(), y_[i] - c.y()) * Eigen::Vector2d(fx_[i], fy_[i]).transpose();
  return m / volume();
}

std::vector<World::ContactView> WorldImpl::contacts() const {
  std::vector<World::ContactView> out;
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const int i = pair_i_[k], j = pair_j_[k];
    const double ft = slot_ft_[pair_slot_[k]];
    const PairState p = pair_state(i, j);
    if (p.fn <= 0.0 && ft == 0.0) continue;
    out.push_back({i, j, p.nx, p.ny, p.fn, ft, p.overlap});
  }
  return out;
}

}  // namespace demcal
