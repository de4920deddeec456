// Threads (KernelOptions::threads): the kernel must give bit-identical
// results for any thread count. Every particle's force is summed by one
// thread, over its own neighbours in a fixed order, so the partition of the
// blocks among threads cannot change a single bit. Checked on a dense
// frictional packing over many steps, through neighbour-list rebuilds,
// against one thread: positions, velocities, spins, forces, torques, every
// contact force, wall forces and the stress measures.
#include <gtest/gtest.h>

#include <vector>

#include "support/same_bits.hpp"
#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using test::same_bits;

void expect_identical(const World& a, const World& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.steps_taken(), b.steps_taken());
  EXPECT_EQ(a.rebuilds(), b.rebuilds());
  int mismatches = 0;
  for (int i = 0; i < a.size(); ++i) {
    const bool same = same_bits(a.x()[i], b.x()[i]) && same_bits(a.y()[i], b.y()[i]) &&
                      same_bits(a.vx()[i], b.vx()[i]) && same_bits(a.vy()[i], b.vy()[i]) &&
                      same_bits(a.omega()[i], b.omega()[i]) &&
                      same_bits(a.rotation()[i], b.rotation()[i]) &&
                      same_bits(a.fx()[i], b.fx()[i]) && same_bits(a.fy()[i], b.fy()[i]) &&
                      same_bits(a.torque()[i], b.torque()[i]);
    if (!same && ++mismatches <= 5) ADD_FAILURE() << "particle " << i << " differs";
  }
  EXPECT_EQ(mismatches, 0);
  test::expect_same_contacts(a.contacts(), b.contacts(), [](const auto& ca, const auto& cb) {
    return same_bits(ca.fn, cb.fn) && same_bits(ca.ft, cb.ft);
  });
  test::expect_same_walls<WallSide, 4>(a, b);
  const Measures ma = a.measure(), mb = b.measure();
  test::expect_same_stresses(ma, mb);
  EXPECT_TRUE(same_bits(ma.kinetic_energy_translation, mb.kinetic_energy_translation));
  EXPECT_TRUE(same_bits(ma.elastic_energy, mb.elastic_energy));
}

// 30 × 30 polydisperse disks jammed with friction on the walls too (once,
// on one thread).
const World& jammed(double contact_damping) {
  auto make = [](double damping) {
    Material mat = kernel_test::reference_material(0.3, 0.2);
    mat.contact_damping_ratio = damping;
    auto scene = kernel_test::random_loose_scene(30, 30, 7);
    World w = scene.make(mat);
    kernel_test::compact(w, 0.84, 0.3, 500);
    return w;
  };
  static const World plain = make(0.0), damped = make(0.2);
  return contact_damping > 0.0 ? damped : plain;
}

// Shear the jammed packing (top wall down, side walls out) with light
// damping on `threads` threads: contacts open, close and slide, and the
// neighbour list is rebuilt many times.
World sheared(const World& start, int threads, int64_t steps) {
  World w = start;
  w.set_threads(threads);
  Integration in = w.integration();
  in.damping_ratio_translation = 0.1;
  in.damping_ratio_rotation = 0.1;
  w.set_integration(in);
  const double v = 5e-4 * kernel_test::kR / in.dt;
  w.wall(kTop).velocity = -v;
  w.wall(kLeft).velocity = -0.3 * v;
  w.wall(kRight).velocity = 0.3 * v;
  EXPECT_TRUE(w.step(steps)) << to_string(w.divergence());
  return w;
}

TEST(KernelThreads, TwoAndThreeThreadsGiveBitIdenticalResultsToOne) {
  const World& start = jammed(0.0);
  const World one = sheared(start, 1, 4000);
  ASSERT_GT(one.measure().particle_contacts, 1000);
  ASSERT_GE(one.rebuilds() - start.rebuilds(), 5);  // the list was rebuilt during the run
  const World two = sheared(start, 2, 4000);
  EXPECT_EQ(two.threads(), 2);
  expect_identical(one, two);
  const World three = sheared(start, 3, 4000);
  expect_identical(one, three);
}

TEST(KernelThreads, ContactDampingIsBitIdenticalToo) {
  const World& start = jammed(0.2);
  const World one = sheared(start, 1, 2000);
  const World two = sheared(start, 2, 2000);
  expect_identical(one, two);
}

TEST(KernelThreads, CopiesAndThreadChangesMidRunKeepTheTrajectory) {
  World a = sheared(jammed(0.0), 1, 500);
  World b = a;  // a copy does not share threads; give it two of its own
  b.set_threads(2);
  World c = b;  // copy of a threaded world
  ASSERT_TRUE(a.step(2000));
  ASSERT_TRUE(b.step(1000));
  b.set_threads(1);
  ASSERT_TRUE(b.step(1000));
  ASSERT_TRUE(c.step(2000));
  expect_identical(a, b);
  expect_identical(a, c);
}

}  // namespace
}  // namespace demcal
