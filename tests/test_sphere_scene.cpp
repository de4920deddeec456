// Random sphere gas and the x,y,z,r particle-file reader
// (src/scene/sphere_packing.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "demcal/io/input_error.hpp"
#include "demcal/scene/sphere_packing.hpp"

namespace demcal {
namespace {

double distance(const SphereAssembly& a, int i, int j) {
  return std::sqrt(std::pow(a.x[j] - a.x[i], 2) + std::pow(a.y[j] - a.y[i], 2) +
                   std::pow(a.z[j] - a.z[i], 2));
}

void expect_gas_inside_and_apart(const SphereAssembly& a) {
  for (int i = 0; i < a.size(); ++i) {
    const double p[3] = {a.x[i], a.y[i], a.z[i]};
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_GE(p[axis] - a.r[i], a.lo[axis]);
      EXPECT_LE(p[axis] + a.r[i], a.hi[axis]);
    }
    for (int j = i + 1; j < a.size(); ++j) EXPECT_GT(distance(a, i, j), a.r[i] + a.r[j]);
  }
}

TEST(SphereScene, UniformGasHasItsRadiiInRangeAndNoOverlap) {
  AssemblySpec spec;
  spec.count = 500;
  spec.distribution = "uniform";
  spec.radius_min = 0.8e-3;
  spec.radius_max = 1.2e-3;
  spec.seed = 7;
  const SphereAssembly a = random_sphere_gas(spec);
  ASSERT_EQ(a.size(), 500);
  expect_gas_inside_and_apart(a);
  const auto [lo, hi] = std::minmax_element(a.r.begin(), a.r.end());
  EXPECT_GE(*lo, spec.radius_min);
  EXPECT_LT(*hi, spec.radius_max);
  // Mean of U(a, b) is (a + b)/2 with standard error (b − a)/sqrt(12·n):
  // 4 standard errors.
  const double mean = std::accumulate(a.r.begin(), a.r.end(), 0.0) / a.size();
  EXPECT_NEAR(mean, 1e-3, 4.0 * 0.4e-3 / std::sqrt(12.0 * 500));
  // A cube of cells (aspect 1): 8 across, 8 layers for 500 spheres.
  EXPECT_NEAR(a.hi[0], a.hi[2], 1e-15);
}

TEST(SphereScene, LognormalGasHasTheAskedMeanAndSpread) {
  AssemblySpec spec;
  spec.count = 4000;
  spec.distribution = "lognormal";
  spec.radius_mean = 1e-3;
  spec.radius_std = 0.2e-3;
  spec.seed = 3;
  const SphereAssembly a = random_sphere_gas(spec);
  ASSERT_EQ(a.size(), 4000);
  double mean = 0.0, var = 0.0;
  for (double r : a.r) mean += r;
  mean /= a.size();
  for (double r : a.r) var += (r - mean) * (r - mean);
  const double sd = std::sqrt(var / (a.size() - 1));
  // Standard errors: sd/sqrt(n) for the mean, ~sd/sqrt(2n)·sqrt(1 + kurtosis
  // excess/2) for the sd (≈ 1.2 for this lognormal); 4 of each. The ±3σ
  // truncation of ln r moves the moments by < 0.3 % of the sd.
  EXPECT_NEAR(mean, spec.radius_mean, 4.0 * spec.radius_std / std::sqrt(4000.0));
  EXPECT_NEAR(sd, spec.radius_std, 4.0 * 1.2 * spec.radius_std / std::sqrt(8000.0));
  const double median = std::log(1e-3) - 0.5 * std::log(1.04);  // ln of the median
  const double s = std::sqrt(std::log(1.04));
  for (double r : a.r) {
    EXPECT_GE(std::log(r), median - 3.0 * s - 1e-12);
    EXPECT_LE(std::log(r), median + 3.0 * s + 1e-12);
  }
  // The no-overlap check is O(n²): on a 300-sphere gas of the same law.
  spec.count = 300;
  expect_gas_inside_and_apart(random_sphere_gas(spec));
}

TEST(SphereScene, GasIsDeterministicForASeed) {
  AssemblySpec spec;
  spec.count = 50;
  spec.seed = 11;
  const SphereAssembly a = random_sphere_gas(spec), b = random_sphere_gas(spec);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.r, b.r);
  spec.seed = 12;
  EXPECT_NE(random_sphere_gas(spec).x, a.x);
}

TEST(SphereScene, ReaderTakesHeaderCommentsAndBlankLines) {
  std::istringstream in("# spheres\nx,y,z,r\n\n0,0,0,1\r\n 2.5, 0, 0, 1\n0,2.5,0,1\n# end\n");
  const SphereAssembly a = read_spheres(in, "s.csv");
  ASSERT_EQ(a.size(), 3);
  EXPECT_EQ(a.x[1], 2.5);
  EXPECT_EQ(a.lo[0], -1.0);
  EXPECT_EQ(a.hi[0], 3.5);
  EXPECT_EQ(a.hi[1], 3.5);
  EXPECT_EQ(a.lo[2], -1.0);
  EXPECT_EQ(a.hi[2], 1.0);
}

std::string reader_error(const std::string& text) {
  std::istringstream in(text);
  try {
    read_spheres(in, "s.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SphereScene, ReaderRejectsBadLinesWithFileAndLine) {
  EXPECT_EQ(reader_error("x,y,z,r\n0,0,0,1\n3,0,0\n"),
            "s.csv: line 3: expected four numbers x,y,z,r, got \"3,0,0\"");
  EXPECT_EQ(reader_error("0,0,0,1\n3,0,zero,1\n"),
            "s.csv: line 2: expected four numbers x,y,z,r, got \"3,0,zero,1\"");
  EXPECT_EQ(reader_error("0,0,0,1\n3,0,0,1,5\n"),
            "s.csv: line 2: expected four numbers x,y,z,r, got \"3,0,0,1,5\"");
  EXPECT_EQ(reader_error("0,0,0,1\n3,0,0,-1\n"),
            "s.csv: line 2: radius must be > 0, got \"3,0,0,-1\"");
  EXPECT_EQ(reader_error("0,0,0,1\n3,0,inf,1\n"),
            "s.csv: line 2: values must be finite, got \"3,0,inf,1\"");
  EXPECT_EQ(reader_error("x,y,z,r\n0,0,0,1\n"), "s.csv: needs at least two spheres, found 1");
  // A header that names another order is refused, not read with the axes
  // swapped (a sample tall in z read lying on its side, with no error).
  EXPECT_EQ(reader_error("z,y,x,r\n0,0,0,1\n3,0,0,1\n"),
            "s.csv: line 1: header: the columns must be x,y,z,r in this order (the radius may "
            "be called radius), got \"z,y,x,r\"");
  EXPECT_NE(reader_error("r,x,y,z\n1,0,0,0\n1,3,0,0\n").find("line 1: header:"), std::string::npos);
  EXPECT_NE(reader_error("# c\nid,x,y,z\n0,0,0,1\n3,0,0,1\n").find("line 2: header:"),
            std::string::npos);
  // The names in any case, quoted, blanks around, the radius as radius.
  EXPECT_EQ(reader_error("X, \"y\" ,Z,Radius\n0,0,0,1\n3,0,0,1\n"), "");
  // A header after the first sphere is a bad line.
  EXPECT_NE(reader_error("0,0,0,1\nx,y,z,r\n3,0,0,1\n").find("line 2"), std::string::npos);
  // Overlap limit 5 % of the smaller radius: 1.9 apart (10 %) is an error,
  // 1.96 apart (4 %) is a packing.
  EXPECT_NE(
      reader_error("0,0,0,1\n# c\n1.9,0,0,1\n").find("line 3: sphere overlaps the one on line 1"),
      std::string::npos);
  EXPECT_EQ(reader_error("0,0,0,1\n0,0,1.96,1\n"), "");
  EXPECT_NE(reader_error("").find("needs at least two spheres"), std::string::npos);
  EXPECT_THROW(read_sphere_file("/nonexistent/spheres.csv"), InputError);
}

}  // namespace
}  // namespace demcal
