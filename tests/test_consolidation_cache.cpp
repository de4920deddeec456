// The consolidation cache (issue #15): a state read back is the state
// consolidate() made, bit for bit; any changed input misses; a damaged entry
// is rebuilt, never trusted; concurrent writers leave one whole entry.
//
// The suite must not depend on the home folder: every test process starts
// with the cache off (DEMCAL_CACHE_DIR=off, inherited by the demcal programs
// the tests start), and the tests below name their own temporary folders.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_cache.hpp"
#include "demcal/scene/packing.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
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
  ASSERT_EQ(test::run_demcal(with_output("uncached"), dir.path()).status, 0);
  ::setenv("DEMCAL_CACHE_DIR", cache.c_str(), 1);
  std::vector<pid_t> pids;
  for (int k = 0; k < 3; ++k)
    pids.push_back(test::spawn_demcal(with_output("c" + std::to_string(k))));
  std::vector<int> status;
  for (pid_t p : pids) status.push_back(test::wait_exit(p));
  const test::RunResult again = test::run_demcal(with_output("hit"), dir.path());
  ::setenv("DEMCAL_CACHE_DIR", "off", 1);
  for (int s : status) EXPECT_EQ(s, 0);
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(test::names_in(cache).size(), 1u);
  const std::string series = test::read_text(dir / "uncached" / "series.csv");
  ASSERT_FALSE(series.empty());
  for (const char* out : {"c0", "c1", "c2", "hit"})
    EXPECT_EQ(test::read_text(dir / out / "series.csv"), series) << out;
}

}  // namespace
}  // namespace demcal
