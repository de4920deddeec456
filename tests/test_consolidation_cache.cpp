// The consolidation cache (issue #15): a state read back is the state
// consolidate() (disks) or consolidate_triaxial() (spheres) made, bit for
// bit; any changed input misses; a damaged entry is rebuilt, never trusted;
// concurrent writers leave one whole entry.
//
// The suite must not depend on the home folder: every test process starts
// with the cache off (DEMCAL_CACHE_DIR=off, inherited by the demcal programs
// the tests start), and the tests below name their own temporary folders.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_cache.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/run_status.hpp"
#include "support/same_bits.hpp"
#include "support/same_spheres.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

// Before main(): every test of this binary, and every program it starts,
// runs without the cache unless the test turns it on.
[[maybe_unused]] const bool kCacheOffForTheSuite = [] {
  return ::setenv("DEMCAL_CACHE_DIR", "off", 1) == 0;
}();

SceneConfig scene(const std::string& json) {
  return parse_config_text(test::with_required_material(json), "test");
}

// A random gas: consolidation compresses it and friction leaves tangential
// histories in the contacts, so the state is more than positions.
SceneConfig gas() {
  return scene(R"({"assembly": {"type": "random", "count": 60, "seed": 3},
                   "test": {"monitor_points": 20}})");
}

/// The world after a short loading run from `state`, as bytes: equal bytes
/// mean the two states step identically.
std::string loaded_bytes(const SceneConfig& c, const ConsolidatedState& state) {
  AlgorithmSpec a = c.algorithm;
  a.steps = 3000;
  a.damping_ratio_translation = 0.3;
  World end = state.world;
  run_loading(state, c.test, a, {}, &end);
  return end.save_state();
}

void expect_same_state(const ConsolidatedState& a, const ConsolidatedState& b) {
  EXPECT_EQ(a.world.save_state(), b.world.save_state());
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.width0, b.width0);
  EXPECT_EQ(a.height0, b.height0);
  EXPECT_EQ(a.stress_error, b.stress_error);
  EXPECT_EQ(a.unbalanced_ratio, b.unbalanced_ratio);
  EXPECT_EQ(a.converged, b.converged);
}

TEST(WorldState, ReadBackIsTheSameWorldAndStepsIdentically) {
  const SceneConfig c = gas();
  const ConsolidatedState s = consolidate(c, make_assembly(c), "");
  const std::string bytes = s.world.save_state();
  ConsolidatedState back = s;
  back.world = World::load_state(bytes);
  EXPECT_EQ(back.world.save_state(), bytes);
  EXPECT_EQ(loaded_bytes(c, back), loaded_bytes(c, s));
  EXPECT_THROW(World::load_state(bytes.substr(0, bytes.size() - 1)), std::runtime_error);
  EXPECT_THROW(World::load_state(bytes + "x"), std::runtime_error);
  EXPECT_THROW(World::load_state("not a world"), std::runtime_error);
}

TEST(ConsolidationCache, HitIsTheFreshStateBitForBit) {
  const test::TempDir dir("cache");
  const SceneConfig c = gas();
  const Assembly a = make_assembly(c);
  const ConsolidatedState fresh = consolidate(c, a, "");
  const ConsolidatedState first = consolidate(c, a, dir.str());  // a miss: stored
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(
      std::filesystem::exists(consolidation_cache_path(dir.str(), consolidation_key(c, a))));
  const ConsolidatedState hit = consolidate(c, a, dir.str());
  EXPECT_TRUE(hit.from_cache);
  expect_same_state(hit, fresh);
  EXPECT_EQ(loaded_bytes(c, hit), loaded_bytes(c, fresh));
}

TEST(ConsolidationCache, AnyChangedInputMisses) {
  const test::TempDir dir("cache");
  const SceneConfig c = gas();
  const Assembly a = make_assembly(c);
  const std::string key = consolidation_key(c, a);
  EXPECT_EQ(consolidation_key(c, make_assembly(c)), key);  // the same inputs, the same key
  consolidate(c, a, dir.str());
  std::vector<std::pair<std::string, SceneConfig>> changed;
  for (
      const char* json :
      {R"({"assembly": {"type": "random", "count": 60, "seed": 4}})",
       R"({"assembly": {"type": "random", "count": 60, "seed": 3}, "test": {"lateral_stress": 2e5}})",
       R"({"assembly": {"type": "random", "count": 60, "seed": 3}, "material": {"friction": 0.5}})",
       R"({"assembly": {"type": "random", "count": 60, "seed": 3},
            "test": {"consolidation_tolerance": 5e-4}})",
       R"({"assembly": {"type": "random", "count": 60, "seed": 3},
            "algorithm": {"lock_rotation": true}})"})
    changed.emplace_back(json, scene(json));
  for (const auto& [json, other] : changed) {
    const Assembly b = make_assembly(other);
    EXPECT_NE(consolidation_key(other, b), key) << json;
    EXPECT_FALSE(load_consolidated(dir.str(), consolidation_key(other, b))) << json;
  }
  // One disk a little larger: another assembly (a particle file's content
  // enters the same way).
  Assembly bigger = a;
  bigger.r[7] *= 1.0 + 1e-12;
  EXPECT_NE(consolidation_key(c, bigger), key);
  // What the loading alone uses does not enter.
  SceneConfig loading = c;
  loading.algorithm.steps *= 2;
  loading.test.vertical_strain *= 2;
  EXPECT_EQ(consolidation_key(loading, a), key);
}

TEST(ConsolidationCache, DamagedEntryIsRebuiltNeverTrusted) {
  const test::TempDir dir("cache");
  const SceneConfig c = gas();
  const Assembly a = make_assembly(c);
  const ConsolidatedState fresh = consolidate(c, a, dir.str());
  const std::string path = consolidation_cache_path(dir.str(), consolidation_key(c, a));
  const std::string whole = test::read_text(path);
  ASSERT_GT(whole.size(), 1000u);
  std::string flipped = whole;
  flipped[whole.size() / 2] ^= 0x10;  // one bit of a double
  // Another key's entry under this key's name.
  const SceneConfig other = scene(R"({"assembly": {"type": "random", "count": 60, "seed": 4}})");
  const Assembly b = make_assembly(other);
  consolidate(other, b, dir.str());
  const std::string foreign =
      test::read_text(consolidation_cache_path(dir.str(), consolidation_key(other, b)));
  for (const std::string& damaged :
       {flipped, whole.substr(0, whole.size() / 3), whole.substr(0, whole.size() - 1),
        std::string(), std::string(whole.size(), '\0'), foreign}) {
    test::write_text(path, damaged);
    EXPECT_FALSE(load_consolidated(dir.str(), consolidation_key(c, a)));
    const ConsolidatedState rebuilt = consolidate(c, a, dir.str());
    EXPECT_FALSE(rebuilt.from_cache);
    expect_same_state(rebuilt, fresh);
    EXPECT_EQ(test::read_text(path), whole);  // rewritten whole
  }
}

TEST(ConsolidationCache, ConcurrentWritersLeaveOneWholeEntry) {
  const test::TempDir dir("cache");
  const SceneConfig c = gas();
  const Assembly a = make_assembly(c);
  const ConsolidatedState fresh = consolidate(c, a, "");
  std::vector<std::optional<ConsolidatedState>> got(4);
  std::vector<std::thread> threads;
  for (auto& g : got) threads.emplace_back([&] { g.emplace(consolidate(c, a, dir.str())); });
  for (auto& t : threads) t.join();
  for (const auto& g : got) expect_same_state(*g, fresh);
  EXPECT_EQ(test::names_in(dir.path()).size(), 1u);  // the entry, no temporary left
  const auto hit = load_consolidated(dir.str(), consolidation_key(c, a));
  ASSERT_TRUE(hit);
  expect_same_state(*hit, fresh);
}

TEST(ConsolidationCache, FolderFromTheEnvironment) {
  const char* saved = std::getenv("DEMCAL_CACHE_DIR");
  const std::string keep = saved ? saved : "";
  ::setenv("DEMCAL_CACHE_DIR", "/some/where", 1);
  EXPECT_EQ(consolidation_cache_dir(), "/some/where");
  ::setenv("DEMCAL_CACHE_DIR", "off", 1);
  EXPECT_EQ(consolidation_cache_dir(), "");
  ::unsetenv("DEMCAL_CACHE_DIR");
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const std::string keep_xdg = xdg ? xdg : "";
  ::setenv("XDG_CACHE_HOME", "/x", 1);
  EXPECT_EQ(consolidation_cache_dir(), "/x/demcal");
  ::unsetenv("XDG_CACHE_HOME");
  if (const char* home = std::getenv("HOME"); home && *home) {
    EXPECT_EQ(consolidation_cache_dir(), std::string(home) + "/.cache/demcal");
  }
  if (xdg) ::setenv("XDG_CACHE_HOME", keep_xdg.c_str(), 1);
  ::setenv("DEMCAL_CACHE_DIR", saved ? keep.c_str() : "off", 1);
}

// Commands share the cache: programs started at once on an empty folder all
// succeed with the result of an uncached run, and leave one entry.
TEST(ConsolidationCacheCli, ConcurrentRunsShareOneEntryWithUncachedResults) {
  const test::TempDir dir("cli");
  const std::string cache = (dir / "cache").string();
  const std::vector<std::string> args = {"run", test::shipped_config("random_400"), "--set",
                                         "algorithm.steps=2000"};
  auto with_output = [&](const std::string& out) {
    auto a = args;
    a.insert(a.end(), {"-o", (dir / out).string()});
    return a;
  };
  // `demcal run`'s status is its verdict (2000 steps: FAIL, 1): every run
  // here ends as the uncached one.
  const int verdict = test::run_demcal(with_output("uncached"), dir.path()).status;
  ASSERT_NO_FATAL_FAILURE(test::expect_run_status(verdict, dir / "uncached"));
  ::setenv("DEMCAL_CACHE_DIR", cache.c_str(), 1);
  std::vector<pid_t> pids;
  for (int k = 0; k < 3; ++k)
    pids.push_back(test::spawn_demcal(with_output("c" + std::to_string(k))));
  std::vector<int> status;
  for (pid_t p : pids) status.push_back(test::wait_exit(p));
  const test::RunResult again = test::run_demcal(with_output("hit"), dir.path());
  ::setenv("DEMCAL_CACHE_DIR", "off", 1);
  for (int s : status) EXPECT_EQ(s, verdict);
  EXPECT_EQ(again.status, verdict) << again.err;
  EXPECT_EQ(test::names_in(cache).size(), 1u);
  const std::string series = test::read_text(dir / "uncached" / "series.csv");
  ASSERT_FALSE(series.empty());
  for (const char* out : {"c0", "c1", "c2", "hit"})
    EXPECT_EQ(test::read_text(dir / out / "series.csv"), series) << out;
}

// ---- 3D: spheres, the triaxial consolidation --------------------------------

using test::same_bits;

// A random gas of spheres (σ3 = 1e7 Pa: the stiffness level of
// configs/random_500_3d.json): consolidation compresses it and friction
// leaves tangential histories in the contacts and at the walls.
SceneConfig sphere_gas() {
  return scene(R"({"dimension": 3, "assembly": {"type": "random", "count": 60,
                   "radius_min": 4e-4, "radius_max": 6e-4, "seed": 5},
                   "test": {"lateral_stress": 1e7, "monitor_points": 20}})");
}

/// A short loading run from `state` (light damping: the spheres move, the
/// contacts slide, the list is rebuilt): its series, peak and final world.
struct SphereLoading {
  TriaxialResult run;
  SphereWorld end;
};
SphereLoading load_spheres(const SceneConfig& c, const TriaxialState& state) {
  AlgorithmSpec a = c.algorithm;
  a.steps = 3000;
  a.damping_ratio_translation = 0.3;
  SphereLoading out{{}, state.world};
  out.run = run_triaxial_loading(state, c.test, a, {}, &out.end);
  return out;
}

void expect_same_loading(const SphereLoading& a, const SphereLoading& b) {
  EXPECT_FALSE(a.run.diverged);
  EXPECT_GT(a.end.rebuilds(), 1);
  ASSERT_EQ(a.run.series.size(), b.run.series.size());
  ASSERT_GT(a.run.series.size(), 10u);
  for (size_t k = 0; k < a.run.series.size(); ++k) {
    const TriaxialPoint &p = a.run.series[k], &q = b.run.series[k];
    bool same = p.step == q.step && same_bits(p.strain_zz, q.strain_zz) &&
                same_bits(p.kinetic_energy, q.kinetic_energy) &&
                same_bits(p.elastic_energy, q.elastic_energy) &&
                same_bits(p.unbalanced_force_ratio, q.unbalanced_force_ratio);
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col)
        same = same && same_bits(p.b(r, col), q.b(r, col)) &&
               same_bits(p.sigma(r, col), q.sigma(r, col));
    for (int s = 0; s < 6; ++s) same = same && same_bits(p.walls[s], q.walls[s]);
    EXPECT_TRUE(same) << "monitoring point " << k;
  }
  EXPECT_TRUE(same_bits(a.run.peak_stress_zz, b.run.peak_stress_zz));
  EXPECT_TRUE(same_bits(a.run.peak_ratio, b.run.peak_ratio));
  test::expect_same_spheres(a.end, b.end);
  EXPECT_EQ(a.end.save_state(), b.end.save_state());
}

void expect_same_state(const TriaxialState& a, const TriaxialState& b) {
  test::expect_same_spheres(a.world, b.world);
  EXPECT_EQ(a.world.save_state(), b.world.save_state());
  EXPECT_EQ(a.steps, b.steps);
  for (int axis = 0; axis < 3; ++axis) EXPECT_TRUE(same_bits(a.extent0[axis], b.extent0[axis]));
  EXPECT_TRUE(same_bits(a.stress_error, b.stress_error));
  EXPECT_TRUE(same_bits(a.unbalanced_ratio, b.unbalanced_ratio));
  EXPECT_EQ(a.converged, b.converged);
}

TEST(SphereWorldState, ReadBackIsTheSameWorldAndStepsIdentically) {
  const SceneConfig c = sphere_gas();
  const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c), "");
  ASSERT_FALSE(s.world.contacts().empty());
  const std::string bytes = s.world.save_state();
  TriaxialState back = s;
  back.world = SphereWorld::load_state(bytes);
  EXPECT_EQ(back.world.save_state(), bytes);  // save → load → save: the same bytes
  test::expect_same_spheres(back.world, s.world);
  const SphereLoading loaded = load_spheres(c, s);
  expect_same_loading(load_spheres(c, back), loaded);
  // Mid-run (the energy ledger's running totals, the walls moving): a copy
  // read back continues as the original does.
  SphereWorld original = loaded.end;
  SphereWorld again = SphereWorld::load_state(original.save_state());
  ASSERT_TRUE(original.step(2000));
  ASSERT_TRUE(again.step(2000));
  test::expect_same_spheres(again, original);
  EXPECT_NE(original.energy_created(), 0.0);
  // Bytes that do not read whole, and another kernel's, throw.
  EXPECT_THROW(SphereWorld::load_state(bytes.substr(0, bytes.size() - 1)), std::runtime_error);
  EXPECT_THROW(SphereWorld::load_state(bytes + "x"), std::runtime_error);
  EXPECT_THROW(SphereWorld::load_state(bytes.substr(0, 8)), std::runtime_error);
  EXPECT_THROW(SphereWorld::load_state("not a world"), std::runtime_error);
  const SceneConfig disks = gas();
  const std::string world_2d = consolidate(disks, make_assembly(disks), "").world.save_state();
  EXPECT_THROW(SphereWorld::load_state(world_2d), std::runtime_error);
  EXPECT_THROW(World::load_state(bytes), std::runtime_error);
  // Counts that do not fit the arrays read (the bytes whole otherwise): the
  // sphere count, its blocks of 8 and the ghost's index, stored side by
  // side, changed one at a time.
  const int counts[3] = {s.world.size(), (s.world.size() + 7) / 8, 8 * ((s.world.size() + 7) / 8)};
  const size_t at = bytes.find(std::string(reinterpret_cast<const char*>(counts), sizeof counts));
  ASSERT_NE(at, std::string::npos);
  for (int k = 0; k < 3; ++k) {
    std::string misfit = bytes;
    int changed = counts[k] - 1;
    std::memcpy(misfit.data() + at + k * sizeof(int), &changed, sizeof changed);
    EXPECT_THROW(SphereWorld::load_state(misfit), std::runtime_error) << k;
  }
}

TEST(ConsolidationCache, SphereHitIsTheFreshStateBitForBit) {
  const test::TempDir dir("cache3d");
  const SceneConfig c = sphere_gas();
  const SphereAssembly a = make_sphere_assembly(c);
  const TriaxialState fresh = consolidate_triaxial(c, a, "");
  const TriaxialState first = consolidate_triaxial(c, a, dir.str());  // a miss: stored
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(
      std::filesystem::exists(consolidation_cache_path(dir.str(), consolidation_key(c, a))));
  const TriaxialState hit = consolidate_triaxial(c, a, dir.str());
  EXPECT_TRUE(hit.from_cache);
  EXPECT_LT(hit.wall_time_s, fresh.wall_time_s);
  expect_same_state(hit, fresh);
  expect_same_loading(load_spheres(c, hit), load_spheres(c, fresh));
}

TEST(ConsolidationCache, SphereAnyChangedInputMisses) {
  const test::TempDir dir("cache3d");
  const SceneConfig c = sphere_gas();
  const SphereAssembly a = make_sphere_assembly(c);
  const std::string key = consolidation_key(c, a);
  EXPECT_EQ(consolidation_key(c, make_sphere_assembly(c)), key);  // the same inputs, the same key
  consolidate_triaxial(c, a, dir.str());
  std::vector<std::pair<std::string, SceneConfig>> changed;
  auto change = [&](const std::string& what, auto edit) {
    SceneConfig other = c;
    edit(other);
    changed.emplace_back(what, other);
  };
  change("seed", [](SceneConfig& o) { o.assembly.seed = 6; });
  change("sigma3", [](SceneConfig& o) { o.test.lateral_stress *= 1.0 + 1e-12; });
  change("friction", [](SceneConfig& o) { o.material.particle.friction = 0.5; });
  change("wall kn", [](SceneConfig& o) { o.material.wall.kn *= 2; });
  change("density", [](SceneConfig& o) { o.material.density *= 2; });
  change("servo gain", [](SceneConfig& o) { o.test.servo_gain *= 0.5; });
  change("tolerance", [](SceneConfig& o) { o.test.consolidation_tolerance = 5e-4; });
  change("unbalanced", [](SceneConfig& o) { o.test.consolidation_unbalanced *= 0.5; });
  change("max steps", [](SceneConfig& o) { o.test.consolidation_max_steps += 1; });
  change("lock rotation", [](SceneConfig& o) { o.algorithm.lock_rotation = true; });
  for (const auto& [what, other] : changed) {
    const SphereAssembly b = make_sphere_assembly(other);
    EXPECT_NE(consolidation_key(other, b), key) << what;
    EXPECT_FALSE(load_consolidated_triaxial(dir.str(), consolidation_key(other, b))) << what;
  }
  // One sphere a little larger, one a little moved, one wall a little out:
  // another assembly (a particle file's content enters the same way).
  SphereAssembly bigger = a, moved = a, wider = a;
  bigger.r[7] *= 1.0 + 1e-12;
  moved.z[7] *= 1.0 + 1e-12;
  wider.hi[2] *= 1.0 + 1e-12;
  for (const SphereAssembly* other : {&bigger, &moved, &wider})
    EXPECT_NE(consolidation_key(c, *other), key);
  // What the loading alone uses does not enter.
  SceneConfig loading = c;
  loading.algorithm.steps *= 2;
  loading.algorithm.dt_ratio *= 0.5;
  loading.test.vertical_strain *= 2;
  EXPECT_EQ(consolidation_key(loading, a), key);
  // A 2D and a 3D key differ in their first line (the protocol), whatever
  // follows.
  const SceneConfig disks = gas();
  const std::string key_2d = consolidation_key(disks, make_assembly(disks));
  EXPECT_NE(key_2d.substr(0, key_2d.find('\n')), key.substr(0, key.find('\n')));
  EXPECT_NE(key.find(" triaxial\n"), std::string::npos);
  EXPECT_NE(key.find(" spheres "), std::string::npos);
  EXPECT_NE(key_2d.find(" biaxial\n"), std::string::npos);
  // The SIMD path is in the key (another path: ConsolidationCacheCli).
  EXPECT_NE(key.find(std::string("\nsimd ") + kernel_simd() + "\n"), std::string::npos);
}

TEST(ConsolidationCache, SphereDamagedEntryIsRebuiltNeverTrusted) {
  const test::TempDir dir("cache3d");
  const SceneConfig c = sphere_gas();
  const SphereAssembly a = make_sphere_assembly(c);
  const TriaxialState fresh = consolidate_triaxial(c, a, dir.str());
  const std::string path = consolidation_cache_path(dir.str(), consolidation_key(c, a));
  const std::string whole = test::read_text(path);
  ASSERT_GT(whole.size(), 1000u);
  std::string flipped = whole;
  flipped[whole.size() / 2] ^= 0x10;  // one bit of a number
  // Another key's entry under this key's name: another gas, and a 2D one.
  SceneConfig other = c;
  other.assembly.seed = 6;
  const SphereAssembly b = make_sphere_assembly(other);
  consolidate_triaxial(other, b, dir.str());
  const std::string foreign =
      test::read_text(consolidation_cache_path(dir.str(), consolidation_key(other, b)));
  const SceneConfig disks = gas();
  const Assembly d = make_assembly(disks);
  consolidate(disks, d, dir.str());
  const std::string foreign_2d =
      test::read_text(consolidation_cache_path(dir.str(), consolidation_key(disks, d)));
  ASSERT_FALSE(foreign.empty());
  ASSERT_FALSE(foreign_2d.empty());
  for (const std::string& damaged :
       {flipped, whole.substr(0, whole.size() / 3), whole.substr(0, whole.size() - 1),
        std::string(), std::string(whole.size(), '\0'), foreign, foreign_2d}) {
    test::write_text(path, damaged);
    EXPECT_FALSE(load_consolidated_triaxial(dir.str(), consolidation_key(c, a)));
    const TriaxialState rebuilt = consolidate_triaxial(c, a, dir.str());
    EXPECT_FALSE(rebuilt.from_cache);
    expect_same_state(rebuilt, fresh);
    EXPECT_EQ(test::read_text(path), whole);  // rewritten whole
  }
  // And a sphere entry is no 2D state.
  EXPECT_FALSE(load_consolidated(dir.str(), consolidation_key(c, a)));
}

// The commands read the 3D cache: `demcal run` of a sphere scene writes the
// same files uncached, on a miss and on a hit, and says where the state
// came from; the SIMD path is part of the key (another path, another entry).
TEST(ConsolidationCacheCli, SphereRunsReadTheCacheWithUncachedResults) {
  const test::TempDir dir("cli3d");
  const std::string cache = (dir / "cache").string();
  auto run = [&](const std::string& out, const std::string& cache_dir,
                 const std::string& simd = "") {
    std::vector<std::string> args = {"DEMCAL_CACHE_DIR=" + cache_dir};
    // (DEMCAL_GATHER empty, the default: one set for the whole suite may
    // name a way the other path lacks)
    if (!simd.empty()) args.insert(args.end(), {"DEMCAL_SIMD=" + simd, "DEMCAL_GATHER="});
    args.insert(args.end(),
                {test::kDemcalBinary, "run", test::shipped_config("random_500_3d"), "--set",
                 "assembly.count=60", "--set", "algorithm.steps=3000", "-o", (dir / out).string()});
    return test::run_program("/usr/bin/env", args, dir.path());
  };
  // `demcal run`'s status is its verdict (3000 steps: FAIL, 1): every run
  // here ends as the uncached one.
  const test::RunResult off = run("off", "off");
  ASSERT_NO_FATAL_FAILURE(test::expect_run_status(off.status, dir / "off", off.err));
  const test::RunResult miss = run("miss", cache);
  ASSERT_EQ(miss.status, off.status) << miss.err;
  EXPECT_EQ(test::names_in(cache).size(), 1u);
  const test::RunResult hit = run("hit", cache);
  ASSERT_EQ(hit.status, off.status) << hit.err;
  EXPECT_EQ(off.out.find("from the cache"), std::string::npos);
  EXPECT_EQ(miss.out.find("from the cache"), std::string::npos);
  EXPECT_NE(hit.out.find("from the cache"), std::string::npos) << hit.out;
  const auto summary = [&](const char* out) {
    return nlohmann::json::parse(test::read_text(dir / out / "summary.json"));
  };
  EXPECT_FALSE(summary("miss")["consolidation"]["from_cache"].get<bool>());
  EXPECT_TRUE(summary("hit")["consolidation"]["from_cache"].get<bool>());
  EXPECT_EQ(summary("hit")["consolidation"]["steps"], summary("off")["consolidation"]["steps"]);
  for (const char* file : {"series.csv", "final.vtk"}) {
    const std::string uncached = test::read_text(dir / "off" / file);
    ASSERT_FALSE(uncached.empty()) << file;
    EXPECT_TRUE(test::read_text(dir / "miss" / file) == uncached) << file;
    EXPECT_TRUE(test::read_text(dir / "hit" / file) == uncached) << file;
  }
  // Another SIMD path: another key, so another entry (and a miss).
  const std::string other = std::string(kernel_simd()) == "sse2" ? "" : "sse2";
  if (other.empty()) GTEST_SKIP() << "this CPU runs the SSE2 path only";
  const test::RunResult sse2 = run("sse2", cache, other);
  ASSERT_NO_FATAL_FAILURE(test::expect_run_status(sse2.status, dir / "sse2", sse2.err));
  EXPECT_EQ(sse2.out.find("from the cache"), std::string::npos);
  EXPECT_EQ(test::names_in(cache).size(), 2u);
}

}  // namespace
}  // namespace demcal
