// Test support: two samples compared bit for bit, for the kernels' promise
// of bit-identical results on any thread count (test_kernel_threads.cpp,
// test_sphere_threads.cpp), in 2D (World) and 3D (SphereWorld) alike.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>

namespace demcal::test {

/// Bitwise equality (distinguishes −0 from +0 and compares NaNs by pattern).
inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Two samples' contact lists: the same pairs in the same order, and
/// same_force(a, b) for each pair of contacts.
template <class Contacts, class SameForce>
void expect_same_contacts(const Contacts& ca, const Contacts& cb, SameForce same_force) {
  ASSERT_EQ(ca.size(), cb.size());
  for (size_t k = 0; k < ca.size(); ++k) {
    ASSERT_EQ(ca[k].i, cb[k].i);
    ASSERT_EQ(ca[k].j, cb[k].j);
    EXPECT_TRUE(same_force(ca[k], cb[k])) << "contact " << k;
  }
}

/// The `walls` walls (of type Side) of two samples: position, each force
/// component and the contact count.
template <class Side, int walls, class Sample>
void expect_same_walls(const Sample& a, const Sample& b) {
  for (int s = 0; s < walls; ++s) {
    const auto &wa = a.wall(static_cast<Side>(s)), &wb = b.wall(static_cast<Side>(s));
    EXPECT_TRUE(same_bits(wa.position, wb.position)) << "wall " << s;
    for (int c = 0; c < wa.force.size(); ++c)
      EXPECT_TRUE(same_bits(wa.force[c], wb.force[c])) << "wall " << s;
    EXPECT_EQ(wa.contacts, wb.contacts);
  }
}

/// Every component of the homogenized and the boundary stress of two
/// samples' measures.
template <class Measures>
void expect_same_stresses(const Measures& a, const Measures& b) {
  for (int r = 0; r < a.homogenized_stress.rows(); ++r)
    for (int c = 0; c < a.homogenized_stress.cols(); ++c) {
      EXPECT_TRUE(same_bits(a.homogenized_stress(r, c), b.homogenized_stress(r, c)));
      EXPECT_TRUE(same_bits(a.boundary_stress(r, c), b.boundary_stress(r, c)));
    }
}

}  // namespace demcal::test
