// The FCC generator and the contact counting behind the walled peak
// (src/scene/sphere_packing.cpp).
#include <gtest/gtest.h>

#include <cmath>

#include "demcal/scene/sphere_packing.hpp"
#include "test_sphere_helpers.hpp"

namespace demcal {
namespace {

using sphere_test::kR;

TEST(SpherePacking, FccLatticeTouchesItsNeighboursAndTheWalls) {
  const int nx = 2, ny = 3, nz = 4;
  const double eps = 1e-4;
  const SphereAssembly a = fcc_packing(nx, ny, nz, kR, eps);
  ASSERT_EQ(a.size(), 4 * nx * ny * nz);
  const double contact = 2.0 * kR * (1.0 - eps);
  std::vector<int> neighbours(a.size(), 0);
  int pairs = 0;
  for (int i = 0; i < a.size(); ++i)
    for (int j = i + 1; j < a.size(); ++j) {
      const double d = std::sqrt(std::pow(a.x[j] - a.x[i], 2) + std::pow(a.y[j] - a.y[i], 2) +
                                 std::pow(a.z[j] - a.z[i], 2));
      EXPECT_GE(d, contact * (1.0 - 1e-12));  // nothing closer than the lattice contacts
      if (d < contact * (1.0 + 1e-12)) {
        ++pairs;
        ++neighbours[i];
        ++neighbours[j];
      }
    }
  // Interior spheres have the 12 FCC neighbours; nobody has more.
  EXPECT_EQ(*std::max_element(neighbours.begin(), neighbours.end()), 12);
  // Pairs along <110>: for each of the 6 directions (±1, ±1, 0) etc. the
  // sites whose neighbour lies inside the box; e.g. (1, 1, 0): i < 2nx − 1,
  // j < 2ny − 1, every k, i + j + k even → (2nx − 1)(2ny − 1)(2nz)/2 sites
  // (each count is even in one factor, so the halving is exact).
  auto count = [](int p, int q, int r) { return p * q * r / 2; };
  const int expected =
      2 * (count(2 * nx - 1, 2 * ny - 1, 2 * nz) + count(2 * nx - 1, 2 * ny, 2 * nz - 1) +
           count(2 * nx, 2 * ny - 1, 2 * nz - 1));
  EXPECT_EQ(pairs, expected);
  // Each wall overlaps the outermost spheres by 2rε.
  double min_x = 1e9, max_z = -1e9;
  for (int i = 0; i < a.size(); ++i) {
    min_x = std::min(min_x, a.x[i]);
    max_z = std::max(max_z, a.z[i]);
  }
  EXPECT_NEAR(kR - (min_x - a.lo[0]), 2.0 * kR * eps, 1e-12 * kR);
  EXPECT_NEAR(kR - (a.hi[2] - max_z), 2.0 * kR * eps, 1e-12 * kR);
}

// The walled peak counts the inclined contacts crossing a horizontal and a
// vertical cut; here they are counted on the generated lattice of a
// non-cubic box and the ratio rebuilt from the counts.
TEST(SpherePacking, WalledFccPeakMatchesContactsCountedOnTheLattice) {
  const int nx = 2, ny = 3, nz = 4;
  const double mu = 0.3;
  const SphereAssembly a = fcc_packing(nx, ny, nz, kR);
  const double half = std::sqrt(2.0) * kR;
  // Cut between site planes k = 2 and 3 (z), and between i = 1 and 2 (x).
  const double z_cut = kR + 2.5 * half, x_cut = kR + 1.5 * half;
  int vertical = 0, lateral = 0;
  for (int i = 0; i < a.size(); ++i)
    for (int j = 0; j < a.size(); ++j) {
      const double dx = a.x[j] - a.x[i], dy = a.y[j] - a.y[i], dz = a.z[j] - a.z[i];
      if (std::abs(std::sqrt(dx * dx + dy * dy + dz * dz) - 2.0 * kR) > 1e-9 * kR) continue;
      if (a.z[i] < z_cut && a.z[j] > z_cut) ++vertical;  // inclined, upward
      if (a.x[i] < x_cut && a.x[j] > x_cut && std::abs(dz) > 0.5 * half) ++lateral;  // xz only
    }
  EXPECT_EQ(vertical, 2 * ny * (2 * nx - 1) + 2 * nx * (2 * ny - 1));
  EXPECT_EQ(lateral, 2 * ny * (2 * nz - 1));
  const double lx = a.hi[0] - a.lo[0], ly = a.hi[1] - a.lo[1], lz = a.hi[2] - a.lo[2];
  // σ_zz = vertical·(N + T)/√2/(Lx·Ly), σ_xx = lateral·(N − T)/√2/(Ly·Lz).
  const double ratio = (vertical / (lx * ly)) / (lateral / (ly * lz)) * (1.0 + mu) / (1.0 - mu);
  EXPECT_NEAR(fcc_peak_ratio_walled(mu, nx, ny, nz), ratio, 1e-12 * ratio);
  // A cube: exactly the periodic value; other boxes tend to it as O(1/n)
  // (each count and length differs from the periodic one by O(1) in O(n)).
  EXPECT_NEAR(fcc_peak_ratio_walled(mu, 3, 3, 3), fcc_peak_ratio(mu), 1e-12);
  EXPECT_NEAR(fcc_peak_ratio_walled(mu, 200, 200, 100), fcc_peak_ratio(mu),
              fcc_peak_ratio(mu) / 100.0);
  EXPECT_LT(std::abs(fcc_peak_ratio_walled(mu, 400, 400, 200) - fcc_peak_ratio(mu)),
            std::abs(fcc_peak_ratio_walled(mu, 200, 200, 100) - fcc_peak_ratio(mu)));
  EXPECT_NEAR(fcc_peak_ratio(0.3), 2.0 * 1.3 / 0.7, 1e-15);
}

}  // namespace
}  // namespace demcal
