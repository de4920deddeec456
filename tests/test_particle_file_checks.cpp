// The per-line checks of particle files (issue #13 follow-up), one home for
// the 2D (x,y,r) and the 3D (x,y,z,r) readers: parse_particle_fields. The
// sphere reader lacked two of the disk reader's: a coordinate plus a few
// radii overflowing a double (1e308), and the particle count limit
// (kMaxParticles). Each is an InputError naming the file and the line.
#include <gtest/gtest.h>

#include <array>
#include <sstream>
#include <string>

#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "support/input_errors.hpp"

namespace demcal {
namespace {

using test::input_error;

/// The sphere reader fails on `content` naming "s.csv", `field` and `words`.
void expect_spheres_rejected(const std::string& content, const std::string& field,
                             const std::string& words) {
  SCOPED_TRACE(content);
  std::istringstream in(content);
  test::expect_input_error([&] { read_spheres(in, "s.csv"); }, "s.csv", field, words);
}

void expect_disks_rejected(const std::string& content, const std::string& field,
                           const std::string& words) {
  SCOPED_TRACE(content);
  std::istringstream in(content);
  test::expect_input_error([&] { read_particles(in, "p.csv"); }, "p.csv", field, words);
}

// |coordinate| + 4 r must be finite: the overlap test adds radii to the
// coordinates. A sphere at 1.7e308 (any axis) with a radius of 1e307, or of
// radius 1e308, is refused with its line, as a disk is.
TEST(ParticleFileChecks, OverflowingCoordinatesNameTheLine) {
  for (const std::string line :
       {"1.7e308,0,0,1e307", "0,-1.7e308,0,1e307", "0,0,1.7e308,1e307", "0,0,0,1e308"})
    expect_spheres_rejected("x,y,z,r\n0,0,0,1\n" + line + "\n", "line 3", "values too large");
  expect_disks_rejected("0,0,1\n1.7e308,0,1e307\n", "line 2", "values too large");
  expect_disks_rejected("0,0,1\n0,0,1e308\n", "line 2", "values too large");
  // Large but representable: read.
  std::istringstream in("0,0,0,1\n1e300,0,0,1\n");
  EXPECT_EQ(read_spheres(in, "s.csv").size(), 2);
}

// NaN and a radius that is not positive, in 3D as in 2D.
TEST(ParticleFileChecks, NanAndNonPositiveRadiiNameTheLine) {
  expect_spheres_rejected("0,0,0,1\n3,0,0,nan\n", "line 2", "values must be finite");
  expect_spheres_rejected("0,0,0,1\n3,nan,0,1\n", "line 2", "values must be finite");
  expect_spheres_rejected("0,0,0,1\n3,0,0,-0\n", "line 2", "radius must be > 0");
  expect_spheres_rejected("0,0,0,1\n3,0,0,0\n", "line 2", "radius must be > 0");
  expect_disks_rejected("0,0,1\n3,0,-2\n", "line 2", "radius must be > 0");
}

// The count limit lives in the shared line parser: a particle line read
// after kMaxParticles others is refused, for disks and spheres alike (a
// file of 10^7 lines is too large for a unit test: the parser is called
// with the count each reader passes it, a.size()).
TEST(ParticleFileChecks, CountLimitIsInTheSharedParser) {
  for (const std::string& line : {std::string("1,2,3"), std::string("1,2,3,4")}) {
    SCOPED_TRACE(line);
    std::array<double, 4> storage{};
    const std::span<double> v(storage.data(), line == "1,2,3" ? 3 : 4);
    bool seen = true;
    EXPECT_TRUE(parse_particle_fields(line, v, seen, kMaxParticles - 1, "f.csv", "line 9"));
    const auto e = input_error(
        [&] { parse_particle_fields(line, v, seen, kMaxParticles, "f.csv", "line 9"); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), "f.csv");
    EXPECT_EQ(e->field(), "line 9");
    EXPECT_NE(std::string(e->what()).find(std::string("more particles than the limit ") +
                                          kMaxParticlesWhy),
              std::string::npos)
        << e->what();
    // The header is no particle: never counted.
    bool first = false;
    EXPECT_FALSE(parse_particle_fields(line.size() == 5 ? "x,y,r" : "x,y,z,r", v, first,
                                       kMaxParticles, "f.csv", "line 1"));
  }
}

}  // namespace
}  // namespace demcal
