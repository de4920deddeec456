// Packings (issue #3): the lattice and random generators, the particle-file
// reader with its errors (issue #9 §1), and the hexagonal analytical peak.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>
#include <optional>
#include <string>

#include "demcal/scene/packing.hpp"
#include "support/files.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

/// A fresh folder per test, removed afterwards.
class PackingFile : public ::testing::Test {
 protected:
  std::string write(const std::string& content, const std::string& name = "p.csv") {
    return test::write_text(dir_ / name, content);
  }
  /// Reading `content` fails naming the file and `field`.
  void expect_rejected(const std::string& content, const std::string& field,
                       const std::string& in_message = "") {
    SCOPED_TRACE(content);
    const std::string path = write(content);
    try {
      read_particle_file(path);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
      if (!in_message.empty()) {
        EXPECT_NE(std::string(e.what()).find(in_message), std::string::npos) << e.what();
      }
    }
  }
  test::TempDir tmp_{"packing"};
  const fs::path dir_ = tmp_.path();
};

TEST_F(PackingFile, HeaderIsOptional) {
  const Assembly with = read_particle_file(write("x,y,r\n0,0,1\n2,0,1\n"));
  const Assembly without = read_particle_file(write("0,0,1\n2,0,1\n"));
  ASSERT_EQ(with.size(), 2);
  EXPECT_EQ(with.x, without.x);
  EXPECT_EQ(with.r, without.r);
  // Walls at the bounding box.
  EXPECT_EQ(with.left, -1.0);
  EXPECT_EQ(with.right, 3.0);
  EXPECT_EQ(with.bottom, -1.0);
  EXPECT_EQ(with.top, 1.0);
  EXPECT_TRUE(with.dense);
}

// The header is the first line that is not blank or a comment, wherever it
// is (the reader used to accept it on line 1 only).
TEST_F(PackingFile, HeaderAfterCommentsAndBlankLines) {
  const Assembly a =
      read_particle_file(write("# exported by tool\n\n  # units: m\nx, y, radius\n0,0,1\n2,0,1\n"));
  EXPECT_EQ(a.size(), 2);
}

TEST_F(PackingFile, CommentsBlanksCrlfBomAndSpaces) {
  const Assembly a = read_particle_file(write(
      "\xEF\xBB\xBFx,y,r\r\n# comment\r\n\r\n 0 , 0 ,1\r\n\t2,0, 1 \r\n   \r\n4e0,0,1e0\r\n"));
  ASSERT_EQ(a.size(), 3);
  EXPECT_EQ(a.x, (std::vector<double>{0, 2, 4}));
  EXPECT_EQ(a.r, (std::vector<double>{1, 1, 1}));
  const Assembly no_final_newline = read_particle_file(write("0,0,1\n2,0,1"));
  EXPECT_EQ(no_final_newline.size(), 2);
}

TEST_F(PackingFile, NonNumericLineNamesTheLine) {
  expect_rejected("x,y,r\n0,0,1\n2,zero,1\n", "line 3", "2,zero,1");
  expect_rejected("0,0,1\n2,0\n", "line 2");           // two fields
  expect_rejected("0,0,1\n2,0,1,7\n", "line 2");       // four fields
  expect_rejected("0,0,1\n2 0 1\n", "line 2");         // not comma separated
  expect_rejected("0,0,1\n2,0,1x\n", "line 2");        // trailing garbage
  expect_rejected("0,0,1\nx,y,r\n2,0,1\n", "line 2");  // a header after data
  expect_rejected("x,y,r\nx,y,r\n0,0,1\n2,0,1\n", "line 2");
  // A header in another order is refused: the axes are never guessed.
  expect_rejected("y,x,r\n0,0,1\n2,0,1\n", "line 1", "x,y,r in this order");
  expect_rejected("# c\nr,x,y\n1,0,0\n1,2,0\n", "line 2", "got \"r,x,y\"");
  // A first line with some numbers is a broken particle, not a header: it
  // must not be skipped silently.
  expect_rejected("0,0,abc\n2,0,1\n4,0,1\n", "line 1");
  expect_rejected("# c\n0,0,abc\n2,0,1\n4,0,1\n", "line 2");
}

TEST_F(PackingFile, RadiusMustBePositive) {
  expect_rejected("0,0,1\n2,0,0\n", "line 2", "radius");
  expect_rejected("# c\n0,0,1\n2,0,-1\n", "line 3", "radius");
}

TEST_F(PackingFile, NonFiniteValues) {
  expect_rejected("0,0,1\nnan,0,1\n", "line 2", "finite");
  expect_rejected("0,0,1\n2,inf,1\n", "line 2", "finite");
  expect_rejected("0,0,1\n2,0,1e999\n", "line 2", "finite");  // strtod overflows to inf
  expect_rejected("0,0,1\n-1e999,0,1\n", "line 2", "finite");
}

TEST_F(PackingFile, OverlapBeyondFivePercentNamesTheLines) {
  // Radii 1 and 2 at distance 3 − 0.06 overlap 6 % of the smaller radius;
  // the comment and the header shift the lines: the error names the file's
  // lines, not the particle numbers.
  expect_rejected("# c\nx,y,r\n10,10,1\n0,0,1\n2.94,0,2\n", "line 5", "line 4");
  // 4 % is tolerated (a packing written at rest under load overlaps a bit).
  const Assembly a = read_particle_file(write("0,0,1\n2.96,0,2\n"));
  EXPECT_EQ(a.size(), 2);
  // The same disk twice.
  expect_rejected("0,0,1\n5,5,1\n0,0,1\n", "line 3", "line 1");
}

TEST_F(PackingFile, OverlapFoundAcrossCellsAndInLargeFiles) {
  // 400 disks on a touching square lattice, then one intruder.
  std::string content = "x,y,r\n";
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      content += std::to_string(2.0 * i) + "," + std::to_string(2.0 * j) + ",1\n";
  EXPECT_EQ(read_particle_file(write(content)).size(), 400);
  expect_rejected(content + "21,21,0.5\n", "line 402");
}

// Regression: a sparse, huge domain once overflowed the overlap check's
// integer cell keys. Far-apart disks are valid; a span beyond a double is
// rejected with a message, not undefined behaviour.
TEST_F(PackingFile, HugeCoordinatesDoNotOverflowTheCellGrid) {
  EXPECT_EQ(read_particle_file(write("0,0,1\n1e300,1e300,1\n3,0,1\n")).size(), 3);
  expect_rejected("0,0,1\n1e300,1e300,1\n1e300,1e300,1\n", "line 3");  // coincident pair found
  expect_rejected("-1.5e308,0,1\n1.5e308,0,1\n", "", "span");
}

TEST_F(PackingFile, FewerThanTwoParticles) {
  expect_rejected("", "", "two particles");
  expect_rejected("x,y,r\n", "", "two particles");
  expect_rejected("# only\n0,0,1\n", "", "two particles");
}

TEST_F(PackingFile, MissingFileAndConfigDispatch) {
  const std::string missing = (dir_ / "missing.csv").string();
  try {
    read_particle_file(missing);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), missing);
  }
  // make_assembly reads the config's file, resolved against the config.
  write("0,0,1e-3\n2e-3,0,1e-3\n4e-3,0,1e-3\n");
  const SceneConfig c = parse_config_text(
      "{" + test::kMaterialMember + R"(, "assembly": {"type": "file", "file": "p.csv"}})",
      (dir_ / "scene.json").string());
  EXPECT_EQ(make_assembly(c).size(), 3);
}

// --- lattices ---------------------------------------------------------------

double min_gap(const Assembly& a) {
  double gap = std::numeric_limits<double>::infinity();
  for (int i = 0; i < a.size(); ++i)
    for (int j = i + 1; j < a.size(); ++j)
      gap = std::min(gap, std::hypot(a.x[i] - a.x[j], a.y[i] - a.y[j]) - a.r[i] - a.r[j]);
  return gap;
}

bool inside(const Assembly& a, double slack) {
  for (int i = 0; i < a.size(); ++i)
    if (a.x[i] - a.r[i] < a.left - slack || a.x[i] + a.r[i] > a.right + slack ||
        a.y[i] - a.r[i] < a.bottom - slack || a.y[i] + a.r[i] > a.top + slack)
      return false;
  return true;
}

TEST(PackingLattice, HexagonalGeometry) {
  const double r = 5e-4;
  const Assembly a = hexagonal_packing(5, 4, r);
  ASSERT_EQ(a.size(), 20);
  EXPECT_NEAR(a.right - a.left, 11 * r, 1e-15);  // (2c + 1)·r
  EXPECT_NEAR(a.top - a.bottom, (2 + 3 * std::sqrt(3.0)) * r, 1e-15);
  EXPECT_NEAR(min_gap(a), 0.0, 1e-15);  // touching, no overlap
  EXPECT_TRUE(inside(a, 1e-15));
  // Six neighbours for an interior disk (row 1, column 2).
  int neighbours = 0;
  for (int j = 0; j < a.size(); ++j)
    if (j != 7 && std::hypot(a.x[7] - a.x[j], a.y[7] - a.y[j]) < 2 * r * (1 + 1e-9)) ++neighbours;
  EXPECT_EQ(neighbours, 6);
}

// Pre-compressed (ε = 1e-3): every lattice contact and each wall contact
// overlaps by 2rε; the box shrinks by (1 − ε).
TEST(PackingLattice, PrecompressedHexagonalOverlapsEverywhereBy2rEps) {
  const double r = 5e-4, eps = 1e-3, overlap = 2 * r * eps;
  const Assembly a = hexagonal_packing(5, 4, r, eps);
  EXPECT_NEAR(a.right - a.left, 11 * r * (1 - eps) - overlap, 1e-15);
  EXPECT_NEAR(min_gap(a), -overlap, 1e-15);
  for (int i = 0; i < a.size(); ++i)
    for (int j = i + 1; j < a.size(); ++j) {
      const double gap = std::hypot(a.x[i] - a.x[j], a.y[i] - a.y[j]) - 2 * r;
      if (gap < r) {  // a lattice neighbour
        EXPECT_NEAR(gap, -overlap, 1e-15);
      }
    }
  EXPECT_NEAR(a.x[0] - r - a.left, -overlap, 1e-15);
  EXPECT_NEAR(a.y[0] - r - a.bottom, -overlap, 1e-15);
  EXPECT_NEAR(a.right - (a.x[5 + 4] + r), -overlap, 1e-15);  // row 1 is the shifted one
  EXPECT_NEAR(a.top - (a.y[15] + r), -overlap, 1e-15);
}

TEST(PackingLattice, SquareGeometry) {
  const Assembly a = square_packing(4, 3, 1.0);
  ASSERT_EQ(a.size(), 12);
  EXPECT_EQ(a.right, 8.0);
  EXPECT_EQ(a.top, 6.0);
  EXPECT_NEAR(min_gap(a), 0.0, 1e-15);
  EXPECT_TRUE(inside(a, 0.0));
}

// --- the random gas ---------------------------------------------------------

AssemblySpec random_spec(int count, uint64_t seed, const std::string& distribution = "uniform") {
  AssemblySpec s;
  s.type = "random";
  s.count = count;
  s.seed = seed;
  s.distribution = distribution;
  return s;
}

TEST(PackingRandomGas, DeterministicForASeed) {
  const Assembly a = random_gas(random_spec(300, 42)), b = random_gas(random_spec(300, 42));
  EXPECT_EQ(a.x, b.x);  // bit for bit
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.r, b.r);
  EXPECT_EQ(a.right, b.right);
  const Assembly c = random_gas(random_spec(300, 43));
  EXPECT_NE(a.r, c.r);
  EXPECT_NE(a.x, c.x);
  EXPECT_FALSE(a.dense);
}

TEST(PackingRandomGas, UniformRadiiWithinBoundsNoOverlapsInsideTheBox) {
  AssemblySpec s = random_spec(500, 7);
  s.aspect = 2.0;
  const Assembly a = random_gas(s);
  ASSERT_EQ(a.size(), 500);
  for (double r : a.r) {
    EXPECT_GE(r, s.radius_min);
    EXPECT_LT(r, s.radius_max);
  }
  // Spread over the range: the sample mean of U(a, b) with n = 500 is within
  // 5 standard errors of (a + b)/2.
  const double mean = std::accumulate(a.r.begin(), a.r.end(), 0.0) / a.size();
  const double se = (s.radius_max - s.radius_min) / std::sqrt(12.0 * a.size());
  EXPECT_NEAR(mean, 0.5 * (s.radius_min + s.radius_max), 5 * se);
  EXPECT_GT(min_gap(a), 0.0);
  EXPECT_TRUE(inside(a, 0.0));
  EXPECT_GT(a.right - a.left, a.top - a.bottom);  // aspect = width/height > 1
}

TEST(PackingRandomGas, LognormalTruncatedAtThreeSigma) {
  AssemblySpec s = random_spec(2000, 3, "lognormal");
  s.radius_mean = 5e-4;
  s.radius_std = 1.5e-4;
  const Assembly a = random_gas(s);
  const double s2 = std::log(1.0 + (s.radius_std * s.radius_std) / (s.radius_mean * s.radius_mean));
  const double mu = std::log(s.radius_mean) - 0.5 * s2;
  const double lo = std::exp(mu - 3 * std::sqrt(s2)), hi = std::exp(mu + 3 * std::sqrt(s2));
  for (double r : a.r) {
    EXPECT_GE(r, lo);
    EXPECT_LE(r, hi);
  }
  // Mean and spread as asked (truncation at ±3σ of the log changes them by
  // well under 1 %; the sample error of the mean is 0.8 % here).
  const double mean = std::accumulate(a.r.begin(), a.r.end(), 0.0) / a.size();
  double var = 0.0;
  for (double r : a.r) var += (r - mean) * (r - mean);
  const double sd = std::sqrt(var / (a.size() - 1));
  EXPECT_NEAR(mean, s.radius_mean, 0.03 * s.radius_mean);
  EXPECT_NEAR(sd, s.radius_std, 0.1 * s.radius_std);
  EXPECT_GT(min_gap(a), 0.0);
  EXPECT_TRUE(inside(a, 0.0));
  // Zero spread is monodisperse.
  s.radius_std = 0.0;
  for (double r : random_gas(s).r) EXPECT_NEAR(r, s.radius_mean, 1e-15);
}

TEST(PackingRandomGas, MakeAssemblyDispatches) {
  SceneConfig c;
  c.assembly = random_spec(60, 5);
  EXPECT_EQ(make_assembly(c).size(), 60);
  c.assembly.type = "hexagonal";
  c.assembly.columns = 3;
  c.assembly.rows = 2;
  EXPECT_EQ(make_assembly(c).size(), 6);
  c.assembly.type = "square";
  EXPECT_EQ(make_assembly(c).size(), 6);
}

// --- the analytical hexagonal peak -----------------------------------------

// Periodic cell, rotation locked, horizontal rows: sliding at the inclined
// (60°) contacts when f_v/f_h = tan(60° + φ), so σ1/σ3 = tan 60°·tan(60° + φ)
// = (3 + √3 μ)/(1 − √3 μ).
TEST(PackingHexagonalPeak, PeriodicValue) {
  EXPECT_NEAR(hexagonal_peak_ratio(0.3), 7.3267, 5e-5);
  for (double mu : {0.0, 0.1, 0.3, 0.5})
    EXPECT_NEAR(hexagonal_peak_ratio(mu), (3 + std::sqrt(3.0) * mu) / (1 - std::sqrt(3.0) * mu),
                1e-9 * (1 + mu))
        << mu;
  EXPECT_NEAR(hexagonal_peak_ratio(0.0), 3.0, 1e-12);  // frictionless: tan² 60°
}

TEST(PackingHexagonalPeak, NoSlidingFailureFromOneOverRootThree) {
  EXPECT_TRUE(std::isinf(hexagonal_peak_ratio(1.0 / std::sqrt(3.0))));
  EXPECT_TRUE(std::isinf(hexagonal_peak_ratio(0.6)));
  EXPECT_TRUE(std::isinf(hexagonal_peak_ratio(1.0)));
  EXPECT_TRUE(std::isfinite(hexagonal_peak_ratio(0.577)));
  EXPECT_GT(hexagonal_peak_ratio(0.577), 1e3);
  EXPECT_TRUE(std::isinf(hexagonal_peak_ratio_walled(0.6, 10, 10)));
}

// The walled c × R box (packing.cpp): a horizontal cut crosses 2c − 1
// inclined contacts over the width W = (2c + 1) r, a vertical cut R − 1 over
// the height H = (2 + (R − 1)√3) r, where the periodic cell has one per r
// and one per √3 r; so σ1/σ3 = periodic · (2c − 1)/(2c + 1) · H/((R − 1)√3 r).
TEST(PackingHexagonalPeak, WalledBoxFactor) {
  const double s3 = std::sqrt(3.0);
  for (auto [c, rows] : {std::pair{5, 5}, {10, 10}, {20, 20}, {7, 3}}) {
    const double factor = (2.0 * c - 1) / (2.0 * c + 1) * (2 + (rows - 1) * s3) / ((rows - 1) * s3);
    EXPECT_NEAR(hexagonal_peak_ratio_walled(0.3, c, rows), hexagonal_peak_ratio(0.3) * factor,
                1e-12)
        << c << "x" << rows;
  }
  EXPECT_NEAR(hexagonal_peak_ratio_walled(0.3, 5, 5), 7.725, 5e-4);
  EXPECT_NEAR(hexagonal_peak_ratio_walled(0.3, 10, 10), 7.479, 5e-4);
  EXPECT_NEAR(hexagonal_peak_ratio_walled(0.3, 20, 20), 7.3928, 5e-4);
  // The box effect vanishes for a large sample.
  EXPECT_NEAR(hexagonal_peak_ratio_walled(0.3, 4000, 4000) / hexagonal_peak_ratio(0.3), 1.0, 1e-3);
  // One row has no inclined contacts: the periodic value is returned.
  EXPECT_EQ(hexagonal_peak_ratio_walled(0.3, 5, 1), hexagonal_peak_ratio(0.3));
}

}  // namespace
}  // namespace demcal
