// Reference scales and stable-step estimates of the sphere kernel, as the
// 2D kernel's (stability.cpp): the explicit scheme with this global damping
// is stable for ω_max·Δt < 2 whatever the damping ratio, ω²_max the largest
// eigenvalue of A = M^-½ K M^-½, K the stiffness of the current contact
// network with translation and rotation coupled (6 DOF per sphere). Two
// estimates: Lanczos (a sharp lower estimate) and Gershgorin row sums (a
// rigorous, loose upper bound).
//
// Linearised contact (i, j), wall contacts with j the fixed wall: the
// relative displacement of the contact points is
//   Δ = u_j − u_i − (a_i·θ_i + a_j·θ_j) × n,
// energy ½·kn·(Δ·n)² + ½·kt·|Δ − (Δ·n)n|². With f = kn·(Δ·n)·n + kt·Δ_t the
// generalised forces are ∂E/∂u_i = −f, ∂E/∂u_j = f and
// ∂E/∂θ_i = a_i·(f × n), ∂E/∂θ_j = a_j·(f × n). A wall contact is a pair
// whose j is the wall: n = −g (g the inward wall normal), a_i = distance
// from the centre to the wall.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "contact_law.hpp"
#include "measure_formulas.hpp"
#include "sphere_world_impl.hpp"

namespace demcal {

ReferenceScales SphereWorldImpl::reference_scales() const {
  ReferenceScales s;
  if (n_ == 0) return s;
  int imin = 0;
  for (int i = 1; i < n_; ++i)
    if (m_[i] < m_[imin]) imin = i;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  s.mass_min = m_[imin];
  s.dt_crit = critical_time_step(m_[imin], kn);
  s.damping_translation_crit = critical_damping_translation(kn, m_[imin]);
  s.damping_rotation_crit = critical_damping_rotation(kt, r_[imin], inertia_[imin]);
  double dt_sum = 0.0, dr_sum = 0.0;
  for (int i = 0; i < n_; ++i) {
    dt_sum += critical_damping_translation(kn, m_[i]);
    dr_sum += critical_damping_rotation(kt, r_[i], inertia_[i]);
  }
  s.damping_translation_crit_mean = dt_sum / n_;
  s.damping_rotation_crit_mean = dr_sum / n_;
  return s;
}

namespace {

using V3 = Eigen::Vector3d;

struct LinearContact {
  int i, j;  // j < 0: wall
  V3 n;
  double ai, aj, kn, kt;
};

// y = A·x, 6 dofs per particle (u, θ).
void apply(const std::vector<LinearContact>& contacts, const std::vector<double>& ism,
           const std::vector<double>& isi, bool rotation, const Eigen::VectorXd& x,
           Eigen::VectorXd& y) {
  y.setZero();
  auto u = [&](int p) -> V3 { return ism[p] * x.segment<3>(6 * p); };
  auto th = [&](int p) -> V3 {
    return rotation ? V3(isi[p] * x.segment<3>(6 * p + 3)) : V3::Zero();
  };
  for (const auto& c : contacts) {
    V3 d = -u(c.i) - (c.ai * th(c.i)).cross(c.n);
    if (c.j >= 0) d += u(c.j) - (c.aj * th(c.j)).cross(c.n);
    const double dn = d.dot(c.n);
    const V3 f = c.kn * dn * c.n + c.kt * (d - dn * c.n);
    const V3 fxn = f.cross(c.n);
    y.segment<3>(6 * c.i) -= f;
    y.segment<3>(6 * c.i + 3) += c.ai * fxn;
    if (c.j >= 0) {
      y.segment<3>(6 * c.j) += f;
      y.segment<3>(6 * c.j + 3) += c.aj * fxn;
    }
  }
  const int n = static_cast<int>(ism.size());
  for (int p = 0; p < n; ++p) {
    y.segment<3>(6 * p) *= ism[p];
    if (rotation)
      y.segment<3>(6 * p + 3) *= isi[p];
    else
      y.segment<3>(6 * p + 3).setZero();
  }
}

// Gershgorin: row sums of |A|, bounded contact by contact. With an
// orthonormal frame (n, t1, t2) a contact's stiffness is
// kn·b_n b_nᵀ + kt·(b_1 b_1ᵀ + b_2 b_2ᵀ), b the gradient of Δ·e over the
// contact's dofs, and |K_pq| ≤ kn|b_n,p||b_n,q| + kt Σ_k |b_k,p||b_k,q|.
double gershgorin_bound(const std::vector<LinearContact>& contacts, const std::vector<double>& ism,
                        const std::vector<double>& isi, bool rotation) {
  std::vector<double> row(6 * ism.size(), 0.0);
  for (const auto& c : contacts) {
    const V3 t1 = c.n.unitOrthogonal(), t2 = c.n.cross(t1);
    const V3 e[3] = {c.n, t1, t2};
    const double k[3] = {c.kn, c.kt, c.kt};
    int dof[12];
    double coef[12][3], s[12];
    int nd = 0;
    // Δ·e = (u_j − u_i)·e + a_i·θ_i·(e × n) + a_j·θ_j·(e × n)
    auto add_particle = [&](int p, double sign, double arm) {
      for (int a = 0; a < 3; ++a) {
        dof[nd] = 6 * p + a;
        s[nd] = ism[p];
        for (int q = 0; q < 3; ++q) coef[nd][q] = std::abs(sign * e[q][a]);
        ++nd;
      }
      if (!rotation) return;
      for (int a = 0; a < 3; ++a) {
        dof[nd] = 6 * p + 3 + a;
        s[nd] = isi[p];
        for (int q = 0; q < 3; ++q) coef[nd][q] = std::abs(arm * e[q].cross(c.n)[a]);
        ++nd;
      }
    };
    add_particle(c.i, -1.0, c.ai);
    if (c.j >= 0) add_particle(c.j, 1.0, c.aj);
    double sum[3] = {0.0, 0.0, 0.0};
    for (int p = 0; p < nd; ++p)
      for (int q = 0; q < 3; ++q) sum[q] += coef[p][q] * s[p];
    for (int p = 0; p < nd; ++p) {
      double r = 0.0;
      for (int q = 0; q < 3; ++q) r += k[q] * coef[p][q] * sum[q];
      row[dof[p]] += s[p] * r;
    }
  }
  return row.empty() ? 0.0 : *std::max_element(row.begin(), row.end());
}

}  // namespace

StabilityEstimate SphereWorldImpl::stability_estimate(int iterations) const {
  const bool rotation = !integration_.lock_rotation;
  std::vector<LinearContact> contacts;
  // A sliding contact can stick again: count its tangential spring too.
  const double kn = material_.particle.kn;
  const double kt = material_.particle.friction > 0.0 ? material_.particle.kt : 0.0;
  for (int i = 0; i < n_; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_j_[k];
      const PairGeometry g = pair_geometry(i, j);
      if (!g.touching || g.fn <= 0.0) continue;
      contacts.push_back({i, j, g.n, r_[i] - 0.5 * g.overlap, r_[j] - 0.5 * g.overlap, kn, kt});
    }
  const double kw = material_.wall.kn;
  const double ktw = material_.wall.friction > 0.0 ? material_.wall.kt : 0.0;
  for (int s = 0; s < 6; ++s)
    for (size_t k = 0; k < wall_candidates_[s].size(); ++k) {
      const int i = wall_candidates_[s][k];
      if (wall_fn_[s][k] <= 0.0) continue;
      V3 n = V3::Zero();
      n[s / 2] = (s % 2 == 0) ? -1.0 : 1.0;  // from the particle to the wall
      contacts.push_back({i, -1, n, wall_distance(s, i), 0.0, kw, ktw});
    }
  return detail::network_stability(
      contacts, m_, inertia_, n_, 6, 3, rotation, iterations, gershgorin_bound, apply,
      law::dashpot_gamma_max(contacts, m_, material_.contact_damping_ratio),
      reference_scales().dt_crit);
}

}  // namespace demcal
