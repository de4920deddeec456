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
  out.volume = volume();
  const Eigen::Vector2d c = centre();
  detail::ContactSums<2> sums;
  const double kn = material_.particle.kn, kt = material_.particle.kt;

  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const int i = pair_i_[k], j = pair_j_[k];
    const double ft = slot_ft_[pair_slot_[k]];
    const PairState p = pair_state(i, j);
    const double fn = p.fn;
    // The springs' energy, by the contact law: the elastic part of the
    // normal force (with a dashpot, fn is not kn·δ).
    sums.elastic += law::spring_energy(p.fn_elastic, kn) + law::spring_energy(ft, kt);
    if (fn <= 0.0 && ft == 0.0) continue;
    const double nx = p.nx, ny = p.ny;
    const Eigen::Vector2d f(-fn * nx - ft * ny, -fn * ny + ft * nx);  // on i
    sums.add_pair(Eigen::Vector2d(x_[j] - x_[i], y_[j] - y_[i]), f);
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
        sums.elastic += law::spring_energy(law::elastic_normal_force(kw, overlap), kw) +
                        law::spring_energy(ft, ktw);
      if (fn <= 0.0 && ft == 0.0) continue;
      const Eigen::Vector2d f(fn * gnx - ft * gny, fn * gny + ft * gnx);
      const Eigen::Vector2d xc(x_[i] - dist * gnx, y_[i] - dist * gny);
      sums.add_wall(xc - Eigen::Vector2d(x_[i], y_[i]), xc - c, f);
    }
  }

  detail::ParticleSums particles;
  for (int i = 0; i < n; ++i) {
    particles.ke_translation += 0.5 * m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i]);
    particles.ke_rotation += 0.5 * inertia_[i] * omega_[i] * omega_[i];
    particles.net_force += std::hypot(fx_[i], fy_[i]);
    particles.diameter += 2.0 * r_[i];
  }
  detail::set_measures(out, sums, particles, n, strain_rate,
                       material_.density * integration_.mass_scaling);
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
