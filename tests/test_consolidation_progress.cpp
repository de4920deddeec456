// demcal's 2D and 3D consolidations report progress while they run (issue
// #16: they never spend minutes silently) and step on threads without
// changing the state they reach; the CLI prints the reports on stderr.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "consolidation_progress.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

// A random gas of 150 disks: compressed by the walls first (no trend while
// they close in), then settling (the criteria decay), then friction on.
SceneConfig gas() {
  return parse_config_text(test::with_required_material(
                               R"({"assembly": {"type": "random", "count": 150, "radius_min": 4e-4,
              "radius_max": 6e-4, "seed": 3}})"),
                           "gas");
}

// A consolidation's wall time: three significant digits whatever the
// stream's format, whole seconds from 1000 s on (a prototype's: "4012 s",
// not "4.01e+03 s"), the stream's format left as it was.
TEST(ConsolidationProgress, TheWallTimeHasOneFormat) {
  const auto printed = [](double s, bool from_cache, std::ios_base& (*format)(std::ios_base&)) {
    std::ostringstream o, reference;
    o << format << std::setprecision(9);
    reference << format << std::setprecision(9) << 0.5;
    cli::print_consolidation_time(o, s, from_cache);
    const std::string time = o.str();
    o << 0.5;  // the stream's own format afterwards, as it was
    EXPECT_EQ(o.str().substr(time.size()), reference.str());
    return time;
  };
  for (auto* format : {&std::defaultfloat, &std::fixed, &std::scientific}) {
    EXPECT_EQ(printed(0.00255984, false, format), "0.00256 s");
    EXPECT_EQ(printed(12.3456, true, format), "read from the cache in 12.3 s");
    EXPECT_EQ(printed(4012.35, false, format), "4012 s");
    EXPECT_EQ(printed(0.5, false, format), "0.5 s");
  }
}

TEST(ConsolidationProgress, EveryCheckIsReportedWithAPositiveEstimate) {
  const SceneConfig c = gas();
  const Assembly a = make_assembly(c);
  std::vector<ConsolidationProgress> seen;
  ConsolidationOptions o;
  o.progress = [&](const ConsolidationProgress& p) { seen.push_back(p); };
  const ConsolidatedState s = consolidate(c, a, "", o);
  ASSERT_TRUE(s.converged);
  // One report per check (every 200 steps), the last one at the last step.
  ASSERT_EQ(static_cast<int64_t>(seen.size()) * 200, s.steps);
  EXPECT_EQ(seen.back().steps, s.steps);
  EXPECT_EQ(seen.back().phase, 1);
  EXPECT_EQ(seen.back().stress_error, s.stress_error);
  EXPECT_EQ(seen.back().unbalanced_ratio, s.unbalanced_ratio);
  EXPECT_EQ(seen.back().steps_to_go, 0);  // static: nothing to go
  int trends = 0;
  for (size_t k = 0; k < seen.size(); ++k) {
    const ConsolidationProgress& p = seen[k];
    SCOPED_TRACE("check " + std::to_string(k));
    EXPECT_EQ(p.steps, 200 * static_cast<int64_t>(k + 1));
    EXPECT_EQ(p.max_steps, c.test.consolidation_max_steps);
    if (k > 0) {
      EXPECT_GE(p.phase, seen[k - 1].phase);
      EXPECT_GE(p.elapsed_s, seen[k - 1].elapsed_s);
    }
    EXPECT_GT(p.elapsed_s, 0.0);
    EXPECT_GT(p.remaining_max_s, 0.0);  // the budget is far from spent
    const bool met = p.stress_error < c.test.consolidation_tolerance &&
                     p.unbalanced_ratio < c.test.consolidation_unbalanced;
    if (met) {
      EXPECT_EQ(p.steps_to_go, 0);
      EXPECT_EQ(p.remaining_s, 0.0);
    } else {
      EXPECT_NE(p.steps_to_go, 0);
      EXPECT_GT(p.remaining_s, 0.0);
      EXPECT_LE(p.remaining_s, p.remaining_max_s);
      if (p.steps_to_go < 0) {
        EXPECT_EQ(p.remaining_s, p.remaining_max_s);
      }
      trends += p.steps_to_go > 0;
    }
  }
  // The settling is seen converging (the gas compression is not).
  EXPECT_GT(trends, 0);
  EXPECT_EQ(seen.front().steps_to_go, -1);
  std::printf("150-disk gas: %lld steps, %zu reports, %d with a trend\n",
              static_cast<long long>(s.steps), seen.size(), trends);
}

TEST(ConsolidationProgress, ThreadsAndReportsDoNotChangeTheState) {
  const SceneConfig c = gas();
  const Assembly a = make_assembly(c);
  const ConsolidatedState plain = consolidate(c, a, "");
  ConsolidationOptions o;
  o.threads = 2;
  int calls = 0;
  o.progress = [&](const ConsolidationProgress&) { ++calls; };
  const ConsolidatedState threaded = consolidate(c, a, "", o);
  EXPECT_GT(calls, 0);
  ASSERT_EQ(threaded.steps, plain.steps);
  ASSERT_EQ(threaded.world.size(), plain.world.size());
  for (int i = 0; i < plain.world.size(); ++i) {
    ASSERT_EQ(threaded.world.x()[i], plain.world.x()[i]) << "particle " << i;
    ASSERT_EQ(threaded.world.y()[i], plain.world.y()[i]) << "particle " << i;
    ASSERT_EQ(threaded.world.rotation()[i], plain.world.rotation()[i]) << "particle " << i;
    ASSERT_EQ(threaded.world.fx()[i], plain.world.fx()[i]) << "particle " << i;
  }
  EXPECT_EQ(threaded.width0, plain.width0);
  EXPECT_EQ(threaded.height0, plain.height0);
  // The state steps on one thread afterwards, as every World starts.
  EXPECT_EQ(threaded.world.threads(), 1);
}

// The 3D consolidation (consolidate_triaxial): a random gas of 120 spheres
// (σ3 = 1e7 Pa: the stiffness level of configs/random_500_3d.json) on two
// threads with a callback reaches the single-threaded state bit for bit,
// and reports every check.
TEST(ConsolidationProgress, SphereThreadsAndReportsDoNotChangeTheState) {
  const SceneConfig c = parse_config_text(
      test::with_required_material(
          R"({"dimension": 3, "assembly": {"type": "random", "count": 120, "radius_min": 4e-4,
              "radius_max": 6e-4, "seed": 5}, "test": {"lateral_stress": 1e7}})"),
      "gas3d");
  const SphereAssembly a = make_sphere_assembly(c);
  const TriaxialState plain = consolidate_triaxial(c, a);
  ConsolidationOptions o;
  o.threads = 2;
  std::vector<ConsolidationProgress> seen;
  o.progress = [&](const ConsolidationProgress& p) { seen.push_back(p); };
  const TriaxialState threaded = consolidate_triaxial(c, a, o);
  ASSERT_TRUE(plain.converged);
  ASSERT_EQ(threaded.steps, plain.steps);
  ASSERT_EQ(static_cast<int64_t>(seen.size()) * 200, threaded.steps);
  EXPECT_EQ(seen.back().phase, 1);
  EXPECT_EQ(seen.back().stress_error, threaded.stress_error);
  EXPECT_EQ(seen.back().steps_to_go, 0);
  const SphereWorld& p = plain.world;
  const SphereWorld& t = threaded.world;
  ASSERT_EQ(t.size(), p.size());
  for (int i = 0; i < p.size(); ++i) {
    ASSERT_EQ(t.x()[i], p.x()[i]) << "sphere " << i;
    ASSERT_EQ(t.y()[i], p.y()[i]) << "sphere " << i;
    ASSERT_EQ(t.z()[i], p.z()[i]) << "sphere " << i;
    ASSERT_EQ(t.fx()[i], p.fx()[i]) << "sphere " << i;
    ASSERT_EQ(t.fz()[i], p.fz()[i]) << "sphere " << i;
    ASSERT_EQ(t.omega_x()[i], p.omega_x()[i]) << "sphere " << i;
  }
  for (int s = 0; s < 6; ++s)
    EXPECT_EQ(t.wall(static_cast<SphereWallSide>(s)).position,
              p.wall(static_cast<SphereWallSide>(s)).position);
  EXPECT_EQ(threaded.stress_error, plain.stress_error);
  EXPECT_EQ(threaded.unbalanced_ratio, plain.unbalanced_ratio);
  EXPECT_EQ(t.threads(), 1);
  std::printf("120-sphere gas: %lld steps, %zu reports\n", static_cast<long long>(plain.steps),
              seen.size());
}

// The frictionless phase gets at most the first quarter of the budget
// (critical_damping_after), and at most half of it (frictionless_phase_cut):
// one not static by then ends there and friction goes on, at the light
// damping, which locks the packing; critical damping comes at twice the
// quarter. Before, the frictionless phase crept on at critical damping:
// random_400 with a 40 000-step budget, and random_500_3d with 100 000, never
// came to rest (exit 1); the shipped budgets' runs, whose frictionless
// phases end before the quarter, are unchanged. `cut`: the check phase 0
// must end at.
template <class State, class Consolidate>
void expect_the_frictionless_phase_cut(const SceneConfig& c, int64_t cut,
                                       Consolidate consolidate_it) {
  std::vector<ConsolidationProgress> seen;
  ConsolidationOptions o;
  o.progress = [&](const ConsolidationProgress& p) { seen.push_back(p); };
  const State s = consolidate_it(o);
  ASSERT_TRUE(s.converged);
  ASSERT_FALSE(seen.empty());
  // The premise: still frictionless and not static at the cut.
  const auto at_cut =
      std::find_if(seen.begin(), seen.end(), [&](const auto& p) { return p.steps == cut; });
  ASSERT_NE(at_cut, seen.end());
  EXPECT_EQ(at_cut->phase, 0);
  EXPECT_FALSE(at_cut->stress_error < c.test.consolidation_tolerance &&
               at_cut->unbalanced_ratio < c.test.consolidation_unbalanced);
  // Phase 0's estimate of the steps it has left never passes the cut, where
  // it ends (it did: random_400 with a 40 000-step budget, at step 3 400 of
  // a phase cut at 10 000, estimated 40 000 more).
  int capped = 0;
  for (auto p = seen.begin(); p != at_cut; ++p) {
    EXPECT_LE(p->steps + p->steps_to_go, cut) << "at step " << p->steps;
    capped += p->steps + p->steps_to_go == cut;
  }
  EXPECT_GT(capped, 0);  // the premise: the trend ran past the cut
  // Friction from the next check on, static within the budget.
  ASSERT_NE(at_cut + 1, seen.end());
  EXPECT_EQ((at_cut + 1)->phase, 1);
  EXPECT_GT(s.steps, cut);
  EXPECT_LE(s.steps, c.test.consolidation_max_steps);
  std::printf("%s, contact damping %g, budget %lld: frictionless until %lld, static at %lld\n",
              c.name.c_str(), c.material.contact_damping_ratio,
              static_cast<long long>(c.test.consolidation_max_steps), static_cast<long long>(cut),
              static_cast<long long>(s.steps));
}

TEST(ConsolidationProgress, AFrictionlessPhaseNotStaticByTheQuarterEndsThere) {
  SceneConfig c = load_config(test::shipped_config("random_400"));
  c.test.consolidation_max_steps = 40000;
  const Assembly a = make_assembly(c);
  const int64_t quarter = c.test.consolidation_max_steps / 4;
  expect_the_frictionless_phase_cut<ConsolidatedState>(
      c, quarter, [&](const ConsolidationOptions& o) {
        const ConsolidatedState s = consolidate(c, a, "", o);
        EXPECT_LE(s.steps, 2 * quarter);  // at the light damping
        return s;
      });
}

TEST(ConsolidationProgress, AFrictionlessSpherePhaseNotStaticByTheQuarterEndsThere) {
  SceneConfig c = load_config(test::shipped_config("random_500_3d"));
  c.test.consolidation_max_steps = 100000;
  const SphereAssembly a = make_sphere_assembly(c);
  const int64_t quarter = c.test.consolidation_max_steps / 4;
  expect_the_frictionless_phase_cut<TriaxialState>(c, quarter, [&](const ConsolidationOptions& o) {
    const TriaxialState s = consolidate_triaxial(c, a, o);
    EXPECT_LE(s.steps, 2 * quarter);  // at the light damping
    return s;
  });
}

// Contact dashpots strong enough that the consolidation's step shrinks
// below a quarter of the undamped one (S < 1/4) put the quarter in
// simulated time past the budget's end: the frictionless phase had no cut,
// crept on to the end of the budget and failed (exit 1: random_400 at ζ_c 1
// with a 60 000-step budget, random_500_3d at ζ_c 0.5 with 100 000; at the
// shipped 2·10⁶, random_500_3d at ζ_c 5 after 2·10⁶ frictionless steps).
// Now it ends at half the budget, and friction locks the packing.
template <class State, class Make, class Consolidate>
void expect_a_cut_at_half_the_budget(SceneConfig c, double zeta_c, int64_t budget, Make make,
                                     Consolidate consolidate_it) {
  c.material.contact_damping_ratio = zeta_c;
  c.test.consolidation_max_steps = budget;
  const auto a = make(c);
  const auto radii = std::minmax_element(a.r.begin(), a.r.end());
  const double shrink = consolidation_step_shrink(
      consolidation_alpha(zeta_c, c.dimension, *radii.first, *radii.second));
  ASSERT_LT(shrink, 0.25);  // the premise: the quarter lies past the budget
  ASSERT_GT(critical_damping_after(budget, shrink), budget);
  ASSERT_EQ(frictionless_phase_cut(budget, shrink), budget / 2);
  expect_the_frictionless_phase_cut<State>(
      c, budget / 2, [&](const ConsolidationOptions& o) { return consolidate_it(c, a, o); });
}

TEST(ConsolidationProgress, WithStrongContactDashpotsTheFrictionlessPhaseEndsAtHalfTheBudget) {
  expect_a_cut_at_half_the_budget<ConsolidatedState>(
      load_config(test::shipped_config("random_400")), 1.0, 60000,
      [](const SceneConfig& c) { return make_assembly(c); },
      [](const SceneConfig& c, const Assembly& a, const ConsolidationOptions& o) {
        return consolidate(c, a, "", o);
      });
  expect_a_cut_at_half_the_budget<TriaxialState>(
      load_config(test::shipped_config("random_500_3d")), 0.5, 100000,
      [](const SceneConfig& c) { return make_sphere_assembly(c); },
      [](const SceneConfig& c, const SphereAssembly& a, const ConsolidationOptions& o) {
        return consolidate_triaxial(c, a, o);
      });
}

// One callback serves consolidations one after another (scaling's sizes):
// each starts again at step 200 and time 0, and its lines come every
// `every_s` of its own time. (The callback kept the last line's time of the
// one before, so a later consolidation printed nothing until its clock
// passed that time, then counted from it.) The second one here is slow to
// start (its first check at 4.5 s): its first line is that check's.
TEST(ConsolidationProgress, OneCallbackServesConsolidationsOneAfterAnother) {
  const ConsolidationCallback callback = cli::consolidation_progress(2.0);
  std::ostringstream captured;
  std::streambuf* const old = std::cerr.rdbuf(captured.rdbuf());
  for (const double start_s : {0.0, 4.0})
    for (int k = 1; k <= 10; ++k) {
      ConsolidationProgress p;
      p.steps = 200 * k;
      p.max_steps = 2'000'000;
      p.elapsed_s = start_s + 0.5 * k;
      callback(p);
    }
  std::cerr.rdbuf(old);
  std::vector<std::string> lines;
  std::istringstream in(captured.str());
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  // The first: lines at 2 s and 4 s (steps 800, 1600); the second at 4.5,
  // 6.5 and 8.5 s (steps 200, 1000, 1800).
  const std::vector<int> steps = {800, 1600, 200, 1000, 1800};
  ASSERT_EQ(lines.size(), steps.size()) << captured.str();
  for (size_t k = 0; k < steps.size(); ++k)
    EXPECT_NE(lines[k].find("step " + std::to_string(steps[k]) + " of at most "), std::string::npos)
        << lines[k];
}

std::vector<std::string> progress_lines(const std::string& err) {
  std::vector<std::string> lines;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("consolidating (", 0) == 0) lines.push_back(line);
  return lines;
}

TEST(ConsolidationProgress, ExportPrintsProgressOnStderr) {
  // --progress 0 prints at every check (the default, 2 s, keeps a short
  // consolidation quiet): the lines a long one prints, in a fast test.
  const test::TempDir dir("consolidation_progress");
  const std::string params = test::example_params("hex_10x10");
  const auto every = test::run_demcal({"export", params, "--particles", "100", "--consolidate-in",
                                       "demcal", "--progress", "0", "-o", "a/deck.lammps"},
                                      dir.path());
  ASSERT_EQ(every.status, 0) << every.err;
  const std::vector<std::string> lines = progress_lines(every.err);
  ASSERT_GE(lines.size(), 2u) << every.err;
  EXPECT_NE(lines.front().find("consolidating (frictionless): step 200 of at most "),
            std::string::npos)
      << lines.front();
  EXPECT_NE(lines.back().find("consolidating (friction on)"), std::string::npos) << lines.back();
  for (const std::string& l : lines) {
    EXPECT_NE(l.find(" so far, "), std::string::npos) << l;
    EXPECT_NE(l.find("(the step budget)"), std::string::npos) << l;
  }
  const auto quiet = test::run_demcal(
      {"export", params, "--particles", "100", "--consolidate-in", "demcal", "-o", "b/deck.lammps"},
      dir.path());
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_TRUE(progress_lines(quiet.err).empty()) << quiet.err;
  EXPECT_EQ(test::read_text(dir.path() / "a" / "deck.lammps"),
            test::read_text(dir.path() / "b" / "deck.lammps"));
  EXPECT_EQ(
      test::run_demcal({"export", params, "--progress", "-1", "-o", "c/deck.lammps"}, dir.path())
          .status,
      2);
}

}  // namespace
}  // namespace demcal
