// Test support: a head-on collision of two bodies, undamped, stepped until
// they separate, and the bounds of the discrete contact duration and largest
// overlap, for the contact-law tests of both kernels
// (test_kernel_contact.cpp, test_sphere_contact.cpp); the restitution of the
// clamped dashpot (test_kernel_contact_damping.cpp, the LIGGGHTS decks).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace demcal::test {

/// What a head-on collision showed. The kernels move each body on a
/// straight line between steps (x += v(n+½)·Δt), so the entry and exit
/// times are the linear interpolations of the crossings; d_k, d_k1 are the
/// overlaps on the steps that straddle entry (δ_k < 0 ≤ δ_k+1), d_m, d_m1
/// those that straddle exit.
struct HeadOnCollision {
  double t_in = -1.0, t_out = -1.0, max_overlap = 0.0;
  double d_k = 0.0, d_k1 = 0.0, d_m = 0.0, d_m1 = 0.0;
  int contact_steps = 0;
};

/// Steps `w` (step `dt`) one step at a time, at most 2000, until the bodies
/// separate; `overlap()` is their overlap as the kernel computes it
/// (negative: a gap). In contact the kernel lists exactly one contact,
/// passed to in_contact(contact, overlap); apart, none.
template <class Sample, class Overlap, class InContact>
void collide_head_on(Sample& w, double dt, Overlap overlap, InContact in_contact,
                     HeadOnCollision& out) {
  double prev = overlap();
  for (int s = 0; s < 2000 && out.t_out < 0.0; ++s) {
    ASSERT_TRUE(w.step(1));
    const double cur = overlap();
    const auto c = w.contacts();
    if (cur > 0.0) {
      ++out.contact_steps;
      ASSERT_EQ(c.size(), 1u);
      in_contact(c[0], cur);
      out.max_overlap = std::max(out.max_overlap, cur);
    } else {
      EXPECT_TRUE(c.empty());
    }
    const double t0 = w.time() - dt;
    if (prev <= 0.0 && cur > 0.0) {
      out.t_in = t0 + dt * (-prev) / (cur - prev);
      out.d_k = prev;
      out.d_k1 = cur;
    }
    if (prev > 0.0 && cur <= 0.0) {
      out.t_out = t0 + dt * prev / (prev - cur);
      out.d_m = prev;
      out.d_m1 = cur;
    }
    prev = cur;
  }
}

/// Duration and largest overlap of a linear spring of reduced mass meff,
/// h = ω·Δt, ω = sqrt(kn/meff), approach speed v_rel.
///
/// Duration. While the spring acts, central difference gives
/// δ(n+1) = (2 − h²)·δ(n) − δ(n−1); the samples from the last one before
/// contact to the first one after it all lie on one discrete sine
/// A·sin(θ·(n − n0)), θ = 2·asin(h/2), whose half period is π/θ steps.
/// The only error of the measurement is the linear interpolation of that
/// sine across its two zeros: at most (θ²/6)·max a(1−a)(1−2a) ≈ 0.016·θ²
/// steps each, so |T_meas − π·Δt/θ| ≤ θ²·Δt/16. The discrete half period
/// differs from the continuous T = π·sqrt(meff/kn) by T·(1 − h/θ) ≤ T·h²/24.
///
/// Largest overlap δ_max = v_rel/ω. In contact the scheme conserves
/// J = v(n+½)² + ω²·δ(n)·δ(n+1), so the discrete sine has amplitude
/// A = sqrt(J)·Δt/sin θ with sqrt(J)/v_in ∈ [sqrt(1 − h²/4), 1], i.e.
/// A/δ_max ∈ [sqrt(1 − h²/4), 1]/cos(θ/2); the sampled crest is within a
/// factor cos(θ/2) below A. Hence |max δ/δ_max − 1| ≤ θ²/8 (θ ≥ h).
inline void expect_head_on_bounds(const HeadOnCollision& c, double meff, double kn, double dt,
                                  double v_rel) {
  const double omega = std::sqrt(kn / meff), h = omega * dt;
  const double T = std::numbers::pi * std::sqrt(meff / kn);
  const double theta = 2.0 * std::asin(0.5 * h);
  EXPECT_NEAR(c.t_out - c.t_in, std::numbers::pi * dt / theta, theta * theta * dt / 16.0);
  EXPECT_NEAR(c.t_out - c.t_in, T, T * h * h / 24.0 + theta * theta * dt / 16.0);
  const double dmax = v_rel / omega;
  EXPECT_NEAR(c.max_overlap, dmax, dmax * theta * theta / 8.0);
}

/// The restitution of a head-on collision under demcal's dashpot, which
/// never pulls (fn = max(0, kn·δ + c·δ̇), c = 2ζ·sqrt(kn·m_eff), ζ < 1/√2):
/// the bodies part when kn·δ + c·δ̇ = 0, at ω_d·t* = π − atan(2ζ·sqrt(1−ζ²)/
/// (1−2ζ²)), and e = e^(−ζωt*)·|cos(ω_d·t*) − ζ/sqrt(1−ζ²)·sin(ω_d·t*)|
/// (test_kernel_contact_damping.cpp derives it). A function of ζ alone.
inline double clamped_restitution(double zeta) {
  const double s = std::sqrt(1.0 - zeta * zeta);
  const double phase = std::numbers::pi - std::atan(2.0 * zeta * s / (1.0 - 2.0 * zeta * zeta));
  const double t = phase / s;  // ω·t*
  return std::exp(-zeta * t) * std::abs(std::cos(phase) - zeta / s * std::sin(phase));
}

/// How far the kernels' explicit scheme may put a bounce's restitution
/// from clamped_restitution(ζ), h = ω·Δt (ω = sqrt(kn/m_eff)):
/// e·[h·(ζ + ζ²·|d ln e/dζ|/2) + h²] — the dashpot switching on partway
/// through the first touching step, its half-step lag (a ratio ζ(1 + ζh/2))
/// and second-order terms (test_sphere_restitution.cpp derives it). The
/// slope by a central difference.
inline double clamped_restitution_tolerance(double zeta, double h) {
  const double e = clamped_restitution(zeta), dz = 1e-6;
  const double slope = std::abs(std::log(clamped_restitution(zeta + dz)) -
                                std::log(clamped_restitution(zeta - dz))) /
                       (2.0 * dz);
  return e * (h * (zeta + 0.5 * zeta * zeta * slope) + h * h);
}

/// The energy ledger's bound on a lone damped bounce, (1 + 6ζ)·h: the
/// leapfrog energy (h), the dashpot's loss booked for the whole first
/// touching step (4ζh) and at the half-step-old velocity (2ζh), each of
/// the incoming kinetic energy (test_sphere_restitution.cpp derives it).
inline double bounce_ledger_bound(double zeta, double h) { return (1.0 + 6.0 * zeta) * h; }

/// Its bound from below, (1 + 2ζ)·h: the first touching step's over-booking
/// only raises the reading, the other two errors go either way. Below it
/// the ledger would be missing a loss it should book.
inline double bounce_ledger_lower_bound(double zeta, double h) { return (1.0 + 2.0 * zeta) * h; }

/// Steps `w` one step at a time until the contact (overlap() > 0) has been
/// made and has parted, at most 20 000 steps, with the energy ledger on:
/// into `out` (fields contact_steps, parted, ledger_max, ledger_min) its
/// steps in contact, whether it parted and the ledger's largest and
/// smallest readings. A stop of the kernel (a false "energy created")
/// fails the test. Both kernels' restitution tests
/// (test_kernel_contact_damping.cpp, test_sphere_restitution.cpp).
template <class Sample, class Overlap, class Bounce>
void step_until_parted(Sample& w, const Overlap& overlap, Bounce& out) {
  out.ledger_max = -1e300;
  out.ledger_min = 1e300;
  bool touched = false;
  for (int k = 0; k < 20000 && !out.parted; ++k) {
    if (!w.step(1)) {
      ADD_FAILURE() << to_string(w.divergence()) << " at step " << k << ", ledger "
                    << w.energy_created();
      return;
    }
    out.ledger_max = std::max(out.ledger_max, w.energy_created());
    out.ledger_min = std::min(out.ledger_min, w.energy_created());
    if (overlap() > 0.0) {
      touched = true;
      ++out.contact_steps;
    } else {
      out.parted = touched;
    }
  }
}

}  // namespace demcal::test
