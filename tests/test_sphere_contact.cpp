// Contact law of the sphere kernel against closed-form results: normal
// force kn·δ, duration and restitution of a head-on collision, the
// tangential spring sticking then sliding at μ·Fn with the torques it
// makes, and the tangential history turning with a rigidly rotating pair.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "support/head_on.hpp"
#include "test_sphere_helpers.hpp"

namespace demcal {
namespace {

using Eigen::Vector3d;
using sphere_test::kEps;
using sphere_test::kR;
using sphere_test::test_material;

// Two equal spheres approach head-on at ±v0 along a direction oblique to
// every axis, undamped, and separate again. Linear spring, reduced mass
// m_eff = m/2, ω = sqrt(kn/m_eff): fn = kn·δ at every instant, contact
// duration T = π·sqrt(m_eff/kn), restitution 1, largest overlap v_rel/ω.
// The discrete bounds are the 2D kernel's (support/head_on.hpp derives
// them): the samples lie on a discrete sine of angle θ = 2·asin(h/2),
// h = ω·Δt; linear interpolation of the crossings errs by ≤ θ²·Δt/16 each
// side; the discrete half period differs from T by ≤ T·h²/24; |e − 1| ≤ h²/8;
// |max δ/δ_max − 1| ≤ θ²/8.
TEST(SphereContact, HeadOnCollisionForceDurationAndRestitution) {
  const SphereMaterial mat = test_material(0.3);
  const double r = kR, v0 = 0.05;
  const Vector3d u = Vector3d(1.0, 2.0, 2.0) / 3.0;
  sphere_test::Scene s;
  s.add(Vector3d::Zero(), r);
  s.add((2.0 * r + 1e-4 * r) * u, r);  // gap 5e-8 m, ~200 steps to close
  s.lo = {-10 * r, -10 * r, -10 * r};
  s.hi = {12 * r, 12 * r, 12 * r};
  SphereWorld w = s.make(mat);
  const double alpha = 0.01;
  const Integration in = sphere_test::set_undamped(w, alpha);
  w.set_velocity(0, v0 * u, Vector3d::Zero());
  w.set_velocity(1, -v0 * u, Vector3d::Zero());

  const double m = w.mass()[0], kn = mat.particle.kn, kt = mat.particle.kt;
  const double meff = 0.5 * m, omega = std::sqrt(kn / meff), h = omega * in.dt;
  const double v_rel = 2.0 * v0;
  auto overlap = [&] {
    return 2.0 * r - (sphere_test::position(w, 1) - sphere_test::position(w, 0)).norm();
  };
  test::HeadOnCollision hit;
  ASSERT_NO_FATAL_FAILURE(test::collide_head_on(
      w, in.dt, overlap,
      [&](const auto& c, double cur) {
        // δ = 2r − d: a few ulps of 2r.
        EXPECT_NEAR(c.fn, kn * cur, kn * 8.0 * kEps * 2.0 * r);
        // Head-on: the tangential velocity is round-off (a few ulps of v_rel),
        // accumulated over at most the ~110 contact steps.
        EXPECT_LE(c.tangential.norm(), kt * in.dt * 200.0 * 8.0 * kEps * v_rel);
        EXPECT_NEAR(c.normal.dot(u), 1.0, 8.0 * kEps);
        // Newton's third law, repulsive.
        EXPECT_NEAR((sphere_test::force(w, 0) + c.fn * u).norm(), 0.0, 1e-12 * c.fn);
        EXPECT_NEAR((sphere_test::force(w, 1) + sphere_test::force(w, 0)).norm(), 0.0,
                    1e-14 * c.fn);
      },
      hit));
  ASSERT_GT(hit.t_in, 0.0);
  ASSERT_GT(hit.t_out, hit.t_in);
  ASSERT_GT(hit.contact_steps, 100);
  test::expect_head_on_bounds(hit, meff, kn, in.dt, v_rel);
  const double e = (sphere_test::velocity(w, 1) - sphere_test::velocity(w, 0)).dot(u) / v_rel;
  EXPECT_NEAR(e, 1.0, h * h / 8.0);
}

// Contact dashpot: two spheres overlapping by δ along an oblique normal n,
// sphere 1 set moving towards sphere 0 at V after a step (update_forces()
// must read the velocities set since, not the step's: a pair pass that
// read a copy of the neighbour's state refreshed only by the integration
// pass would fail here). Normal force kn·δ + 2ζ·sqrt(kn·m_eff)·V, m_eff =
// m/2, on 0 along −n; no tangential force (v_rel ∥ n, and update_forces
// adds no increment).
TEST(SphereContact, DampedNormalForceReadsAVelocitySetSinceTheLastStep) {
  SphereMaterial mat = test_material(0.3);
  mat.contact_damping_ratio = 0.2;
  const double r = kR, delta = 1e-3 * r, V = 0.05;
  const Vector3d u = Vector3d(1.0, 2.0, 2.0) / 3.0;
  sphere_test::Scene s;
  s.add(Vector3d::Zero(), r);
  s.add((2.0 * r - delta) * u, r);
  s.lo = {-10 * r, -10 * r, -10 * r};
  s.hi = {12 * r, 12 * r, 12 * r};
  SphereWorld w = s.make(mat);
  sphere_test::set_undamped(w, 0.1);
  ASSERT_TRUE(w.step(1));  // the spring sets them moving apart
  const double kn = mat.particle.kn, meff = 0.5 * w.mass()[0];
  const double dist = (sphere_test::position(w, 1) - sphere_test::position(w, 0)).norm();
  const double spring = kn * (2.0 * r - dist);
  w.set_velocity(0, Vector3d::Zero(), Vector3d::Zero());
  w.set_velocity(1, -V * u, Vector3d::Zero());
  w.update_forces();
  const double fn = spring + 2.0 * mat.contact_damping_ratio * std::sqrt(kn * meff) * V;
  // δ = 2r − d cancels most of d: a few ulps of 2r relative to δ.
  const double tol = kn * 8.0 * kEps * 2.0 * r + 8.0 * kEps * fn;
  EXPECT_NEAR((sphere_test::force(w, 0) + fn * u).norm(), 0.0, tol);
  EXPECT_NEAR((sphere_test::force(w, 1) - fn * u).norm(), 0.0, tol);
  // The springs hold ½·(kn·δ)²/kn, the dashpot's share of fn none (the
  // motion was along n, so no tangential spring); d(½f²/kn) = f·df/kn.
  const double tol_spring = kn * 8.0 * kEps * 2.0 * r + 8.0 * kEps * spring;
  EXPECT_NEAR(w.measure().elastic_energy, 0.5 * spring * spring / kn, spring * tol_spring / kn);
}

// The oblique tests' scene: two heavy spheres of radius kR (mass scaling
// 1e15) overlapping by δ along n0, undamped, Δt = 1e-6 s.
SphereWorld oblique_pair(const SphereMaterial& mat, const Vector3d& n0, double delta,
                         Integration& in) {
  const double r = kR;
  sphere_test::Scene s;
  s.add(Vector3d::Zero(), r);
  s.add((2.0 * r - delta) * n0, r);
  s.lo = {-10 * r, -10 * r, -10 * r};
  s.hi = {10 * r, 10 * r, 10 * r};
  SphereWorld w = s.make(mat);
  in = sphere_test::set_undamped(w, 0.0, 1e15);
  in.dt = 1e-6;
  w.set_integration(in);
  return w;
}

// Two spheres overlapping by δ along an oblique normal n; sphere 1 slides
// past sphere 0 at constant speed V along a tangent t. Heavy spheres (mass
// scaling 1e15): the contact forces change the velocities by a fraction
// F·T/(m·V) < 1e-7 over the test. Incremental spring: Ft = kt·V·t_elapsed
// along the (turning) tangent while below μ·Fn, then exactly μ·Fn. The
// normal turns by φ ≤ s/d (s the slip), which shortens each increment's
// projection by at most φ²/2. Forces −Fn·n + Ft on 0 and the opposite on 1;
// torques a_0·n × Ft and a_1·n × Ft, a = r − δ/2.
TEST(SphereContact, ObliqueContactSticksThenSlidesAtCoulombLimit) {
  const double mu = 0.3, r = kR, delta = 1e-6, V = 1e-3;
  const SphereMaterial mat = test_material(mu);
  const Vector3d n0 = Vector3d(2.0, 3.0, 6.0) / 7.0, t = Vector3d(3.0, -6.0, 2.0) / 7.0;
  Integration in;
  SphereWorld w = oblique_pair(mat, n0, delta, in);
  w.set_velocity(1, V * t, Vector3d::Zero());
  const double kn = mat.particle.kn, kt = mat.particle.kt;
  const int steps = 1000;
  const double slip_max = V * in.dt * steps, phi = slip_max / (2.0 * r - delta);
  const double force_max = kn * 2.0 * delta;  // far above anything reached
  const double drift = force_max * steps * in.dt / (w.mass()[0] * V);
  ASSERT_LT(drift, 1e-6);
  int stuck = 0, slid = 0;
  for (int k = 1; k <= steps; ++k) {
    ASSERT_TRUE(w.step(1));
    const auto c = w.contacts();
    ASSERT_EQ(c.size(), 1u);
    const Vector3d n = c[0].normal, ft = c[0].tangential;
    const double d = (sphere_test::position(w, 1) - sphere_test::position(w, 0)).norm();
    const double fn = kn * (2.0 * r - d);
    EXPECT_NEAR(c[0].fn, fn, kn * 8.0 * kEps * 2.0 * r);
    EXPECT_NEAR(ft.dot(n), 0.0, 1e-12 * ft.norm());
    // Direction: the current tangent, the one t turns into.
    const Vector3d t_now = (t - t.dot(n) * n).normalized();
    EXPECT_NEAR(ft.normalized().dot(t_now), 1.0, 1e-12);
    const double stick = kt * V * in.dt * k;
    const double tol = stick * (phi * phi / 2.0 + drift) + 1e-12 * stick;
    if (stick < mu * fn - tol) {
      EXPECT_NEAR(ft.norm(), stick, tol);
      ++stuck;
    } else if (stick > mu * fn + tol) {
      EXPECT_NEAR(ft.norm(), mu * fn, 1e-13 * mu * fn);
      ++slid;
    }
    const Vector3d f0 = -c[0].fn * n + ft;
    EXPECT_NEAR((sphere_test::force(w, 0) - f0).norm(), 0.0, 1e-13 * fn);
    EXPECT_NEAR((sphere_test::force(w, 1) + f0).norm(), 0.0, 1e-13 * fn);
    const double a = r - 0.5 * c[0].overlap;
    EXPECT_NEAR((sphere_test::torque(w, 0) - a * n.cross(ft)).norm(), 0.0, 1e-13 * fn * r);
    EXPECT_NEAR((sphere_test::torque(w, 1) - a * n.cross(ft)).norm(), 0.0, 1e-13 * fn * r);
  }
  EXPECT_GT(stuck, 500);  // μ·Fn/(kt·V·Δt) = 600 steps of sticking
  EXPECT_GT(slid, 300);
}

// Frictionless spheres (μ = 0) touch with the normal force alone, whatever
// the slip and the spins: the tangential force and both torques are exactly
// 0 — along an oblique normal, and along an axis with a slip so small
// (1e-165 m/s) that the trial history's square underflows to 0, where a
// Coulomb cap compared in squares lets it through. (Along an oblique
// normal the normal motion's round-off leaves a tangential slip far above
// that: the axis keeps the components apart.)
TEST(SphereContact, FrictionlessSpheresExertNoTangentialForce) {
  const double r = kR, delta = 1e-6;
  const SphereMaterial mat = test_material(0.0);
  const Vector3d oblique_n = Vector3d(2.0, 3.0, 6.0) / 7.0,
                 oblique_t = Vector3d(3.0, -6.0, 2.0) / 7.0;
  for (const bool axis : {false, true})
    for (const double V : {1e-3, 1e-165}) {
      SCOPED_TRACE(testing::Message()
                   << (axis ? "axis" : "oblique") << " normal, slip " << V << " m/s");
      const Vector3d n0 = axis ? Vector3d::UnitZ() : oblique_n;
      const Vector3d t = axis ? Vector3d::UnitX() : oblique_t;
      Integration in;
      SphereWorld w = oblique_pair(mat, n0, delta, in);
      w.set_velocity(1, V * t, (0.7 * V / r) * n0.cross(t));
      w.set_velocity(0, Vector3d::Zero(), (0.3 * V / r) * n0);
      for (int k = 1; k <= 50; ++k) {
        ASSERT_TRUE(w.step(1));
        const auto c = w.contacts();
        ASSERT_EQ(c.size(), 1u);
        EXPECT_EQ(c[0].tangential, Vector3d::Zero());
        const Vector3d n = c[0].normal, f0 = sphere_test::force(w, 0);
        EXPECT_EQ(f0, -c[0].fn * n);
        EXPECT_EQ(sphere_test::force(w, 1), -f0);
        EXPECT_EQ(sphere_test::torque(w, 0), Vector3d::Zero());
        EXPECT_EQ(sphere_test::torque(w, 1), Vector3d::Zero());
      }
    }
}

// The oblique contact of the test above, slid past the Coulomb limit, then
// driven back: the spring unloads elastically from the capped force, by
// kt·V·Δt per step along the current tangent, through zero after
// μ·Fn/(kt·V·Δt) = 600 steps, and slides again at −μ·Fn after 1 200. A
// history reset when the contact slides, or set to μ·Fn along the slip,
// flips the force at the first step back and fails. Tolerances as above:
// the normal turns by φ ≤ s/d over the whole slip s (O(φ²) of the force),
// the spheres' velocities drift by < 1e-6 relative, and round-off.
TEST(SphereContact, ObliqueContactUnloadsElasticallyAfterSliding) {
  const double mu = 0.3, r = kR, delta = 1e-6, V = 1e-3;
  const SphereMaterial mat = test_material(mu);
  const Vector3d n0 = Vector3d(2.0, 3.0, 6.0) / 7.0, t = Vector3d(3.0, -6.0, 2.0) / 7.0;
  Integration in;
  SphereWorld w = oblique_pair(mat, n0, delta, in);
  const double kn = mat.particle.kn, kt = mat.particle.kt, inc = kt * V * in.dt;
  const int forth = 1000, back = 1600;
  const double phi = V * in.dt * (forth + back) / (2.0 * r - delta);
  const double drift = kn * 2.0 * delta * (forth + back) * in.dt / (w.mass()[0] * V);
  ASSERT_LT(drift, 1e-6);
  // Along t_now, the tangent t turns into, and the normal force now.
  auto along = [&](double& fn) {
    const auto c = w.contacts();
    EXPECT_EQ(c.size(), 1u);
    const Vector3d n = c.at(0).normal;
    fn = c.at(0).fn;
    return c.at(0).tangential.dot((t - t.dot(n) * n).normalized());
  };
  w.set_velocity(1, V * t, Vector3d::Zero());
  ASSERT_TRUE(w.step(forth));
  double fn = 0.0;
  const double f0 = along(fn);
  ASSERT_NEAR(f0, mu * fn, 1e-13 * mu * fn);  // sliding forward
  w.set_velocity(1, -V * t, Vector3d::Zero());
  int unloading = 0, sliding_back = 0;
  for (int k = 1; k <= back; ++k) {
    ASSERT_TRUE(w.step(1));
    const double ft = along(fn);
    const double elastic = f0 - inc * k;
    const double tol = (f0 + inc * k) * (phi * phi + drift) + 1e-12 * mu * fn;
    if (elastic > -mu * fn + tol) {
      EXPECT_NEAR(ft, elastic, tol) << "step " << k << " back";
      ++unloading;
    } else if (elastic < -mu * fn - tol) {
      EXPECT_NEAR(ft, -mu * fn, 1e-13 * mu * fn) << "step " << k << " back";
      ++sliding_back;
    }
  }
  EXPECT_GT(unloading, 1150);  // 2·μ·Fn/(kt·V·Δt) = 1 200 steps
  EXPECT_GT(sliding_back, 350);
}

// Lever arms with unequal radii, by hand. A small sphere (r_s = r) and a
// large one (r_b = 1.6·r) overlap by δ = 1e-5 m along n (from the small
// to the large), δ/(2·r_s) = 1 %; neither moves, both may spin about axes
// normal to n. The contact point is the middle of the overlap, at arms a_s
// = r_s − δ/2 and a_b = r_b − δ/2 from the centres, so the large sphere's
// contact point moves relative to the small one's at
//   v_t = ω_b × (−a_b·n) − ω_s × (a_s·n) = n × S,  S = a_s·ω_s + a_b·ω_b,
// tangential (S ⊥ n). Centres fixed, the normal never turns and, the spins
// being normal to n, the history does not twist: the incremental spring
// gives, on the small sphere, h = kt·Δt·k·v_t after k steps while |h| <
// μ·Fn, then μ·Fn·v_t/|v_t| (friction drags each body along with the
// other's surface), Fn = kn·δ; the force on the small sphere −Fn·n + h, on
// the large one its opposite. The torques a·n × h are, with n × (n × S) =
// −S, −a_s·(h/|v_t|)·S on the small sphere and −a_b·(h/|v_t|)·S on the large
// one: each opposes S, in the ratio of the arms. With the small sphere at
// rest (S = a_b·ω_b) the large one is braked (−a_b²·ω_b) and the small one
// driven the other way, as meshing gears. Run with either sphere the lower
// index (the kernel's n, and the force it books on "i", flip with it).
//
// Tolerances. Mass scaling 1e19 makes both spheres near-immovable: over T =
// 2 000·Δt the spins change by at most a·μFn·T/I, the centres' speeds by
// 2Fn·T/m and the overlap by 2Fn·T²/m, which changes |v_t| and Fn by the
// `drift` computed below (1.4e-10 of themselves), and h, a sum of
// increments, by as much. Round-off: δ = r_s + r_b
// − d cancels d, a few ulps of d relative to δ (8ε·(r_s + r_b)/δ ≈ 2e-13),
// and h sums ≤ 2 000 increments (2 000·ε). Swapping the arms (a_b·ω_s +
// a_s·ω_b) changes |v_t| by a factor a_s/a_b ≈ 0.63, and arms r instead of
// r − δ/2 change the forces or torques by δ/(2r) ≥ 0.6 %.
void expect_lever_arms(bool small_first, const Vector3d& omega_small, const Vector3d& omega_big) {
  const double mu = 0.3, rs = kR, rb = 1.6 * kR, delta = 1e-5;
  const SphereMaterial mat = test_material(mu);
  const Vector3d n = Vector3d(2.0, 3.0, 6.0) / 7.0;
  const int is = small_first ? 0 : 1, ib = 1 - is;
  sphere_test::Scene s;
  const Vector3d x_small = Vector3d::Zero(), x_big = (rs + rb - delta) * n;
  s.add(small_first ? x_small : x_big, small_first ? rs : rb);
  s.add(small_first ? x_big : x_small, small_first ? rb : rs);
  s.lo = {-10 * rb, -10 * rb, -10 * rb};
  s.hi = {10 * rb, 10 * rb, 10 * rb};
  SphereWorld w = s.make(mat);
  Integration in = sphere_test::set_undamped(w, 0.0, 1e19);
  in.dt = 1e-6;
  w.set_integration(in);
  ASSERT_FALSE(in.lock_rotation);
  w.set_velocity(is, Vector3d::Zero(), omega_small);
  w.set_velocity(ib, Vector3d::Zero(), omega_big);

  const double kn = mat.particle.kn, kt = mat.particle.kt, fn = kn * delta, cap = mu * fn;
  const double as = rs - 0.5 * delta, ab = rb - 0.5 * delta;
  const Vector3d S = as * omega_small + ab * omega_big, vt = n.cross(S);
  ASSERT_NEAR(S.dot(n), 0.0, 1e-15 * S.norm());
  const int steps = 2000;
  const double T = steps * in.dt;
  const double ms = w.mass()[is], mb = w.mass()[ib], Is = w.inertia()[is], Ib = w.inertia()[ib];
  const double drift = T * (as * as * cap / Is + ab * ab * cap / Ib) / vt.norm() +
                       2.0 * fn * T / (std::min(ms, mb) * vt.norm()) +
                       2.0 * fn * T * T / (std::min(ms, mb) * delta);
  ASSERT_LT(drift, 1e-9);
  const double tol = (drift + 2000.0 * kEps + 8.0 * kEps * (rs + rb) / delta) * (fn + cap);
  int stuck = 0, slid = 0;
  for (int k = 1; k <= steps; ++k) {
    ASSERT_TRUE(w.step(1));
    const double stick = kt * in.dt * k * vt.norm();
    if (std::abs(stick - cap) < tol) continue;
    const double ht = std::min(stick, cap);  // |h|
    (stick < cap ? stuck : slid)++;
    const Vector3d h = ht * vt.normalized();
    const Vector3d f_small = -fn * n + h;
    EXPECT_NEAR((sphere_test::force(w, is) - f_small).norm(), 0.0, tol) << "step " << k;
    EXPECT_NEAR((sphere_test::force(w, ib) + f_small).norm(), 0.0, tol) << "step " << k;
    const Vector3d m_small = -as * (ht / vt.norm()) * S, m_big = -ab * (ht / vt.norm()) * S;
    EXPECT_NEAR((sphere_test::torque(w, is) - m_small).norm(), 0.0, tol * rs) << "step " << k;
    EXPECT_NEAR((sphere_test::torque(w, ib) - m_big).norm(), 0.0, tol * rb) << "step " << k;
    // The contact's own view: the force on the lower index, tangential part.
    const auto c = w.contacts();
    ASSERT_EQ(c.size(), 1u);
    EXPECT_NEAR((c[0].tangential - (small_first ? h : Vector3d(-h))).norm(), 0.0, tol);
    EXPECT_NEAR(c[0].overlap, delta, drift * delta + 8.0 * kEps * (rs + rb));
  }
  // μ·Fn/(kt·Δt·|v_t|) = 1 200 steps of sticking (|v_t| = 5e-3 m/s).
  EXPECT_GT(stuck, 1150);
  EXPECT_GT(slid, 750);
}

TEST(SphereContact, LeverArmsOfUnequalSpheresByHand) {
  const double rs = kR, rb = 1.6 * kR, delta = 1e-5;
  const double as = rs - 0.5 * delta, ab = rb - 0.5 * delta;
  // Two unit vectors normal to n = (2, 3, 6)/7 and to each other.
  const Vector3d e1 = Vector3d(3.0, -6.0, 2.0) / 7.0, e2 = Vector3d(6.0, 2.0, -3.0) / 7.0;
  for (bool small_first : {true, false}) {
    SCOPED_TRACE(small_first ? "small sphere first" : "large sphere first");
    {
      SCOPED_TRACE("small at rest, large spinning");
      expect_lever_arms(small_first, Vector3d::Zero(), (5e-3 / ab) * e1);
    }
    {
      SCOPED_TRACE("both spinning");
      expect_lever_arms(small_first, (4e-3 / as) * e2, (3e-3 / ab) * e1);
    }
  }
}

// A contact pair loaded in shear, then turned rigidly by Θ = 90° about an
// axis through its centre (the driver prescribes the rigid velocity field
// every step: v = (R(Ω·Δt) − I)(x − c)/Δt, so the centres move exactly on
// the rotated positions, and ω = Ω). The tangential force must turn with the
// pair: F_t(end) = R(Θ)·F_t(start), magnitude kept. Error sources, bounded:
//  - the chord velocity leaves a tangential slip rate |d|·Ω·(ΩΔt)²/6 per step,
//    i.e. kt·d·Θ·(ΩΔt)²/6 of force over the turn;
//  - per step the turning is a tilt (rescaled projection: exact for a tilt
//    axis normal to F_t) and a twist about n (exact); splitting a rotation
//    into the two errs by at most (ΩΔt)²·|F_t| per step, and the rescaled
//    projection turns a force with components both in and out of the tilt
//    plane with an error of at most (ΩΔt)²·|F_t|: 2·Θ·ΩΔt·|F_t| in all.
//    For the pure tilt of a force in the tilt plane and for the pure twist
//    only round-off remains;
//  - the incremental law itself: velocities at n+½ against the normal at
//    n+1 leave, per step, a slip ½(ΩΔt)²·|d|·(Ω̂·n)·|Ω̂ × n| along the
//    contact plane (first order in Δt overall, zero for a pure tilt or
//    twist): at most kt·d·Θ·ΩΔt/4 of force over the turn;
//  - the contact forces' own change of the prescribed velocities within a
//    step: a slip ≤ Δt²·|F_t|·(2/m + 2a²/I) = 7·Δt²·|F_t|/m per step,
//    negligible with mass scaling 1e18.
struct TurnResult {
  Vector3d expected, got;
  double force, tolerance;
};

TurnResult turn_loaded_pair(const Vector3d& axis, const Vector3d& load, bool general_axis) {
  const double r = kR, delta = 1e-5;  // Fn = 1000 N
  const SphereMaterial mat = test_material(1.0);
  sphere_test::Scene s;
  s.add(Vector3d::Zero(), r);
  s.add(Vector3d(2.0 * r - delta, 0.0, 0.0), r);
  s.lo = {-10 * r, -10 * r, -10 * r};
  s.hi = {10 * r, 10 * r, 10 * r};
  SphereWorld w = s.make(mat);
  Integration in = sphere_test::set_undamped(w, 0.0, 1e18);
  in.dt = 1e-6;
  w.set_integration(in);
  // Load: sphere 1 slides along `load` for a few steps (|Ft| ≈ 0.25–0.3 Fn).
  w.set_velocity(1, load, Vector3d::Zero());
  w.step(5);
  w.set_velocity(0, Vector3d::Zero(), Vector3d::Zero());
  w.set_velocity(1, Vector3d::Zero(), Vector3d::Zero());
  w.step(1);
  const auto c0 = w.contacts();
  const Vector3d f0 = c0.at(0).tangential;
  const Vector3d centre = 0.5 * (sphere_test::position(w, 0) + sphere_test::position(w, 1));
  const double d = (sphere_test::position(w, 1) - sphere_test::position(w, 0)).norm();

  // A zero `axis` means the branch itself (the loading tilted it a little).
  const Vector3d e =
      axis.isZero()
          ? Vector3d(sphere_test::position(w, 1) - sphere_test::position(w, 0)).normalized()
          : axis.normalized();
  const int steps = 100000;
  const double theta = 0.5 * std::numbers::pi, wdt = theta / steps;
  const Vector3d Omega = e * wdt / in.dt;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(wdt, e).toRotationMatrix();
  for (int k = 0; k < steps; ++k) {
    for (int i = 0; i < 2; ++i)
      w.set_velocity(
          i, (R - Eigen::Matrix3d::Identity()) * (sphere_test::position(w, i) - centre) / in.dt,
          Omega);
    w.step(1);
  }
  const Eigen::Matrix3d Rt = Eigen::AngleAxisd(theta, e).toRotationMatrix();
  TurnResult out;
  out.expected = Rt * f0;
  out.got = w.contacts().at(0).tangential;
  out.force = f0.norm();
  const double kt = mat.particle.kt;
  out.tolerance = kt * d * theta * wdt * wdt / 6.0 +
                  steps * kt * 7.0 * in.dt * in.dt * out.force / w.mass()[0] + 1e-9 * out.force;
  if (general_axis) out.tolerance += 2.0 * theta * wdt * out.force + kt * d * theta * wdt / 4.0;
  return out;
}

TEST(SphereContact, TangentialForceTurnsWithRigidlyRotatingPair) {
  // Tilt (axis normal to the branch, force in the tilt plane), twist (axis
  // along the branch), and both with a force in no special direction.
  struct Case {
    Vector3d axis, load;
    bool general;
  };
  for (const Case& c : {Case{{0, 0, 1}, {0, 1, 0}, false}, Case{{0, 0, 0}, {0, 1, 0.5}, false},
                        Case{{1, 1, 1}, {0, 1, 0.5}, true}}) {
    SCOPED_TRACE(c.axis.transpose());
    const TurnResult t = turn_loaded_pair(c.axis, c.load, c.general);
    EXPECT_GT(t.force, 100.0);
    EXPECT_NEAR((t.got - t.expected).norm(), 0.0, t.tolerance);
    EXPECT_NEAR(t.got.norm(), t.force, t.tolerance);
  }
}

// KernelOptions::max_overlap_ratio bounds a pair's overlap by the smaller
// of its two radii (a small sphere pressed into a big one is what goes
// wrong first): spheres of r and 3r overlapping by 0.3·r pass a bound of
// 0.25 measured on the big one (0.1) but not on the small one, and stop the
// run as an overlap divergence at the next check; 0.2·r stays below it. A
// sphere in a wall is measured on its own radius (on its diameter 0.3·r
// would read 0.15).
TEST(SphereContact, OverlapBoundIsOnTheSmallerRadius) {
  const double r = kR;
  for (const bool wall : {false, true})
    for (const double overlap : {0.2, 0.3}) {
      SCOPED_TRACE(std::string(wall ? "wall, " : "pair, ") + std::to_string(overlap));
      sphere_test::Scene s;
      if (wall) {  // one sphere in the z-min wall
        s.add(Vector3d(0.0, 0.0, -10 * r + r - overlap * r), r);
      } else {
        s.add(Vector3d::Zero(), r);
        s.add(Vector3d(4.0 * r - overlap * r, 0.0, 0.0), 3.0 * r);
      }
      s.lo = {-10 * r, -10 * r, -10 * r};
      s.hi = {10 * r, 10 * r, 10 * r};
      KernelOptions options;
      options.check_interval = 1;
      options.max_overlap_ratio = 0.25;
      SphereWorld w = s.make(test_material(0.3), options);
      sphere_test::set_undamped(w, 1e-3);  // a tiny step: the overlap stays
      const bool ran = w.step(2);
      EXPECT_EQ(ran, overlap < 0.25);
      EXPECT_EQ(w.divergence(), overlap < 0.25 ? Divergence::kNone : Divergence::kOverlap);
    }
}

// Two spheres on the x axis spin together about it, Ω·Δt = `turn` radians a
// step: the contact turns about its normal n = e_x and nothing else moves
// (the centres stay on the axis and both spin alike, so v_rel = −(a_i +
// a_j)·Ω × n = 0: no increment). The history is turned by the twist alone,
// the Cayley rotation about n with c = Δt·n·(ω_i + ω_j)/4 = turn/2
// (sphere_contact.cpp): by φ = 2·atan(turn/2) a step, which is turn −
// turn³/12 + O(turn⁵), and with its length kept exactly, however large the
// turn. The exact form of the scale A (turn_scale) takes over from its
// series where |y − 1| = 2c² + c⁴ ≥ 1e-4, i.e. from turn ≈ 0.014 on: the
// cases below are on both sides. Heavy masses (scaling 1e22): the forces
// move nothing within the run.
TEST(SphereContact, TwistTurnsTheHistoryByTheCayleyAngleAndKeepsItsLengthAtAnyRate) {
  const double r = kR, delta = 1e-5;  // Fn = 1000 N
  for (const double turn : {0.002, 0.05, 0.3, 1.0}) {
    SCOPED_TRACE(turn);
    sphere_test::Scene s;
    s.add(Vector3d::Zero(), r);
    s.add(Vector3d(2.0 * r - delta, 0.0, 0.0), r);
    s.lo = {-10 * r, -10 * r, -10 * r};
    s.hi = {10 * r, 10 * r, 10 * r};
    // No divergence checks within the run: the spin's kinetic energy dwarfs
    // the springs' (their measure, not the law, is what this run strains).
    KernelOptions options;
    options.check_interval = 1 << 20;
    SphereWorld w = s.make(test_material(1.0), options);
    Integration in = sphere_test::set_undamped(w, 0.0, 1e22);
    in.dt = 1e-6;
    w.set_integration(in);
    // Load the tangential spring (|Ft| ≈ kt·5.6e-6 m = 280 N < μ·Fn), then
    // put the sphere back on the axis, so that n = e_x (up to the forces'
    // ≈ 1e-26 m of motion a step); one step turns the history into the
    // contact plane.
    w.set_velocity(1, Vector3d(0.0, 1.0, 0.5), Vector3d::Zero());
    w.step(5);
    w.set_velocity(1, Vector3d::Zero(), Vector3d::Zero());
    w.set_position(1, Vector3d(2.0 * r - delta, 0.0, 0.0));
    w.step(1);
    const Vector3d h0 = w.contacts().at(0).tangential;
    ASSERT_GT(h0.norm(), 100.0);
    ASSERT_LE(std::abs(h0.x()), 1e-15 * h0.norm());
    const Vector3d spin(turn / in.dt, 0.0, 0.0);
    w.set_velocity(0, Vector3d::Zero(), spin);
    w.set_velocity(1, Vector3d::Zero(), spin);
    const int steps = 40;
    ASSERT_TRUE(w.step(steps));
    const double phi = 2.0 * std::atan(0.5 * turn);
    const Vector3d expected = Eigen::AngleAxisd(steps * phi, Vector3d::UnitX()) * h0;
    const Vector3d got = w.contacts().at(0).tangential;
    // A few roundings a step: the turn's arithmetic, and A within 1.5 ulp.
    const double tol = 16.0 * steps * kEps * h0.norm();
    EXPECT_NEAR(got.norm(), h0.norm(), tol);
    EXPECT_LE((got - expected).norm(), tol);
  }
}

}  // namespace
}  // namespace demcal

namespace demcal {
namespace {

// A heavy sphere pressed onto the bottom wall (wall friction μ_w) slides
// horizontally at constant speed V along u. The wall's incremental spring
// gives F_t = kt_w·V·t_elapsed against the motion while below μ_w·Fn, then
// exactly μ_w·Fn; the torque about the centre is (−dist·g) × F_t, dist =
// r − δ; the wall feels the opposite of the force on the sphere. Mass
// scaling 1e15: the forces change the velocity by < 1e-6 relative.
/// A wall's tangential force `ft` on a sphere pressed with `fn` (the
/// imposed normal force; `f_normal` the one measured this step): the
/// spring's `stick` while under the Coulomb cap μ_w·fn, the cap itself once
/// above; steps within `tol` of the cap count as neither.
void expect_stick_or_slide(double ft, double stick, double tol, double mu_w, double fn,
                           double f_normal, int& stuck, int& slid) {
  if (stick < mu_w * fn - tol) {
    EXPECT_NEAR(ft, stick, tol);
    ++stuck;
  } else if (stick > mu_w * fn + tol) {
    EXPECT_NEAR(ft, mu_w * f_normal, 1e-13 * fn);
    ++slid;
  }
}

TEST(SphereContact, WallFrictionSticksThenSlidesWithTorque) {
  const double mu_w = 0.4, r = kR, delta = 1e-6, V = 1e-3;
  const SphereMaterial mat = test_material(0.3, mu_w);
  sphere_test::Scene s;
  s.add(Vector3d(0.0, 0.0, r - delta), r);
  s.lo = {-20 * r, -20 * r, 0.0};
  s.hi = {20 * r, 20 * r, 10 * r};
  SphereWorld w = s.make(mat);
  Integration in = sphere_test::set_undamped(w, 0.0, 1e15);
  in.dt = 1e-6;
  w.set_integration(in);
  const Vector3d u = Vector3d(1.0, 2.0, 0.0).normalized(), g(0.0, 0.0, 1.0);
  w.set_velocity(0, V * u, Vector3d::Zero());
  const double fn = mat.wall.kn * delta, ktw = mat.wall.kt;
  int stuck = 0, slid = 0;
  for (int k = 1; k <= 1500; ++k) {
    ASSERT_TRUE(w.step(1));
    const Vector3d f = sphere_test::force(w, 0);
    EXPECT_NEAR(f.dot(g), fn, 1e-6 * fn);  // the sphere stays at its height
    const Vector3d ft = f - f.dot(g) * g;
    EXPECT_NEAR(ft.normalized().dot(-u), 1.0, 1e-12);
    const double stick = ktw * V * in.dt * k, tol = 1e-6 * stick;
    expect_stick_or_slide(ft.norm(), stick, tol, mu_w, fn, f.dot(g), stuck, slid);
    const double dist = w.z()[0];
    EXPECT_NEAR((sphere_test::torque(w, 0) - (-dist * g).cross(ft)).norm(), 0.0, 1e-13 * fn * r);
    EXPECT_NEAR((w.wall(kZMin).force + f).norm(), 0.0, 1e-13 * fn);
    EXPECT_EQ(w.wall(kZMin).contacts, 1);
  }
  EXPECT_GT(stuck, 700);  // μ_w·Fn/(kt_w·V·Δt) = 800 steps
  EXPECT_GT(slid, 600);
}

// An incremental spring belongs to one contact (the 2D kernel's
// KernelContact.WallSpringStartsAtZeroWhenADiskTouchesAgain). Two spheres
// dragged along the z-min wall load its springs (kt_w·2e-7 m = 10 N each);
// lifted off and put back straight down (by less than the skin: they stay
// on the wall's candidate list), they touch with new springs, at zero, and
// with no tangential motion since they carry no tangential force: exactly 0.
// First one sphere leaves while the other stays (a group of candidates
// partly touching), then both (none touching). Mass scaling 1e15: the set
// velocities are the motion.
TEST(SphereContact, WallSpringStartsAtZeroWhenASphereTouchesAgain) {
  const double r = kR, delta = 1e-6, L = 10 * r;  // Fn = 100 N, μ_w·Fn = 40 N
  const SphereMaterial mat = test_material(0.3, 0.4);
  sphere_test::Scene s;
  for (const double x : {-3.0 * r, 3.0 * r}) s.add(Vector3d(x, 0.0, -L + r - delta), r);
  s.lo = {-L, -L, -L};
  s.hi = {L, L, L};
  SphereWorld w = s.make(mat);
  Integration in = sphere_test::set_undamped(w, 0.0, 1e15);
  in.dt = 1e-6;
  w.set_integration(in);
  const Vector3d drag(1e-3, 0.0, 0.0), up(0.0, 0.0, 1e-2);  // 1e-9 m, 1e-8 m a step
  for (int k = 0; k < 200; ++k) {
    for (int i = 0; i < 2; ++i) w.set_velocity(i, drag, Vector3d::Zero());
    ASSERT_TRUE(w.step(1));
  }
  for (int i = 0; i < 2; ++i)
    ASSERT_NEAR(-sphere_test::force(w, i).x(), mat.wall.kt * 2e-7, 1e-6 * mat.wall.kt * 2e-7);
  const int64_t rebuilds = w.rebuilds();
  for (const int leaving : {1, 2}) {  // sphere 1 alone, then both
    SCOPED_TRACE(std::to_string(leaving) + " leaving");
    bool apart = false;
    for (int k = 0; k < 400; ++k) {  // 2e-6 m up, then down again
      for (int i = 2 - leaving; i < 2; ++i)
        w.set_velocity(i, k < 200 ? up : Vector3d(-up), Vector3d::Zero());
      if (leaving == 1) w.set_velocity(0, Vector3d::Zero(), Vector3d::Zero());
      ASSERT_TRUE(w.step(1));
      apart = apart || w.wall(kZMin).contacts == 2 - leaving;
      if (apart) {
        for (int i = 2 - leaving; i < 2; ++i) {
          const Vector3d f = sphere_test::force(w, i);
          ASSERT_EQ(f.x(), 0.0) << "sphere " << i << " step " << k;
          ASSERT_EQ(f.y(), 0.0) << "sphere " << i << " step " << k;
        }
      }
    }
    EXPECT_TRUE(apart);
    ASSERT_EQ(w.wall(kZMin).contacts, 2);
    if (leaving == 1) {  // the sphere that stayed kept its spring
      EXPECT_NEAR(-sphere_test::force(w, 0).x(), mat.wall.kt * 2e-7, 1e-6 * mat.wall.kt * 2e-7);
    }
  }
  EXPECT_EQ(w.rebuilds(), rebuilds);  // the same lists throughout
}

// The same law on each of the six walls, with the sphere spinning too: the
// wall pass writes each wall along its own axis a and the two others, so
// a slip of the contact point v_s = v + ω × (−dist·g) (g the inward
// normal) tests every axis and sign. The spring gives F_t = −kt_w·v_s·t
// while below μ_w·Fn, then μ_w·Fn along −v_s; Fn = kn_w·δ along g; the
// torque is (−dist·g) × F_t; the wall feels −F. Mass scaling 1e15 keeps v
// and ω constant to < 1e-6 relative.
TEST(SphereContact, WallFrictionOnEveryWallWithSpin) {
  const double mu_w = 0.4, r = kR, delta = 1e-6, V = 1e-3, L = 10 * r;
  const SphereMaterial mat = test_material(0.3, mu_w);
  for (int side = 0; side < 6; ++side) {
    SCOPED_TRACE("wall " + std::to_string(side));
    const int a = side / 2, b = (a + 1) % 3, c = (a + 2) % 3;
    const double sign = (side % 2 == 0) ? 1.0 : -1.0;
    const Vector3d g = sign * Vector3d::Unit(a);
    SphereWorld w = sphere_test::sphere_on_wall(mat, side, delta, L);
    const Integration in = w.integration();
    const Vector3d v = V * (Vector3d::Unit(b) - 2.0 * Vector3d::Unit(c)).normalized();
    // A spin about all three axes: about each of the wall's two tangents it
    // rolls the contact point along the other; about the normal, nothing.
    const Vector3d omega =
        (V / r) * (0.7 * Vector3d::Unit(b) - 0.4 * Vector3d::Unit(c) + 0.5 * Vector3d::Unit(a));
    w.set_velocity(0, v, omega);
    const Vector3d slip = v + omega.cross(-(r - delta) * g);
    const double fn = mat.wall.kn * delta, ktw = mat.wall.kt;
    // Steps until the spring reaches the cap (500 to 920 here): run twice
    // as many.
    const double k_cap = mu_w * fn / (ktw * slip.norm() * in.dt);
    int stuck = 0, slid = 0;
    for (int k = 1; k <= static_cast<int>(2.0 * k_cap); ++k) {
      ASSERT_TRUE(w.step(1));
      const Vector3d f = sphere_test::force(w, 0);
      EXPECT_NEAR(f.dot(g), fn, 1e-6 * fn);
      const Vector3d ft = f - f.dot(g) * g;
      EXPECT_NEAR(ft.normalized().dot(-slip.normalized()), 1.0, 1e-9);
      const double stick = ktw * slip.norm() * in.dt * k, tol = 1e-6 * stick;
      expect_stick_or_slide(ft.norm(), stick, tol, mu_w, fn, f.dot(g), stuck, slid);
      const double dist = (sphere_test::position(w, 0)[a] + sign * L) * sign;
      EXPECT_NEAR((sphere_test::torque(w, 0) - (-dist * g).cross(ft)).norm(), 0.0, 1e-13 * fn * r);
      const SphereWall& wall = w.wall(static_cast<SphereWallSide>(side));
      EXPECT_NEAR((wall.force + f).norm(), 0.0, 1e-13 * fn);
      EXPECT_EQ(wall.contacts, 1);
    }
    EXPECT_GT(stuck, 0.9 * k_cap);
    EXPECT_GT(slid, 0.9 * k_cap);
  }
}

// A frictionless wall (μ_w = 0, the shipped scenes' walls) exerts the
// normal force alone, whatever the slip and spin: the tangential force and
// the torque are exactly 0 on every wall — also for a slip so small that
// the trial history's square underflows to 0 (1e-165 m/s here: kt_w·v·Δt
// = 5e-164 N, squared below the smallest double), where a Coulomb cap
// compared in squares would let the trial force through.
TEST(SphereContact, FrictionlessWallsExertNoTangentialForce) {
  const double r = kR, delta = 1e-6, L = 10 * r;
  const SphereMaterial mat = test_material(0.3, 0.0);
  for (const double V : {1e-3, 1e-165})
    for (int side = 0; side < 6; ++side) {
      SCOPED_TRACE(testing::Message() << "wall " << side << ", slip " << V << " m/s");
      const int a = side / 2;
      const double sign = (side % 2 == 0) ? 1.0 : -1.0;
      const Vector3d g = sign * Vector3d::Unit(a);
      const Vector3d e_b = Vector3d::Unit((a + 1) % 3), e_c = Vector3d::Unit((a + 2) % 3);
      SphereWorld w = sphere_test::sphere_on_wall(mat, side, delta, L);
      w.set_velocity(0, V * (e_b - 2.0 * e_c).normalized(), (0.7 * V / r) * e_b);
      const double fn = mat.wall.kn * delta;
      for (int k = 1; k <= 50; ++k) {
        ASSERT_TRUE(w.step(1));
        const Vector3d f = sphere_test::force(w, 0);
        EXPECT_NEAR(f.dot(g), fn, 1e-6 * fn);
        EXPECT_EQ(f.dot(e_b), 0.0);
        EXPECT_EQ(f.dot(e_c), 0.0);
        EXPECT_EQ(sphere_test::torque(w, 0), Vector3d::Zero());
        const SphereWall& wall = w.wall(static_cast<SphereWallSide>(side));
        EXPECT_EQ(wall.force, -f);
        EXPECT_EQ(wall.contacts, 1);
      }
    }
}

}  // namespace
}  // namespace demcal
