// The REV in 3D (issue #18): the sphere–box volume against analytical
// cases, packing statistics of the FCC lattice (porosity 1 − π/(3√2),
// twelve contacts), the box cut and the resampled gas, a REV cut from an
// FCC prototype file and re-consolidated to σ3, and `demcal rev` on a 3D
// config (files, and bad input: exit 2, one clear error, no folder).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <thread>

#include "demcal/scene/sphere_packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/rev_3d.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

double ball(double r) { return 4.0 / 3.0 * kPi * r * r * r; }
// The cap of height c of a sphere of radius r.
double cap(double r, double c) { return kPi * c * c * (3.0 * r - c) / 3.0; }
// How far a box cut from a cubic FCC block may land from the count asked
// for: a window centred on the block takes a new lattice plane on all six
// faces at once, k³/2 sites becoming (k + 2)³/2 (k sites along an edge,
// k³/2 ≈ count), a jump of about 3k²; the nearest is within half of it.
double lattice_slack(double count) { return 1.5 * std::pow(2.0 * count, 2.0 / 3.0); }

TEST(SphereBoxVolume, AnalyticalCases) {
  const double r = 1.5, full = ball(r), big = 10.0;
  const double cx = 0.3, cy = -0.2, cz = 0.7;
  auto v = [&](std::array<double, 3> lo, std::array<double, 3> hi) {
    return sphere_box_volume(cx, cy, cz, r, lo, hi);
  };
  const double rel = 1e-12 * full;
  // Fully inside, fully outside, touching from outside.
  EXPECT_NEAR(v({-big, -big, -big}, {big, big, big}), full, rel);
  EXPECT_EQ(v({cx + r, -big, -big}, {big, big, big}), 0.0);
  EXPECT_EQ(v({cx + 2 * r, -big, -big}, {big, big, big}), 0.0);
  // One plane at signed distance h from the centre, along each axis: the
  // sphere minus the cap of height r − h (h < 0: only a cap is left).
  for (double h : {-0.9, -0.5, -0.1, 0.0, 0.25, 0.6, 0.95}) {
    SCOPED_TRACE(h);
    const double kept = h >= 0 ? full - cap(r, r - h * r) : cap(r, r + h * r);
    EXPECT_NEAR(v({-big, -big, -big}, {cx + h * r, big, big}), kept, rel);  // x ≤ cx + hr
    EXPECT_NEAR(v({-big, cy - h * r, -big}, {big, big, big}), kept, rel);   // y ≥ cy − hr
    EXPECT_NEAR(v({-big, -big, -big}, {big, big, cz + h * r}), kept, rel);  // z ≤ cz + hr
  }
  // Planes through the centre: half, quarter, eighth, in every orientation.
  EXPECT_NEAR(v({cx, -big, -big}, {big, big, big}), full / 2, rel);
  EXPECT_NEAR(v({cx, cy, -big}, {big, big, big}), full / 4, rel);
  EXPECT_NEAR(v({-big, cy, cz}, {big, big, big}), full / 4, rel);
  EXPECT_NEAR(v({-big, -big, -big}, {cx, big, cz}), full / 4, rel);
  EXPECT_NEAR(v({cx, cy, cz}, {big, big, big}), full / 8, rel);
  EXPECT_NEAR(v({-big, -big, -big}, {cx, cy, cz}), full / 8, rel);
  // A slab through the centre, |z − cz| ≤ h: π(2hr² − 2h³/3).
  const double h = 0.4 * r;
  EXPECT_NEAR(v({-big, -big, cz - h}, {big, big, cz + h}),
              kPi * (2 * h * r * r - 2 * h * h * h / 3), rel);
  // Two perpendicular planes through the centre and a third cutting a cap:
  // a quarter of (sphere − cap).
  EXPECT_NEAR(v({cx, cy, -big}, {big, big, cz + 0.5 * r}), (full - cap(r, 0.5 * r)) / 4, rel);
}

TEST(SphereBoxVolume, AdditiveAndAgreesWithAGrid) {
  // Splitting any box by any plane: the two parts add up to the whole (the
  // kinks of each part fall in different places, so this tests the
  // quadrature where no closed form exists).
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  const double r = 1.0;
  int both = 0;  // splits that cut the sphere into two real parts
  for (int t = 0; t < 500; ++t) {
    std::array<double, 3> lo{u(rng), u(rng), u(rng)}, hi{u(rng), u(rng), u(rng)};
    for (int d = 0; d < 3; ++d)
      if (lo[d] > hi[d]) std::swap(lo[d], hi[d]);
    const int axis = t % 3;
    const double cut = lo[axis] + (hi[axis] - lo[axis]) * (0.5 + 0.5 * u(rng) / 1.2);
    std::array<double, 3> mid_hi = hi, mid_lo = lo;
    mid_hi[axis] = cut;
    mid_lo[axis] = cut;
    const double whole = sphere_box_volume(0, 0, 0, r, lo, hi);
    const double a = sphere_box_volume(0, 0, 0, r, lo, mid_hi),
                 b = sphere_box_volume(0, 0, 0, r, mid_lo, hi), parts = a + b;
    both += a > 0.01 * ball(r) && b > 0.01 * ball(r);
    ASSERT_NEAR(whole, parts, 1e-10 * ball(r)) << t;
  }
  EXPECT_GT(both, 100);  // 158 with this seed: the test does cut spheres
  // An awkward box against a midpoint count on a 240³ grid (the grid's own
  // error: about the surface layer, ~1e-4 of the volume).
  const std::array<double, 3> lo{-0.7, -1.9, -0.35}, hi{1.3, 0.4, 2.0};
  const int n = 240;
  double inside = 0;
  std::array<double, 3> step;
  for (int d = 0; d < 3; ++d) step[d] = (hi[d] - lo[d]) / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double x = lo[0] + (i + 0.5) * step[0], y = lo[1] + (j + 0.5) * step[1],
                     z = lo[2] + (k + 0.5) * step[2];
        inside += x * x + y * y + z * z < 1.0;
      }
  const double grid = inside * step[0] * step[1] * step[2];
  EXPECT_NEAR(sphere_box_volume(0, 0, 0, 1.0, lo, hi), grid, 1e-3 * grid);
}

TEST(SpherePackingStats, FccLattice) {
  // FCC: solid fraction π/(3√2), twelve contacts inside.
  const SphereAssembly a = fcc_packing(6, 6, 6, 1e-3);
  const PackingStats s = packing_stats(a);
  EXPECT_EQ(s.dimension, 3);
  EXPECT_EQ(s.particles, 864);
  EXPECT_NEAR(s.coordination_interior, 12.0, 1e-12);
  EXPECT_LT(s.coordination, 12.0);             // the faces have fewer
  EXPECT_GT(s.porosity, s.porosity_interior);  // the wall voids
  // The interior window (edge 13.6 r of a 17.6 r box) is no whole number of
  // cells, so its porosity differs from the lattice's by the parts of
  // (100) layers it clips at its faces: within 0.01 (5e-4 measured).
  EXPECT_NEAR(s.porosity_interior, 1.0 - kPi / (3.0 * std::sqrt(2.0)), 0.01);
  EXPECT_NEAR(s.radius_mean, 1e-3, 1e-15);
  EXPECT_NEAR(s.depth, a.hi[1] - a.lo[1], 1e-15);
  const nlohmann::json j = to_json(s);
  EXPECT_EQ(j["dimension"].get<int>(), 3);
  EXPECT_NEAR(j["depth"].get<double>(), s.depth, 1e-18);
}

TEST(SphereRev, CutHoldsAboutTheCountAndStaysInsideThePrototype) {
  const SphereAssembly proto = fcc_packing(8, 8, 8, 5e-4);
  for (int count : {50, 200, 500}) {
    SCOPED_TRACE(count);
    const SphereAssembly rev = cut_rev(proto, count);
    EXPECT_NEAR(rev.size(), count, lattice_slack(count));
    for (int i = 0; i < rev.size(); ++i) {
      EXPECT_GE(rev.z[i] - rev.r[i], rev.lo[2] - 1e-15);
      EXPECT_LE(rev.x[i] + rev.r[i], rev.hi[0] + 1e-15);
      EXPECT_GE(rev.lo[1], proto.lo[1] - 1e-15);
      EXPECT_LE(rev.hi[2], proto.hi[2] + 1e-15);
    }
  }
  EXPECT_THROW(cut_rev(proto, 5000), InputError);
  EXPECT_THROW(cut_rev(proto, 1), InputError);
}

TEST(SphereRev, GenerateDrawsTheRadiiFromThePrototype) {
  AssemblySpec spec;
  spec.count = 400;
  const SphereAssembly proto = random_sphere_gas(spec);
  const SphereAssembly rev = generate_rev(proto, 150, 7);
  ASSERT_EQ(rev.size(), 150);
  for (double r : rev.r) EXPECT_NE(std::find(proto.r.begin(), proto.r.end(), r), proto.r.end());
  EXPECT_LT(ks_distance(rev.r, proto.r), 1.358 * std::sqrt((150.0 + 400.0) / (150.0 * 400.0)));
  for (int i = 0; i < rev.size(); ++i)
    for (int j = i + 1; j < rev.size(); ++j)
      EXPECT_GE(std::hypot(rev.x[i] - rev.x[j], rev.y[i] - rev.y[j], rev.z[i] - rev.z[j]),
                rev.r[i] + rev.r[j]);
  // random_sphere_gas is its radii placed by sphere_gas, draw for draw.
  std::mt19937_64 rng(spec.seed);
  std::vector<double> radii(proto.r);
  for (int i = 0; i < spec.count; ++i) rng();  // the uniform radii's draws
  const SphereAssembly again = sphere_gas(radii, spec.aspect, rng);
  EXPECT_EQ(again.x, proto.x);
  EXPECT_EQ(again.z, proto.z);
  EXPECT_EQ(again.hi, proto.hi);
}

TEST(SphereRev, SphereCsvRoundTrips) {
  AssemblySpec spec;
  spec.count = 30;
  const SphereAssembly a = random_sphere_gas(spec);
  const test::TempDir dir("rev3d");
  const SphereAssembly b = read_sphere_file(test::write_text(dir / "s.csv", sphere_csv(a)));
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(b.x, a.x);
  EXPECT_EQ(b.y, a.y);
  EXPECT_EQ(b.z, a.z);
  EXPECT_EQ(b.r, a.r);
}

SceneConfig fcc_scene() {
  SceneConfig c =
      parse_config_text("{" + test::kMaterialMember + R"(, "name": "fcc_rev", "dimension": 3,
        "assembly": {"type": "fcc", "cells_x": 2, "cells_y": 2, "cells_z": 2, "radius": 5e-4},
        "test": {"type": "triaxial", "lateral_stress": 1e5}})",
                        "fcc_rev.json");
  return c;
}

TEST(SphereRev, CutFromAnFccFileIsRepresentativeAfterReconsolidation) {
  // The prototype as a user gives it: a sphere file.
  const test::TempDir dir("rev3d");
  const std::string path =
      test::write_text(dir / "proto.csv", sphere_csv(fcc_packing(7, 7, 7, 5e-4)));
  const SceneConfig c = fcc_scene();
  const SphereAssembly proto = read_sphere_file(path);
  RevOptions o;
  o.particles = 500;
  const SphereRevResult r = make_rev(c, proto, o);
  EXPECT_TRUE(r.state.converged);
  EXPECT_EQ(r.method, "cut");
  EXPECT_NEAR(r.assembly.size(), 500, lattice_slack(500));
  const auto& rep = r.representativeness;
  EXPECT_EQ(rep.rev.dimension, 3);
  EXPECT_EQ(rep.ks, 0.0);  // one radius
  EXPECT_TRUE(rep.size_distribution_ok);
  // The lattice survives isotropic consolidation: each interior sphere keeps
  // its twelve neighbours, and the contacts shorten by F/kn with
  // F = √2·r²·σ3 (FCC under isotropic stress), a strain F/(kn·2r) of
  // 3.5e-7 here: the interior porosity moves by about 3·3.5e-7·(1 − n)
  // ≈ 1e-6. What remains is the window: the REV's interior window (edge
  // ≈ 10.7 r) and the prototype's clip different fractions of the
  // lattice's layers (8e-4 seen), well inside the verdict's 0.02.
  EXPECT_NEAR(rep.rev.coordination_interior, 12.0, 1e-12);
  EXPECT_NEAR(rep.prototype.coordination_interior, 12.0, 1e-12);
  EXPECT_NEAR(rep.prototype.porosity_interior, 1.0 - kPi / (3.0 * std::sqrt(2.0)), 0.01);
  EXPECT_TRUE(rep.porosity_ok) << rep.verdict;
  EXPECT_TRUE(rep.coordination_ok) << rep.verdict;
  EXPECT_TRUE(rep.representative) << rep.verdict;
  const nlohmann::json j = to_json(rep);
  EXPECT_TRUE(j["representative"].get<bool>());
  EXPECT_EQ(j["rev"]["particles"].get<int>(), r.assembly.size());
  EXPECT_EQ(j["prototype"]["dimension"].get<int>(), 3);
}

// A consolidated lattice keeps its layers only to within about an overlap
// (5e-7 r in the FCC prototype `demcal rev configs/fcc_4x4x4.json` makes):
// rounding orders a layer's centres, and a window cut to the exact count
// asked took part of a layer, whose spheres the walls then squeezed into
// the gaps beside them: `--particles 300` never reached a static state (2
// million steps). The cut goes between layers: the same count as on the
// exact lattice, and the REV consolidates.
TEST(SphereRev, CutGoesBetweenTheLayersOfAConsolidatedLattice) {
  const SphereAssembly exact = fcc_packing(8, 8, 8, 5e-4);
  SphereAssembly proto = exact;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> jitter(-2.5e-7 * 5e-4, 2.5e-7 * 5e-4);
  for (auto* c : {&proto.x, &proto.y, &proto.z})
    for (double& v : *c) v += jitter(rng);
  // Cubes of 2m whole (100) layers around the centre: 4m³ spheres.
  for (auto [asked, whole] : {std::pair{10, 4}, {172, 108}, {300, 256}, {400, 500}}) {
    SCOPED_TRACE(asked);
    EXPECT_EQ(cut_rev(exact, asked).size(), whole);
    EXPECT_EQ(cut_rev(proto, asked).size(), whole);
  }
  RevOptions o;
  o.particles = 300;
  const SphereRevResult r = make_rev(fcc_scene(), proto, o);
  EXPECT_TRUE(r.state.converged);
  EXPECT_EQ(r.assembly.size(), 256);
  EXPECT_NEAR(r.representativeness.rev.coordination_interior, 12.0, 1e-12);
}

// In a random packing nearly every gap between the centres' window scales
// is wider than the tenth of their mean spacing that marks a layer, so the
// cut holds the count asked, or one next to it.
TEST(SphereRev, CutOfARandomPackingHoldsAboutTheCountAsked) {
  AssemblySpec spec;
  spec.count = 3000;
  spec.radius_min = 4e-4;
  spec.radius_max = 6e-4;
  const SphereAssembly proto = random_sphere_gas(spec);
  for (int asked : {50, 200, 333, 1000}) {
    SCOPED_TRACE(asked);
    EXPECT_NEAR(cut_rev(proto, asked).size(), asked, 2);
  }
}

TEST(SphereRev, GeneratedRevIsADensePackingOfThePrototypesRadii) {
  // Radii uniform in [0.75, 1.25]·5e-4 m from a loose gas (porosity ≈ 0.8:
  // one sphere per cell of edge 2.2·r_max). The generated REV, consolidated,
  // is a dense random packing: porosity between random close packing of
  // mildly polydisperse spheres (≈ 0.35) and random loose packing (≈ 0.45),
  // so the verdict against the gas is NOT representative, on porosity.
  AssemblySpec spec;
  spec.count = 400;
  const SphereAssembly proto = random_sphere_gas(spec);
  RevOptions o;
  o.particles = 120;
  o.method = "generate";
  // The shipped random scene's material (kn = 1e6 N/m: a gas consolidates
  // in about 1e5 steps).
  const SceneConfig c = load_config(test::shipped_config("random_500_3d"));
  const SphereRevResult r = make_rev(c, proto, o);
  EXPECT_TRUE(r.state.converged);
  ASSERT_EQ(r.assembly.size(), 120);
  const auto& rep = r.representativeness;
  EXPECT_TRUE(rep.size_distribution_ok) << rep.verdict;
  EXPECT_GT(rep.prototype.porosity, 0.7);
  EXPECT_GT(rep.rev.porosity_interior, 0.30) << rep.verdict;
  EXPECT_LT(rep.rev.porosity_interior, 0.45) << rep.verdict;
  EXPECT_FALSE(rep.porosity_ok) << rep.verdict;
  EXPECT_FALSE(rep.representative);
}

TEST(SphereRev, AWrongSizeDistributionIsCaught) {
  // compare is the 2D one: a REV whose radii are not the prototype's fails
  // the KS test, in 3D as in 2D.
  const SphereAssembly big = fcc_packing(3, 3, 3, 1e-3), small = fcc_packing(3, 3, 3, 5e-4);
  const Representativeness r = compare(packing_stats(small), packing_stats(big), small.r, big.r);
  EXPECT_FALSE(r.size_distribution_ok);
  EXPECT_FALSE(r.representative);
  EXPECT_NE(r.verdict.find("NOT representative"), std::string::npos);
}

// `demcal rev` on a 3D config.
class Rev3dCli : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ / "work");
    config_ = test::write_text(dir_ / "fcc.json", R"({)" + test::kMaterialMember +
                                                      R"(, "name": "fcc_rev", "dimension": 3,
        "assembly": {"type": "fcc", "cells_x": 2, "cells_y": 2, "cells_z": 2, "radius": 5e-4},
        "test": {"type": "triaxial", "lateral_stress": 1e5}})");
  }
  test::RunResult demcal(const std::vector<std::string>& args) {
    return test::run_demcal(args, dir_ / "work");
  }
  test::TempDir tmp_{"rev3dcli"};
  const fs::path dir_ = tmp_.path();
  std::string config_;
};

TEST_F(Rev3dCli, CutsAReviewableRevFromASphereFile) {
  const std::string proto =
      test::write_text(dir_ / "proto.csv", sphere_csv(fcc_packing(6, 6, 6, 5e-4)));
  const auto r = demcal({"rev", config_, "--prototype", proto, "--particles", "200", "-o", "R"});
  ASSERT_EQ(r.status, 0) << r.err;
  const fs::path out = dir_ / "work" / "R";
  // The REV is a sphere file the 3D config reads...
  const SphereAssembly rev = read_sphere_file((out / "rev.csv").string());
  EXPECT_NEAR(rev.size(), 200, lattice_slack(200));
  // ...of whole layers of the lattice, which the summary says moved the count.
  EXPECT_NE(r.out.find("REV of " + std::to_string(rev.size()) + " spheres (cut"), std::string::npos)
      << r.out;
  if (rev.size() != 200) {
    EXPECT_NE(r.out.find("asked for 200, the nearest count whose window cuts between the "
                         "prototype's layers"),
              std::string::npos)
        << r.out;
  }
  // ...and rev-config.json is a 3D config that builds it and names the prototype.
  const SceneConfig c = load_config((out / "rev-config.json").string());
  EXPECT_EQ(c.dimension, 3);
  EXPECT_EQ(c.assembly.type, "file");
  EXPECT_EQ(make_sphere_assembly(c).size(), rev.size());
  EXPECT_EQ(fs::path(c.prototype.file).filename(), "proto.csv");
  const nlohmann::json j = test::read_json(out / "rev.json");
  EXPECT_EQ(j["dimension"].get<int>(), 3);
  EXPECT_EQ(j["particles"].get<int>(), rev.size());
  EXPECT_EQ(j["representativeness"]["rev"]["dimension"].get<int>(), 3);
  EXPECT_TRUE(j["representativeness"]["representative"].get<bool>()) << j.dump(2);
}

TEST_F(Rev3dCli, BadInputIsOneClearErrorAndNoFolder) {
  // A 2D particle file given to a 3D config: named with its line.
  const std::string flat = test::write_text(dir_ / "disks.csv", "x,y,r\n0,0,1\n3,0,1\n");
  auto r = demcal({"rev", config_, "--prototype", flat, "--particles", "2", "-o", "R"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("disks.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("x,y,z,r"), std::string::npos) << r.err;
  // More spheres than the prototype has: refused before any consolidation.
  const std::string proto =
      test::write_text(dir_ / "proto.csv", sphere_csv(fcc_packing(2, 2, 2, 5e-4)));
  r = demcal({"rev", config_, "--prototype", proto, "--particles", "100", "-o", "R"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("prototype has only 32"), std::string::npos) << r.err;
  // No prototype at all.
  r = demcal({"rev", config_, "--particles", "10", "-o", "R"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("prototype"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "work" / "R"));
}

TEST_F(Rev3dCli, ConsolidatesALargeGeneratedPrototypeOnEveryCore) {
  // A generated gas of kThreadsFrom (10^4) spheres: rev consolidates it on
  // every core, as export does, and says so before it starts (a 20 000-sphere
  // prototype is most of rev's time). A budget of 1000 steps keeps the test
  // short: the consolidation fails after the announcement.
  const unsigned cores = std::thread::hardware_concurrency();
  if (cores < 2) GTEST_SKIP() << "one core: every core is one thread";
  const std::string config =
      test::write_text(dir_ / "gas.json", R"({)" + test::kMaterialMember +
                                              R"(, "name": "gas", "dimension": 3,
        "assembly": {"type": "random", "count": 200, "radius_min": 3.75e-4, "radius_max": 6.25e-4},
        "test": {"type": "triaxial", "lateral_stress": 1e5, "consolidation_max_steps": 1000},
        "prototype": {"particles": 10000}})");
  const auto r = demcal({"rev", config, "--particles", "200", "-o", "R"});
  EXPECT_NE(r.status, 0) << r.err;  // 1000 steps do not consolidate a gas
  EXPECT_NE(r.err.find("consolidating the prototype first (10000 spheres from the random "
                       "generator of gas, on " +
                       std::to_string(cores) + " threads)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("single-threaded"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace demcal
