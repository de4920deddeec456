// Reference scales and stable-step estimates.
//
// The explicit scheme with this form of global damping is stable for
// ω_max·Δt < 2 whatever the damping ratio (the characteristic polynomial
// (1+c)z² − (2 − ω²Δt²)z + (1−c) has its roots inside the unit circle iff
// 0 < ω²Δt² < 4 for c ≥ 0). ω²_max is the largest eigenvalue of
// A = M^-½ K M^-½, K the stiffness of the current contact network with
// translation and rotation coupled. We compute it two ways:
//  - Lanczos (no re-orthogonalisation: the extreme Ritz value converges
//    first and copies do not exceed it), a sharp lower estimate;
//  - Gershgorin row sums of A (as YADE's GlobalStiffnessTimeStepper does per
//    body), a rigorous but loose upper bound.
// The rotational mode of a frictional packing is the binding one: with six
// contacts and kt = kn/2 the in-phase rotation needs α < 1/√12 ≈ 0.29,
// Gershgorin says 0.20. The search uses the Lanczos value.
//
// Contact dashpots (Material::contact_damping_ratio ζ_c) are explicit: the
// force at step n uses the velocity v(n−½). For one mode, m·ẍ = −k·x − c·ẋ
// with 2ζω = c/m, the scheme is x(n+1) = (2 − 2ζωΔt − ω²Δt²)·x(n) −
// (1 − 2ζωΔt)·x(n−1), whose roots stay in the unit circle iff
// ω²Δt² + 4ζωΔt < 4, i.e. ωΔt < 2·(sqrt(1 + ζ²) − ζ). The dashpots damp
// each contact in proportion to its stiffness, c_k = γ_k·k_k with
// γ_k = 2ζ_c·sqrt(m_eff/kn), so a mode of frequency ω carries at most
// ζ = γ_max·ω/2 (vᵀCv ≤ γ_max·vᵀKv): the estimate uses that bound. The
// global damping is centred (solver.cpp) and does not shorten the step.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "contact_law.hpp"
#include "measure_formulas.hpp"
#include "world_impl.hpp"

namespace demcal {

ReferenceScales WorldImpl::reference_scales() const {
  return particle_scales(radius(), material_, integration_.mass_scaling);
}

namespace {

// One contact of the linearised network: dofs (u_i, θ_i[, u_j, θ_j]).
struct LinearContact {
  int i, j;  // j < 0: wall contact
  double nx, ny, ai, aj, kn, kt;
};

// y = A·x for A = M^-½ K M^-½ (x, y: 3 dofs per particle).
void apply(const std::vector<LinearContact>& contacts, const std::vector<double>& inv_sqrt_mass,
           const std::vector<double>& inv_sqrt_inertia, bool rotation, const Eigen::VectorXd& x,
           Eigen::VectorXd& y) {
  y.setZero();
  auto ux = [&](int p) { return x[3 * p] * inv_sqrt_mass[p]; };
  auto uy = [&](int p) { return x[3 * p + 1] * inv_sqrt_mass[p]; };
  auto th = [&](int p) { return rotation ? x[3 * p + 2] * inv_sqrt_inertia[p] : 0.0; };
  for (const auto& c : contacts) {
    const double tx = -c.ny, ty = c.nx;
    const int i = c.i, j = c.j;
    double dn, dt;
    if (j >= 0) {
      const double dux = ux(j) - ux(i), duy = uy(j) - uy(i);
      dn = dux * c.nx + duy * c.ny;
      dt = dux * tx + duy * ty - c.aj * th(j) - c.ai * th(i);
    } else {
      dn = ux(i) * c.nx + uy(i) * c.ny;
      dt = ux(i) * tx + uy(i) * ty - c.ai * th(i);
    }
    const double fn = c.kn * dn, ft = c.kt * dt;
    // Generalised forces = ∂E/∂u (E = ½kn·dn² + ½kt·dt²).
    if (j >= 0) {
      y[3 * i] -= fn * c.nx + ft * tx;
      y[3 * i + 1] -= fn * c.ny + ft * ty;
      y[3 * j] += fn * c.nx + ft * tx;
      y[3 * j + 1] += fn * c.ny + ft * ty;
      y[3 * i + 2] -= ft * c.ai;
      y[3 * j + 2] -= ft * c.aj;
    } else {
      y[3 * i] += fn * c.nx + ft * tx;
      y[3 * i + 1] += fn * c.ny + ft * ty;
      y[3 * i + 2] -= ft * c.ai;
    }
  }
  const int n = static_cast<int>(inv_sqrt_mass.size());
  for (int p = 0; p < n; ++p) {
    y[3 * p] *= inv_sqrt_mass[p];
    y[3 * p + 1] *= inv_sqrt_mass[p];
    y[3 * p + 2] = rotation ? y[3 * p + 2] * inv_sqrt_inertia[p] : 0.0;
  }
}

// Gershgorin: row sums of |A| bounded contact by contact.
double gershgorin_bound(const std::vector<LinearContact>& contacts, const std::vector<double>& ism,
                        const std::vector<double>& isi, bool rotation) {
  std::vector<double> row(3 * ism.size(), 0.0);
  for (const auto& c : contacts) {
    const double tx = -c.ny, ty = c.nx;
    // dof list, |B_n| and |B_t| entries, and the 1/sqrt(mass) of each dof
    int dof[6];
    double bn[6], bt[6], s[6];
    int nd = 0;
    auto add = [&](int d, double vn, double vt, double sc) {
      dof[nd] = d;
      bn[nd] = std::abs(vn);
      bt[nd] = std::abs(vt);
      s[nd] = sc;
      ++nd;
    };
    add(3 * c.i, c.nx, tx, ism[c.i]);
    add(3 * c.i + 1, c.ny, ty, ism[c.i]);
    if (rotation) add(3 * c.i + 2, 0.0, c.ai, isi[c.i]);
    if (c.j >= 0) {
      add(3 * c.j, c.nx, tx, ism[c.j]);
      add(3 * c.j + 1, c.ny, ty, ism[c.j]);
      if (rotation) add(3 * c.j + 2, 0.0, c.aj, isi[c.j]);
    }
    double sum_n = 0.0, sum_t = 0.0;
    for (int q = 0; q < nd; ++q) {
      sum_n += bn[q] * s[q];
      sum_t += bt[q] * s[q];
    }
    for (int p = 0; p < nd; ++p)
      row[dof[p]] += s[p] * (c.kn * bn[p] * sum_n + c.kt * bt[p] * sum_t);
  }
  return row.empty() ? 0.0 : *std::max_element(row.begin(), row.end());
}

}  // namespace

StabilityEstimate WorldImpl::stability_estimate(int iterations) const {
  const int n = size();
  const bool rotation = !integration_.lock_rotation;
  std::vector<LinearContact> contacts;
  const double kn = material_.particle.kn;
  // A sliding contact can stick again: count its tangential spring too.
  const double kt = material_.particle.friction > 0.0 ? material_.particle.kt : 0.0;
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const int i = pair_i_[k], j = pair_j_[k];
    const PairState p = pair_state(i, j);
    if (p.fn_elastic <= 0.0) continue;  // apart (a dashpot's fn = 0 is still a contact)
    contacts.push_back(
        {i, j, p.nx, p.ny, r_[i] - 0.5 * p.overlap, r_[j] - 0.5 * p.overlap, kn, kt});
  }
  const double kw = material_.wall.kn;
  const double ktw = material_.wall.friction > 0.0 ? material_.wall.kt : 0.0;
  for (int s = 0; s < 4; ++s) {
    for (int i : wall_candidates_[s]) {
      const bool vertical = (s == kLeft || s == kRight);
      const double dist = vertical ? (x_[i] - walls_[s].position) * law::kWallNormal[s][0]
                                   : (y_[i] - walls_[s].position) * law::kWallNormal[s][1];
      if (law::elastic_normal_force(kw, r_[i] - dist) <= 0.0) continue;
      contacts.push_back(
          {i, -1, law::kWallNormal[s][0], law::kWallNormal[s][1], dist, 0.0, kw, ktw});
    }
  }
  return detail::network_stability(
      contacts, m_, inertia_, n, 3, 2, rotation, iterations, gershgorin_bound, apply,
      law::dashpot_gamma_max(contacts, m_, material_.contact_damping_ratio),
      reference_scales().dt_crit);
}

}  // namespace demcal
