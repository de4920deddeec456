// The contact dashpot (Material::contact_damping_ratio) against closed-form
// results: a head-on collision of two equal disks.
//
// The kernel's normal force is fn = max(0, kn·δ + c·δ̇) with δ the overlap
// and c = 2ζ·sqrt(kn·m_eff) (contact_law.hpp): while fn > 0 the overlap is a
// damped oscillator of ratio ζ and angular frequency ω = sqrt(kn/m_eff),
//   δ(t) = (v/ω_d)·e^(−ζωt)·sin(ω_d·t),  ω_d = ω·sqrt(1 − ζ²).
// The dashpot never pulls, so the disks part when kn·δ + c·δ̇ = 0, before δ
// returns to 0 (a spring-dashpot that could pull would give the textbook
// e = exp(−ζπ/sqrt(1 − ζ²))): with ω_d·t* = π − atan(2ζ·sqrt(1−ζ²)/(1−2ζ²))
// (ζ < 1/√2) the restitution is
//   e = |δ̇(t*)|/v = e^(−ζωt*)·|cos(ω_d·t*) − ζ/sqrt(1−ζ²)·sin(ω_d·t*)|.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "support/head_on.hpp"
#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kR;
using kernel_test::reference_material;

using test::clamped_restitution;

struct Collision {
  double restitution = 0.0;
  double max_energy_gap = 0.0;  // |measured elastic energy − ½kn·δ²| / (½kn·δ_max²)
  double energy_created = 0.0;
};

Collision collide(double zeta, double alpha) {
  Material mat = reference_material(0.3);
  mat.contact_damping_ratio = zeta;
  const double r = kR, v0 = 0.05;
  const std::vector<double> x{0.0, 2.0 * r + 2e-3 * r}, y{0.0, 0.0}, rad{r, r};
  World w(mat, x, y, rad, -10 * r, 12 * r, -10 * r, 10 * r);
  Integration in;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  in.dt = alpha * w.reference_scales().dt_crit;
  w.set_integration(in);
  w.set_velocity(0, v0, 0.0, 0.0);
  w.set_velocity(1, -v0, 0.0, 0.0);
  const double kn = mat.particle.kn;
  auto overlap = [&] { return 2.0 * r - std::hypot(w.x()[1] - w.x()[0], w.y()[1] - w.y()[0]); };
  Collision out;
  bool touched = false;
  double worst_gap = 0.0, max_overlap = 0.0;
  for (int s = 0; s < 100000; ++s) {
    EXPECT_TRUE(w.step(1));
    const double d = overlap();
    if (d > 0.0) {
      touched = true;
      max_overlap = std::max(max_overlap, d);
      // The springs' energy is ½kn·δ² whatever the dashpot does.
      worst_gap = std::max(worst_gap, std::abs(w.measure().elastic_energy - 0.5 * kn * d * d));
    } else if (touched && w.vx()[1] - w.vx()[0] > 0.0 && w.fx()[0] == 0.0) {
      break;
    }
  }
  out.restitution = (w.vx()[1] - w.vx()[0]) / (2.0 * v0);
  out.max_energy_gap = worst_gap / (0.5 * kn * max_overlap * max_overlap);
  out.energy_created = w.energy_created();
  return out;
}

TEST(KernelContactDamping, RestitutionOfTheDampedHeadOnCollision) {
  const double alpha = 0.005;
  // The dashpot acts with the velocity half a step old, the integrator is
  // second order: the restitution is right to first order in ω·Δt.
  const double h = 2.0 * alpha * std::sqrt(2.0);  // ω·Δt with m_eff = m/2
  for (double zeta : {0.05, 0.2, 0.5}) {
    const Collision c = collide(zeta, alpha);
    const double e = clamped_restitution(zeta);
    EXPECT_NEAR(c.restitution, e, 2.0 * h * e) << "zeta " << zeta;
    // Distinct from the law that can pull, which these tolerances separate
    // from ζ = 0.2 on.
    if (zeta >= 0.2) {
      EXPECT_GT(e - std::exp(-zeta * std::numbers::pi / std::sqrt(1.0 - zeta * zeta)), 4.0 * h * e)
          << "zeta " << zeta;
    }
  }
}

TEST(KernelContactDamping, ElasticEnergyIsTheSpringsWhateverTheDashpot) {
  // Measures::elastic_energy and the energy ledger both take ½kn·δ² (the
  // elastic part of the normal force), not ½fn²/kn of the damped force.
  const Collision c = collide(0.3, 0.005);
  EXPECT_LT(c.max_energy_gap, 1e-6);
  // The dashpot's dissipation is booked: no energy reads as created.
  EXPECT_LE(c.energy_created, 0.012);
}

// Issue 14: contact damping 0.2, a common value, failed consolidation on the
// hexagonal REVs with "energy created by the integrator". Two causes in the
// consolidation (biaxial.cpp): the servo ignored the wall dashpots'
// resistance c/Δt, so with gain·ζ_c/α > 1 the wall velocity flipped and
// grew every step; and consolidation ran at α = 0.2, beyond the stable step
// the dashpots leave (estimate 0.16 on hex_5x5). Both REVs now consolidate
// and load to the end at ζ_c = 0.2 and 0.5, the loading at 0.9 × the
// estimate.
TEST(KernelContactDamping, ConsolidationAndLoadingCompleteWithContactDamping) {
  for (const char* name : {"hex_5x5", "hex_10x10"})
    for (const double zeta_c : {0.2, 0.5}) {
      SceneConfig c = load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/" + name + ".json");
      c.material.contact_damping_ratio = zeta_c;
      const ConsolidatedState state = consolidate(c, make_assembly(c));
      ASSERT_TRUE(state.converged) << name << " zeta_c " << zeta_c;
      AlgorithmSpec a = c.algorithm;
      const double stable = estimated_stable_dt_ratio(state, a);
      a.dt_ratio = 0.9 * stable;
      const LoadingResult run = run_loading(state, c.test, a);
      EXPECT_FALSE(run.diverged) << name << " zeta_c " << zeta_c << ": "
                                 << to_string(run.divergence) << " at step " << run.divergence_step;
      EXPECT_EQ(run.steps_run, run.steps_planned) << name << " zeta_c " << zeta_c;
    }
}

}  // namespace
}  // namespace demcal
