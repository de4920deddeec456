// Stress and equilibrium measures of the sphere kernel, tension positive:
//   b_ij = (1/V) Σ_{wall contacts} x^c_i f^c_j      (origin at the box centre)
//   σ_ij = (1/V) Σ_p Σ_{c∈p} (x^c − x^p)_i f^c_j   (wall contacts included)
// f = force on the particle. For a pair the two particles' terms add up to
// (x^j − x^i) ⊗ f_i, wherever the contact point sits. Summing x^p ⊗ F_p
// over the particles (F_p = Σ_c f^c) gives the identity
//   V·(b − σ) = Σ_p x^p ⊗ F_p,
// so b = σ in equilibrium. Normal forces are re-evaluated from the positions
// by the contact law's own function (pair_geometry); the tangential forces
// are the stored histories, i.e. the forces the last evaluation applied.
#include <cmath>

#include "contact_law.hpp"
#include "measure_formulas.hpp"
#include "sphere_world_impl.hpp"

namespace demcal {

namespace {
using V3 = Eigen::Vector3d;
}

SphereMeasures SphereWorldImpl::measure(double strain_rate) const {
  SphereMeasures out;
  const double volume = this->volume();
  out.volume = volume;
  const V3 c = centre();
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero(), b = Eigen::Matrix3d::Zero();
  double sum_contact_force = 0.0, elastic = 0.0;
  int contact_count = 0;
  const double kn = material_.particle.kn, kt = material_.particle.kt;

  for (int i = 0; i < n_; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_j_[k];
      const V3 h = pair_history(k);
      const PairGeometry g = pair_geometry(i, j);
      const double fn = g.touching ? g.fn : 0.0;
      // The springs' energy: the elastic part kn·δ of the normal force, not
      // fn, which carries the dashpot's share with contact damping (and is
      // 0 on a contact opening fast whose spring is still compressed).
      const double fe = g.touching ? law::elastic_normal_force(kn, g.overlap) : 0.0;
      elastic += law::spring_energy(fe, kn) + law::spring_energy_squared(h.squaredNorm(), kt);
      if (fn <= 0.0 && h.squaredNorm() == 0.0) continue;
      const V3 f = -fn * g.n + h;  // on i
      const V3 branch(x_[j] - x_[i], y_[j] - y_[i], z_[j] - z_[i]);
      sigma += branch * f.transpose();
      sum_contact_force += f.norm();
      ++contact_count;
      ++out.particle_contacts;
    }

  const double kw = material_.wall.kn, ktw = material_.wall.kt;
  for (int s = 0; s < 6; ++s) {
    V3 g = V3::Zero();
    g[s / 2] = (s % 2 == 0) ? 1.0 : -1.0;
    for (size_t k = 0; k < wall_candidates_[s].size(); ++k) {
      const int i = wall_candidates_[s][k];
      const double fn = wall_fn_[s][k];
      const V3 h(wall_hx_[s][k], wall_hy_[s][k], wall_hz_[s][k]);
      const double overlap = r_[i] - wall_distance(s, i);
      const double fe = overlap > 0.0 ? law::elastic_normal_force(kw, overlap) : 0.0;
      elastic += law::spring_energy(fe, kw) + law::spring_energy_squared(h.squaredNorm(), ktw);
      if (fn <= 0.0 && h.squaredNorm() == 0.0) continue;
      const V3 f = fn * g + h;
      const V3 arm = -wall_distance(s, i) * g;
      const V3 xc = V3(x_[i], y_[i], z_[i]) + arm;
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
  for (int i = 0; i < n_; ++i) {
    ke_t += 0.5 * m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i] + vz_[i] * vz_[i]);
    ke_r += 0.5 * inertia_[i] * (wx_[i] * wx_[i] + wy_[i] * wy_[i] + wz_[i] * wz_[i]);
    sum_net += V3(fx_[i], fy_[i], fz_[i]).norm();
    sum_d += 2.0 * r_[i];
  }
  out.kinetic_energy_translation = ke_t;
  out.kinetic_energy_rotation = ke_r;
  out.unbalanced_force_ratio =
      detail::unbalanced_force_ratio(sum_net, n_, sum_contact_force, contact_count);
  out.mean_pressure = -out.homogenized_stress.trace() / 3.0;
  out.coordination_number = detail::coordination_number(out.particle_contacts, n_);
  out.inertial_number = detail::inertial_number(
      strain_rate, sum_d, n_, material_.density * integration_.mass_scaling, out.mean_pressure);
  return out;
}

Eigen::Matrix3d SphereWorldImpl::net_force_moment() const {
  const V3 c = centre();
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n_; ++i)
    m += (V3(x_[i], y_[i], z_[i]) - c) * V3(fx_[i], fy_[i], fz_[i]).transpose();
  return m / volume();
}

std::vector<SphereWorld::ContactView> SphereWorldImpl::contacts() const {
  std::vector<SphereWorld::ContactView> out;
  for (int i = 0; i < n_; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_j_[k];
      const V3 h = pair_history(k);
      const PairGeometry g = pair_geometry(i, j);
      const double fn = g.touching ? g.fn : 0.0;
      if (fn <= 0.0 && h.squaredNorm() == 0.0) continue;
      out.push_back({i, j, g.n, fn, h, g.overlap});
    }
  return out;
}

}  // namespace demcal
