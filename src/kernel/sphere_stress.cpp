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

SphereWorldImpl::PairForce SphereWorldImpl::pair_force(int i, int k) const {
  const int j = nbr_j_[k];
  const V3 h = pair_history(k);
  const PairGeometry g = pair_geometry(i, j);
  return {j, g, h, g.touching ? g.fn : 0.0};
}

SphereMeasures SphereWorldImpl::measure(double strain_rate) const {
  SphereMeasures out;
  out.volume = volume();
  const V3 c = centre();
  detail::ContactSums<3> sums;
  const double kn = material_.particle.kn, kt = material_.particle.kt;

  for (int i = 0; i < n_; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const PairForce p = pair_force(i, k);
      // The springs' energy: the elastic part kn·δ of the normal force, not
      // fn, which carries the dashpot's share with contact damping (and is
      // 0 on a contact opening fast whose spring is still compressed).
      const double fe = p.g.touching ? law::elastic_normal_force(kn, p.g.overlap) : 0.0;
      sums.elastic +=
          law::spring_energy(fe, kn) + law::spring_energy_squared(p.h.squaredNorm(), kt);
      if (!p.carries_force()) continue;
      const V3 f = -p.fn * p.g.n + p.h;  // on i
      sums.add_pair(V3(x_[p.j] - x_[i], y_[p.j] - y_[i], z_[p.j] - z_[i]), f);
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
      sums.elastic += law::spring_energy(fe, kw) + law::spring_energy_squared(h.squaredNorm(), ktw);
      if (fn <= 0.0 && h.squaredNorm() == 0.0) continue;
      const V3 f = fn * g + h;
      const V3 arm = -wall_distance(s, i) * g;
      const V3 xc = V3(x_[i], y_[i], z_[i]) + arm;
      sums.add_wall(arm, xc - c, f);
    }
  }

  detail::ParticleSums particles;
  for (int i = 0; i < n_; ++i) {
    particles.ke_translation += 0.5 * m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i] + vz_[i] * vz_[i]);
    particles.ke_rotation +=
        0.5 * inertia_[i] * (wx_[i] * wx_[i] + wy_[i] * wy_[i] + wz_[i] * wz_[i]);
    particles.net_force += V3(fx_[i], fy_[i], fz_[i]).norm();
    particles.diameter += 2.0 * r_[i];
  }
  detail::set_measures(out, sums, particles, n_, strain_rate,
                       material_.density * integration_.mass_scaling);
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
      const PairForce p = pair_force(i, k);
      if (p.carries_force()) out.push_back({i, p.j, p.g.n, p.fn, p.h, p.g.overlap});
    }
  return out;
}

}  // namespace demcal
