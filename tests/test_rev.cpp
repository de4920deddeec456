// The REV (issue #6 §1): exact disk–rectangle areas, the KS distance,
// packing statistics on a lattice whose answers are known, cutting and
// generating REVs from a prototype, and the representativeness verdict.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/upscaling/rev.hpp"
#include "support/files.hpp"

namespace demcal {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(DiskRectangleArea, KnownCases) {
  const double r = 2.0, full = kPi * r * r;
  EXPECT_NEAR(disk_rectangle_area(0, 0, r, -5, 5, -5, 5), full, 1e-12);
  EXPECT_EQ(disk_rectangle_area(0, 0, r, 3, 5, -5, 5), 0.0);
  EXPECT_NEAR(disk_rectangle_area(0, 0, r, 0, 5, -5, 5), full / 2, 1e-12);  // half
  EXPECT_NEAR(disk_rectangle_area(0, 0, r, 0, 5, 0, 5), full / 4, 1e-12);   // quadrant
  EXPECT_NEAR(disk_rectangle_area(0, 0, r, -5, 5, -5, 1),
              full - (r * r * std::acos(0.5) - 1.0 * std::sqrt(3.0)),
              1e-12);  // a circular segment cut off
  // Against a fine grid count for an awkward window.
  const double x0 = -0.7, x1 = 1.3, y0 = -1.9, y1 = 0.4;
  const int n = 2000;
  double inside = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = x0 + (i + 0.5) * (x1 - x0) / n, y = y0 + (j + 0.5) * (y1 - y0) / n;
      inside += x * x + y * y < r * r;
    }
  const double grid = inside * (x1 - x0) * (y1 - y0) / (double(n) * n);
  EXPECT_NEAR(disk_rectangle_area(0, 0, r, x0, x1, y0, y1), grid, 2e-4);
}

TEST(KsDistance, IdenticalDisjointAndShifted) {
  EXPECT_EQ(ks_distance({1, 2, 3}, {3, 2, 1}), 0.0);
  EXPECT_EQ(ks_distance({1, 2, 3}, {4, 5, 6}), 1.0);
  EXPECT_NEAR(ks_distance({1, 2, 3, 4}, {3, 4, 5, 6}), 0.5, 1e-12);
}

TEST(PackingStats, HexagonalLattice) {
  // Interior of a hexagonal packing: porosity 1 − π/(2√3), six contacts.
  const Assembly a = hexagonal_packing(30, 30, 1e-3);
  const PackingStats s = packing_stats(a);
  EXPECT_EQ(s.particles, 900);
  EXPECT_NEAR(s.porosity_interior, 1.0 - kPi / (2.0 * std::sqrt(3.0)), 0.01);
  EXPECT_GT(s.porosity, s.porosity_interior);  // the wall voids
  // (a disk centred exactly on the window's edge may miss a neighbour)
  EXPECT_NEAR(s.coordination_interior, 6.0, 0.05);
  EXPECT_LT(s.coordination, 6.0);  // the boundary disks have fewer
  EXPECT_NEAR(s.radius_mean, 1e-3, 1e-15);
  EXPECT_NEAR(s.radius_std, 0.0, 1e-15);
}

TEST(Rev, CutHoldsAboutTheCountAndStaysInsideThePrototype) {
  const Assembly proto = hexagonal_packing(40, 40, 5e-4);
  for (int count : {25, 100, 400}) {
    SCOPED_TRACE(count);
    const Assembly rev = cut_rev(proto, count);
    // A lattice's rows enter the window together: a row's worth of slack.
    EXPECT_NEAR(rev.size(), count, std::max(0.15 * count, 6.0));
    EXPECT_TRUE(rev.dense);
    for (int i = 0; i < rev.size(); ++i) {
      EXPECT_GE(rev.x[i] - rev.r[i], rev.left - 1e-15);
      EXPECT_LE(rev.y[i] + rev.r[i], rev.top + 1e-15);
    }
  }
  EXPECT_THROW(cut_rev(proto, 5000), InputError);
}

// A consolidated lattice keeps its rows only to within about an overlap:
// rounding orders a row's centres, and the cut must not split a row
// (cut_window.hpp; the sphere test has the failure it caused). The same
// count as on the exact lattice.
TEST(Rev, CutGoesBetweenTheRowsOfAConsolidatedLattice) {
  const Assembly exact = hexagonal_packing(40, 40, 5e-4);
  Assembly proto = exact;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> jitter(-2.5e-7 * 5e-4, 2.5e-7 * 5e-4);
  for (auto* c : {&proto.x, &proto.y})
    for (double& v : *c) v += jitter(rng);
  for (int asked : {25, 100, 170, 400}) {
    SCOPED_TRACE(asked);
    const int whole = cut_rev(exact, asked).size();
    EXPECT_EQ(cut_rev(proto, asked).size(), whole);
  }
}

TEST(Rev, GenerateDrawsTheRadiiFromThePrototype) {
  AssemblySpec spec;
  spec.type = "random";
  spec.count = 300;
  const Assembly proto = random_gas(spec);
  const Assembly rev = generate_rev(proto, 120, 7);
  EXPECT_EQ(rev.size(), 120);
  EXPECT_FALSE(rev.dense);
  for (double r : rev.r) EXPECT_NE(std::find(proto.r.begin(), proto.r.end(), r), proto.r.end());
  EXPECT_LT(ks_distance(rev.r, proto.r), 1.358 * std::sqrt((120.0 + 300.0) / (120.0 * 300.0)));
  // No overlaps in the gas.
  for (int i = 0; i < rev.size(); ++i)
    for (int j = i + 1; j < rev.size(); ++j)
      EXPECT_GE(std::hypot(rev.x[i] - rev.x[j], rev.y[i] - rev.y[j]), rev.r[i] + rev.r[j]);
}

TEST(Rev, CutFromALatticeIsRepresentativeAfterReconsolidation) {
  SceneConfig c = default_config();
  const Assembly proto = hexagonal_packing(30, 30, 5e-4);
  RevOptions o;
  o.particles = 100;
  const RevResult r = make_rev(c, proto, o);
  EXPECT_TRUE(r.state.converged);
  EXPECT_EQ(r.method, "cut");
  const auto& rep = r.representativeness;
  EXPECT_EQ(rep.ks, 0.0);
  EXPECT_TRUE(rep.size_distribution_ok);
  EXPECT_TRUE(rep.porosity_ok) << rep.verdict;
  EXPECT_TRUE(rep.coordination_ok) << rep.verdict;
  EXPECT_TRUE(rep.representative) << rep.verdict;
  // The report says why.
  EXPECT_NE(rep.verdict.find("representative"), std::string::npos);
  const nlohmann::json j = to_json(rep);
  EXPECT_TRUE(j["representative"].get<bool>());
  EXPECT_EQ(j["rev"]["particles"].get<int>(), r.assembly.size());
}

TEST(Rev, AWrongSizeDistributionIsCaught) {
  PackingStats a, b;
  a.porosity_interior = b.porosity_interior = 0.15;
  a.coordination_interior = b.coordination_interior = 3.8;
  std::vector<double> small(200, 1.0), large(200, 2.0);
  const Representativeness r = compare(a, b, small, large);
  EXPECT_FALSE(r.size_distribution_ok);
  EXPECT_FALSE(r.representative);
  b.porosity_interior = 0.2;
  const Representativeness p = compare(a, b, small, small);
  EXPECT_TRUE(p.size_distribution_ok);
  EXPECT_FALSE(p.porosity_ok);
}

TEST(Rev, MirrorTilingMakesSeamsTouch) {
  AssemblySpec spec;
  spec.type = "random";
  spec.count = 60;
  SceneConfig c = default_config();
  c.assembly = spec;
  const Assembly a = assembly_of(consolidate(c, random_gas(spec)).world);
  const Assembly t = tile_mirrored(a, 2, 3);
  EXPECT_EQ(t.size(), 6 * a.size());
  EXPECT_NEAR(t.right - t.left, 2 * (a.right - a.left), 1e-15);
  EXPECT_NEAR(t.top - t.bottom, 3 * (a.top - a.bottom), 1e-15);
  EXPECT_EQ(t.r[a.size() + 5], a.r[5]);
  // No overlap beyond the wall overlaps that met at a seam, and every
  // seam has contacts across it (coordination as inside a tile).
  const PackingStats st = packing_stats(t), sa = packing_stats(a);
  for (int i = 0; i < t.size(); ++i)
    for (int j = i + 1; j < t.size(); ++j)
      ASSERT_GT(std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]), 0.98 * (t.r[i] + t.r[j]));
  EXPECT_GT(st.coordination, sa.coordination);
  EXPECT_THROW(tile_mirrored(a, 0, 1), InputError);
}

TEST(Rev, ParticleCsvRoundTrips) {
  const Assembly a = hexagonal_packing(4, 3, 1e-3);
  const test::TempDir dir("rev");
  const std::string path = test::write_text(dir / "particles.csv", particle_csv(a));
  const Assembly b = read_particle_file(path);
  ASSERT_EQ(b.size(), a.size());
  for (int i = 0; i < a.size(); ++i) {
    EXPECT_EQ(b.x[i], a.x[i]);
    EXPECT_EQ(b.y[i], a.y[i]);
    EXPECT_EQ(b.r[i], a.r[i]);
  }
}

}  // namespace
}  // namespace demcal
