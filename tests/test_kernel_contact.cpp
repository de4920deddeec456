// Contact law of the kernel against closed-form results (README.md "Physics in one paragraph"):
// normal force kn·δ, contact duration and restitution of a head-on collision,
// incremental tangential spring with the Coulomb cap, torques.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "support/head_on.hpp"
#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kEps;
using kernel_test::kR;
using kernel_test::reference_material;

// Two equal disks approach head-on at ±v0, undamped, and separate again.
// Analytical (linear spring, reduced mass m_eff = m/2, ω = sqrt(kn/m_eff)):
//   normal force fn = kn·δ at every instant,
//   contact duration T = π·sqrt(m_eff/kn), restitution e = 1,
//   largest overlap δ_max = v_rel/ω.
TEST(KernelContact, HeadOnCollisionForceDurationAndRestitution) {
  const Material mat = reference_material(0.3);
  const double r = kR, v0 = 0.05;  // v_rel = 0.1 m/s → δ_max ≈ 4.6e-7 m ≈ 1e-3 r
  const std::vector<double> x{0.0, 2.0 * r + 2e-3 * r}, y{0.0, 0.0}, rad{r, r};  // gap 1e-6 m
  World w(mat, x, y, rad, -10 * r, 12 * r, -10 * r, 10 * r);
  Integration in;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  const double alpha = 0.01;
  in.dt = alpha * w.reference_scales().dt_crit;
  w.set_integration(in);
  w.set_velocity(0, v0, 0.0, 0.0);
  w.set_velocity(1, -v0, 0.0, 0.0);

  const double m = w.mass()[0];
  const double kn = mat.particle.kn;
  const double meff = 0.5 * m;
  const double omega = std::sqrt(kn / meff);
  const double h = omega * in.dt;  // = 2α·sqrt(2) ≈ 0.028
  const double v_rel = 2.0 * v0;

  // Gap (negative overlap) along the centre line, as the kernel computes it.
  auto overlap = [&] { return 2.0 * r - std::hypot(w.x()[1] - w.x()[0], w.y()[1] - w.y()[0]); };

  test::HeadOnCollision hit;
  ASSERT_NO_FATAL_FAILURE(test::collide_head_on(
      w, in.dt, overlap,
      [&](const auto& c, double cur) {
        // fn = kn·δ: the only error is the round-off of δ = 2r − d, a
        // difference of two numbers of size 2r, i.e. a few ulps of 2r.
        EXPECT_NEAR(c.fn, kn * cur, kn * 8.0 * kEps * 2.0 * r);
        EXPECT_EQ(c.ft, 0.0);  // head-on: no tangential motion at all
        EXPECT_DOUBLE_EQ(c.nx, 1.0);
        // Newton's third law, and the force pushes the disks apart.
        EXPECT_DOUBLE_EQ(w.fx()[0], -c.fn);
        EXPECT_DOUBLE_EQ(w.fx()[1], c.fn);
      },
      hit));
  ASSERT_GT(hit.t_in, 0.0);
  ASSERT_GT(hit.t_out, hit.t_in);
  ASSERT_GT(hit.contact_steps, 100);  // the contact is resolved by ~110 steps
  // Duration T = π·sqrt(m_eff/kn) and largest overlap v_rel/ω, to the
  // bounds of the discrete scheme (support/head_on.hpp derives them).
  test::expect_head_on_bounds(hit, meff, kn, in.dt, v_rel);

  // Restitution. In contact the scheme conserves exactly
  // J = v(n+½)² + ω²·δ(n)·δ(n+1) (v = dδ/dt, the approach rate), so
  // e² = v_out²/v_in² = 1 + ω²·(δ_k·δ_k+1 − δ_m·δ_m+1)/v_in², to round-off
  // (the δ products are known to ~1e-12 relative, J to the same).
  // Since |δ_k·δ_k+1| ≤ (v·Δt)²/4, this also bounds |e − 1| ≤ h²/8.
  const double v_out = w.vx()[1] - w.vx()[0];
  const double e = v_out / v_rel;
  const double e2_scheme =
      1.0 + omega * omega * (hit.d_k * hit.d_k1 - hit.d_m * hit.d_m1) / (v_rel * v_rel);
  EXPECT_NEAR(e * e, e2_scheme, 1e-9);
  EXPECT_NEAR(e, 1.0, h * h / 8.0);
}

// A heavy disk pressed onto the bottom wall (wall friction μ_w > 0) is moved
// sideways at constant speed V. The wall's incremental tangential spring
// gives Ft = kt·s (s = slip of the contact point) while kt·s < μ_w·Fn and
// Ft = μ_w·Fn from the first step on which kt·s would exceed it. The torque
// about the centre is −dist·Ft, dist = distance centre→wall = r − δ.
// The disk is made heavy (mass scaling 1e9) so that the contact forces do not
// change its velocity noticeably over the test; every expectation below is
// nevertheless computed from the disk's actual state, not from V.
TEST(KernelContact, WallFrictionSticksThenSlidesAtCoulombLimitWithTorque) {
  const double mu_w = 0.4;
  const Material mat = reference_material(0.3, mu_w);
  const double r = kR, delta = 1e-6;  // Fn = kn·δ = 100 N
  World w = kernel_test::disk_on_bottom_wall(mat, delta, true);
  const Integration in = w.integration();
  const double V = 1e-3;  // slip 1e-9 m per step; sticking lasts μFn/(kt·V·Δt) = 800 steps
  w.set_velocity(0, V, 0.0, 0.0);

  const double ktw = mat.wall.kt;
  double slip = 0.0;  // tangential displacement of the contact point
  bool sliding = false;
  int first_slide = -1, steps = 1600;
  for (int s = 1; s <= steps; ++s) {
    ASSERT_TRUE(w.step(1));
    const Wall& wall = w.wall(kBottom);
    ASSERT_EQ(wall.contacts, 1);
    const double dist = w.y()[0] - wall.position;
    const double fn = mat.wall.kn * (r - dist);
    // Force of the particle on the wall: (Ft, −Fn) (friction drags it along).
    EXPECT_NEAR(-wall.force.y(), fn, fn * 1e-12);
    const double ft = wall.force.x();
    // Contact point velocity: centre velocity plus ω × (−dist·ŷ) = (vx + ω·dist).
    slip += (w.vx()[0] + w.omega()[0] * dist) * in.dt;
    const double cap = mu_w * fn;
    // Stick: Ft = kt·slip exactly (sum of kt·Δs increments, round-off only).
    if (!sliding && ktw * slip < cap) {
      EXPECT_NEAR(ft, ktw * slip, 1e-12 * cap);
      EXPECT_LT(ft, cap);
    } else {
      if (!sliding) first_slide = s;
      sliding = true;
      EXPECT_NEAR(ft, cap, 1e-12 * cap);  // slides at exactly μ·Fn
    }
    // Force on the particle opposes the motion; torque = (x_c − x_p) × f.
    EXPECT_DOUBLE_EQ(w.fx()[0], -ft);
    const double arm_x = 0.0, arm_y = -dist;
    const double torque_geom = arm_x * w.fy()[0] - arm_y * w.fx()[0];
    EXPECT_NEAR(w.torque()[0], torque_geom, 1e-12 * std::abs(torque_geom) + 1e-30);
    EXPECT_NEAR(w.torque()[0], -dist * ft, 1e-12 * dist * cap);
    if (ft > 0.0) {
      EXPECT_LT(w.torque()[0], 0.0);  // friction under a disk moving +x spins it clockwise
    }
  }
  // The transition step is where kt·V·Δt·n first reaches μ·Fn (the disk
  // barely decelerates: by then ΔV/V ≈ ½·(μFn/m)·t/V < 1e-5, which moves
  // the transition by less than 0.01 step).
  const double expected = mu_w * mat.wall.kn * delta / (ktw * V * in.dt);
  EXPECT_NEAR(first_slide, expected, 1.0);
  EXPECT_TRUE(sliding);
}

// An incremental spring belongs to one contact. A disk dragged along a
// frictional wall loads the wall's tangential spring; lifted off and put
// back straight down (by less than the skin: it stays on the wall's
// candidate list, the spring's slot kept), it makes a new contact whose
// spring starts at zero, and with no tangential motion since it carries no
// tangential force at all: exactly 0, not the old spring cut to μ·Fn.
// (kernel_test::disk_on_bottom_wall: the set velocities are the motion.)
TEST(KernelContact, WallSpringStartsAtZeroWhenADiskTouchesAgain) {
  const Material mat = reference_material(0.3, 0.4);
  const double delta = 1e-6;  // Fn = 100 N, μ_w·Fn = 40 N
  World w = kernel_test::disk_on_bottom_wall(mat, delta);
  for (int s = 0; s < 200; ++s) {  // slip 1e-9 m a step: kt_w·2e-7 m = 10 N
    w.set_velocity(0, 1e-3, 0.0, 0.0);
    ASSERT_TRUE(w.step(1));
  }
  ASSERT_NEAR(w.wall(kBottom).force.x(), mat.wall.kt * 2e-7, 1e-6 * mat.wall.kt * 2e-7);
  const int64_t rebuilds = w.rebuilds();
  bool apart = false;
  for (int s = 0; s < 400; ++s) {  // 2e-6 m up, then down again: 1e-8 m a step
    w.set_velocity(0, 0.0, s < 200 ? 1e-2 : -1e-2, 0.0);
    ASSERT_TRUE(w.step(1));
    apart = apart || w.wall(kBottom).contacts == 0;
    if (apart) {
      ASSERT_EQ(w.wall(kBottom).force.x(), 0.0) << "step " << s;
    }
  }
  EXPECT_TRUE(apart);
  EXPECT_EQ(w.rebuilds(), rebuilds);  // the same list throughout
  ASSERT_EQ(w.wall(kBottom).contacts, 1);
  EXPECT_NEAR(-w.wall(kBottom).force.y(), mat.wall.kn * delta, 1e-3 * mat.wall.kn * delta);
}

// The overlap bound (KernelOptions::max_overlap_ratio) is on the smaller
// radius, overlap/min(r_i, r_j): the smaller disk is the one an overlap
// cuts deepest into. Disks r and 3r overlapping by 0.2·r and 0.3·r against
// a bound of 0.25 (on the larger radius they would read 0.067 and 0.1); a
// disk in a wall is measured on its own radius (on its diameter, 0.1 and
// 0.15).
TEST(KernelContact, OverlapBoundIsOnTheSmallerRadius) {
  const double r = kR;
  for (const bool wall : {false, true})
    for (const double overlap : {0.2, 0.3}) {
      SCOPED_TRACE(std::string(wall ? "wall, " : "pair, ") + std::to_string(overlap));
      KernelOptions options;
      options.check_interval = 1;
      options.max_overlap_ratio = 0.25;
      std::vector<double> x{0.0, 4.0 * r - overlap * r}, y{0.0, 0.0}, rad{r, 3.0 * r};
      if (wall) {  // one disk in the left wall
        x = {-10 * r + r - overlap * r};
        y = {0.0};
        rad = {r};
      }
      World w(reference_material(0.3), x, y, rad, -10 * r, 10 * r, -10 * r, 10 * r, options);
      Integration in;
      in.dt = 1e-3 * w.reference_scales().dt_crit;  // a tiny step: the overlap stays
      w.set_integration(in);
      const bool ran = w.step(2);
      EXPECT_EQ(ran, overlap < 0.25);
      EXPECT_EQ(w.divergence(), overlap < 0.25 ? Divergence::kNone : Divergence::kOverlap);
    }
}

// Two heavy disks in contact, the upper one (j) dragged sideways over the
// lower one (i): particle–particle incremental tangential spring kt, capped
// by μ·Fn, torque a·Ft on both disks (a = r − δ/2, same sign on both: the
// pair rolls like two gears), Newton's third law.
TEST(KernelContact, ParticleFrictionSticksThenSlidesWithGearTorques) {
  const double mu = 0.3;
  const Material mat = reference_material(mu);
  const double r = kR, delta = 1e-6;
  const std::vector<double> x{0.0, 0.0}, y{0.0, 2.0 * r - delta}, rad{r, r};
  World w(mat, x, y, rad, -20 * r, 20 * r, -10 * r, 10 * r);
  Integration in;
  in.dt = 1e-6;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  in.mass_scaling = 1e9;
  w.set_integration(in);
  const double V = 1e-3;
  w.set_velocity(1, V, 0.0, 0.0);
  const double kt = mat.particle.kt;

  double ft_expected = 0.0;  // incremental spring integrated from the actual state
  bool slid = false;
  for (int s = 1; s <= 1200; ++s) {
    ASSERT_TRUE(w.step(1));
    const auto c = w.contacts();
    ASSERT_EQ(c.size(), 1u);
    ASSERT_EQ(c[0].i, 0);
    ASSERT_EQ(c[0].j, 1);
    const double nx = c[0].nx, ny = c[0].ny, tx = -ny, ty = nx;
    const double dx = w.x()[1] - w.x()[0], dy = w.y()[1] - w.y()[0];
    const double d = std::hypot(dx, dy);
    EXPECT_NEAR(nx, dx / d, 1e-15);
    EXPECT_NEAR(ny, dy / d, 1e-15);
    const double ov = 2.0 * r - d;
    const double fn = mat.particle.kn * ov;
    EXPECT_NEAR(c[0].fn, fn, mat.particle.kn * 8.0 * kEps * 2.0 * r);
    // Relative velocity of j's contact point with respect to i's, along t.
    const double a = r - 0.5 * ov;
    const double vt = (w.vx()[1] - w.vx()[0]) * tx + (w.vy()[1] - w.vy()[0]) * ty -
                      (w.omega()[0] + w.omega()[1]) * a;
    ft_expected += kt * vt * in.dt;
    const double cap = mu * fn;
    if (std::abs(ft_expected) >= cap) {
      ft_expected = std::copysign(cap, ft_expected);
      slid = true;
    }
    // ~10³ increments, each rounded to ε: 1e-12·cap covers the sum.
    EXPECT_NEAR(c[0].ft, ft_expected, 1e-12 * cap);
    // j moves +x over i: the force on i drags it along +x, i.e. ft·t with
    // t = (−1, 0) and ft < 0.
    EXPECT_LT(c[0].ft, 0.0);
    const double fxi = -c[0].fn * nx + c[0].ft * tx, fyi = -c[0].fn * ny + c[0].ft * ty;
    EXPECT_NEAR(w.fx()[0], fxi, 1e-12 * c[0].fn);
    EXPECT_NEAR(w.fy()[0], fyi, 1e-12 * c[0].fn);
    EXPECT_DOUBLE_EQ(w.fx()[0], -w.fx()[1]);
    EXPECT_DOUBLE_EQ(w.fy()[0], -w.fy()[1]);
    // Torques from the geometry: (x_c − x_i) × f_i and (x_c − x_j) × (−f_i).
    const double ti = a * nx * fyi - a * ny * fxi;
    const double tj = (-a * nx) * (-fyi) - (-a * ny) * (-fxi);
    EXPECT_NEAR(w.torque()[0], ti, 1e-12 * a * c[0].fn);
    EXPECT_NEAR(w.torque()[1], tj, 1e-12 * a * c[0].fn);
    EXPECT_NEAR(w.torque()[0], a * c[0].ft, 1e-12 * a * c[0].fn);
    EXPECT_LT(w.torque()[0], 0.0);
    EXPECT_LT(w.torque()[1], 0.0);
  }
  EXPECT_TRUE(slid);
}

// The tangential history survives neighbour-list rebuilds: forcing a rebuild
// on a loaded frictional packing (an edit that invalidates the list) and
// re-evaluating the forces without a time increment leaves every contact
// force and every wall force bit-identical.
TEST(KernelContact, TangentialHistoryCarriesOverRebuilds) {
  const Material mat = reference_material(0.3, 0.2);
  auto scene = kernel_test::random_loose_scene(6, 6, 11);
  World w = scene.make(mat);
  kernel_test::compact(w, 0.84, 0.3, 0);
  // Shear the packing a little with friction on so that tangential springs load.
  Integration in = w.integration();
  w.wall(kTop).velocity = -1e-4 * kR / in.dt;
  w.wall(kLeft).velocity = 0.5e-4 * kR / in.dt;
  ASSERT_TRUE(w.step(300));
  const auto before = w.contacts();
  int loaded = 0;
  for (const auto& c : before) loaded += (c.ft != 0.0);
  ASSERT_GT(loaded, 10);
  std::array<Eigen::Vector2d, 4> wall_before;
  for (int s = 0; s < 4; ++s) wall_before[s] = w.wall(static_cast<WallSide>(s)).force;
  const int64_t rebuilds = w.rebuilds();
  w.set_position(0, w.x()[0], w.y()[0]);  // same place: only invalidates the list
  w.update_forces();
  EXPECT_EQ(w.rebuilds(), rebuilds + 1);
  const auto after = w.contacts();
  ASSERT_EQ(after.size(), before.size());
  for (size_t k = 0; k < after.size(); ++k) {
    EXPECT_EQ(after[k].i, before[k].i);
    EXPECT_EQ(after[k].j, before[k].j);
    EXPECT_EQ(after[k].fn, before[k].fn);
    EXPECT_EQ(after[k].ft, before[k].ft);
  }
  for (int s = 0; s < 4; ++s) {
    EXPECT_EQ(w.wall(static_cast<WallSide>(s)).force.x(), wall_before[s].x());
    EXPECT_EQ(w.wall(static_cast<WallSide>(s)).force.y(), wall_before[s].y());
  }
}

// Locked rotation (algorithm.lock_rotation, the diagnostic switch under which
// the hexagonal packing fails by the analytical sliding mechanism) means ω ≡ 0: a
// spin left over from before the lock, or set afterwards, must neither turn
// the disk nor load the tangential springs through the contact-point
// velocity.
TEST(KernelContact, LockedRotationMeansNoSpinAndNoSpinDrivenFriction) {
  const Material mat = reference_material(0.3, 0.5);
  const double r = kR;
  const std::vector<double> x{0.0}, y{r - 1e-6}, rad{r};
  World w(mat, x, y, rad, -20 * r, 20 * r, 0.0, 10 * r);
  Integration in;
  in.dt = 1e-6;
  in.mass_scaling = 1e9;
  w.set_velocity(0, 0.0, 0.0, 50.0);  // spinning before the lock...
  in.lock_rotation = true;
  w.set_integration(in);
  ASSERT_TRUE(w.step(10));
  w.set_velocity(0, 0.0, 0.0, 50.0);  // ... and after it
  ASSERT_TRUE(w.step(10));
  EXPECT_EQ(w.omega()[0], 0.0);
  EXPECT_EQ(w.rotation()[0], 0.0);
  EXPECT_EQ(w.wall(kBottom).force.x(), 0.0);  // no tangential force at all
  EXPECT_EQ(w.measure().kinetic_energy_rotation, 0.0);
}

}  // namespace
}  // namespace demcal
