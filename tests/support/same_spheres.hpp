// Two sphere worlds compared bit for bit through their public face (the
// thread, cache and state tests).
#pragma once

#include <gtest/gtest.h>

#include "demcal/kernel/sphere_world.hpp"
#include "support/same_bits.hpp"

namespace demcal::test {

/// Two spheres' worlds compared through their public face, bit for bit:
/// every sphere's position, velocity, spin, force and torque, every contact
/// (its normal and tangential force: the history), the walls, the stresses
/// and the energy ledger.
inline void expect_same_spheres(const SphereWorld& a, const SphereWorld& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.steps_taken(), b.steps_taken());
  EXPECT_EQ(a.rebuilds(), b.rebuilds());
  int mismatches = 0;
  for (int i = 0; i < a.size(); ++i) {
    bool same = true;
    for (auto f : {&SphereWorld::x, &SphereWorld::y, &SphereWorld::z, &SphereWorld::vx,
                   &SphereWorld::vy, &SphereWorld::vz, &SphereWorld::omega_x, &SphereWorld::omega_y,
                   &SphereWorld::omega_z, &SphereWorld::fx, &SphereWorld::fy, &SphereWorld::fz,
                   &SphereWorld::torque_x, &SphereWorld::torque_y, &SphereWorld::torque_z})
      same = same && same_bits((a.*f)()[i], (b.*f)()[i]);
    if (!same && ++mismatches <= 5) ADD_FAILURE() << "sphere " << i << " differs";
  }
  EXPECT_EQ(mismatches, 0);
  test::expect_same_contacts(a.contacts(), b.contacts(), [](const auto& ca, const auto& cb) {
    bool same = same_bits(ca.fn, cb.fn) && same_bits(ca.overlap, cb.overlap);
    for (int c = 0; c < 3; ++c) same = same && same_bits(ca.tangential[c], cb.tangential[c]);
    return same;
  });
  test::expect_same_walls<SphereWallSide, 6>(a, b);
  const SphereMeasures ma = a.measure(), mb = b.measure();
  test::expect_same_stresses(ma, mb);
  EXPECT_TRUE(same_bits(ma.kinetic_energy_translation, mb.kinetic_energy_translation));
  EXPECT_TRUE(same_bits(ma.kinetic_energy_rotation, mb.kinetic_energy_rotation));
  EXPECT_TRUE(same_bits(ma.elastic_energy, mb.elastic_energy));
  EXPECT_TRUE(same_bits(a.energy_created(), b.energy_created()));
}

}  // namespace demcal::test
