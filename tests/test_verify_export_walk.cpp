// `demcal verify` and `demcal export` as a first-time user met them (the
// walk of 2026-12-04): a consolidation read from the cache printed as if it
// had been computed; verify's LAMMPS deck of a failed calibration without
// export's NOT CERTIFIED header; "steps upscaled" for a prototype of the
// REV's own size; the deck's run length learnt from a throwaway deck; and
// `export -o FOLDER/` checked by a rule of its own (it consolidated, then
// failed with an internal error).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/export_3d.hpp"
#include "support/files.hpp"
#include "support/process.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

/// demcal ARGS in `cwd` with the environment `env` ("KEY=VALUE") added.
test::RunResult demcal_with(const std::vector<std::string>& env,
                            const std::vector<std::string>& args, const fs::path& cwd) {
  std::vector<std::string> all = env;
  all.push_back(test::kDemcalBinary);
  all.insert(all.end(), args.begin(), args.end());
  return test::run_program("/usr/bin/env", all, cwd);
}

/// The first line of `text` that starts with `start`, else "no line START".
std::string line_of(const std::string& text, const std::string& start) {
  for (const std::string& line : test::lines_of(text))
    if (line.rfind(start, 0) == 0) return line;
  return "no line " + start;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A prototype's consolidation read from the cache (DEMCAL_CACHE_DIR) was
// printed by verify as its computing time, unlabelled, and verify.json did
// not say where it came from. Now verify (2D and 3D, --consolidate-only)
// and export label it as check and run do ("read from the cache in T s",
// print_consolidation_time) and verify.json's consolidation records
// from_cache; a fresh consolidation's lines are unchanged.
TEST(VerifyExportWalk, AConsolidationFromTheCacheIsLabelledAndRecorded) {
  const test::TempDir dir("walk_cache");
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir / "cache").string();
  struct Case {
    std::string scene, particles;
  };
  for (const Case& c : {Case{"hex_10x10", "25"}, Case{"fcc_4x4x4", "32"}}) {
    SCOPED_TRACE(c.scene);
    const std::string params = test::example_params(c.scene);
    auto verify = [&](const std::string& out) {
      const test::RunResult r = demcal_with(
          {cache}, {"verify", params, "--particles", c.particles, "-o", out}, dir.path());
      EXPECT_TRUE(r.status == 0 || r.status == 1) << r.err;  // PASS or FAIL, both reported
      return r;
    };
    const test::RunResult miss = verify(c.scene + "-miss");
    const test::RunResult hit = verify(c.scene + "-hit");
    const nlohmann::json fresh = test::read_json(dir / (c.scene + "-miss") / "verify.json");
    const nlohmann::json read = test::read_json(dir / (c.scene + "-hit") / "verify.json");
    ASSERT_TRUE(fresh.at("consolidation").contains("from_cache")) << fresh.dump(1);
    EXPECT_FALSE(fresh["consolidation"]["from_cache"].get<bool>());
    EXPECT_TRUE(read.at("consolidation").at("from_cache").get<bool>());
    EXPECT_EQ(read["consolidation"]["steps"], fresh["consolidation"]["steps"]);
    // stdout: "  consolidation T s, loading ..."; read: "  consolidation
    // read from the cache in T s, loading ...".
    const std::string fresh_line = line_of(miss.out, "  consolidation ");
    const std::string read_line = line_of(hit.out, "  consolidation ");
    EXPECT_FALSE(contains(fresh_line, "cache")) << fresh_line;
    EXPECT_TRUE(contains(fresh_line, " s, loading ")) << fresh_line;
    EXPECT_EQ(read_line.rfind("  consolidation read from the cache in ", 0), 0u) << read_line;
    EXPECT_TRUE(contains(read_line, " s, loading ")) << read_line;
    // stderr: "consolidated in N steps, T s" / "..., read from the cache in T s".
    const std::string steps = "demcal verify: consolidated in " +
                              std::to_string(fresh["consolidation"]["steps"].get<int64_t>()) +
                              " steps, ";
    EXPECT_TRUE(contains(miss.err, steps)) << miss.err;
    EXPECT_FALSE(contains(miss.err, "cache")) << miss.err;
    EXPECT_TRUE(contains(hit.err, steps + "read from the cache in ")) << hit.err;
  }
  // --consolidate-only (2D) and export say it too.
  const std::string params = test::example_params("hex_10x10");
  const test::RunResult only = demcal_with(
      {cache}, {"verify", params, "--particles", "25", "--consolidate-only", "-o", "only"},
      dir.path());
  ASSERT_EQ(only.status, 0) << only.err;
  EXPECT_TRUE(contains(only.out, " steps, read from the cache in ")) << only.out;
  const test::RunResult exported =
      demcal_with({cache}, {"export", params, "--particles", "25", "-o", "d.lammps"}, dir.path());
  ASSERT_EQ(exported.status, 0) << exported.err;
  EXPECT_TRUE(contains(line_of(exported.err, "demcal export: consolidated in "),
                       " steps, read from the cache in "))
      << exported.err;
}

// `demcal export` printed "consolidating the prototype (...) to sigma3 ...,
// single-threaded" before it found the state in the consolidation cache:
// now that line comes only before a consolidation, 2D and 3D (--consolidate-in
// demcal), and a cache read's line says it was read (print_consolidation_time).
TEST(VerifyExportWalk, ExportSaysConsolidatingOnlyWhenItConsolidates) {
  const test::TempDir dir("walk_export_cache");
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir / "cache").string();
  struct Case {
    std::string scene, particles;
  };
  for (const Case& c : {Case{"hex_10x10", "25"}, Case{"fcc_4x4x4", "32"}}) {
    SCOPED_TRACE(c.scene);
    auto exported = [&](const std::string& deck) {
      const test::RunResult r = demcal_with({cache},
                                            {"export", test::example_params(c.scene), "--particles",
                                             c.particles, "--consolidate-in", "demcal", "-o", deck},
                                            dir.path());
      EXPECT_EQ(r.status, 0) << r.err;
      return r;
    };
    const test::RunResult miss = exported(c.scene + "-miss.lammps");
    const test::RunResult hit = exported(c.scene + "-hit.lammps");
    const std::string consolidating = "demcal export: consolidating the prototype (";
    EXPECT_TRUE(contains(miss.err, consolidating)) << miss.err;
    EXPECT_FALSE(contains(hit.err, consolidating)) << hit.err;
    EXPECT_FALSE(contains(hit.err, "single-threaded")) << hit.err;
    const std::string fresh = line_of(miss.err, "demcal export: consolidated in ");
    const std::string read = line_of(hit.err, "demcal export: consolidated in ");
    EXPECT_FALSE(contains(fresh, "cache")) << fresh;
    const size_t comma = fresh.find(" steps, ");
    ASSERT_NE(comma, std::string::npos) << fresh;
    EXPECT_EQ(read.rfind(fresh.substr(0, comma + 8) + "read from the cache in ", 0), 0u) << read;
    // The consolidated prototype (the deck's data file) is the same either way.
    EXPECT_TRUE(test::read_text(dir / (c.scene + "-hit.lammps.data")) ==
                test::read_text(dir / (c.scene + "-miss.lammps.data")));
  }
}

// `demcal verify` said before its consolidation what it would cost ("plus
// consolidation, short for a dense packing", "--consolidate-only: the
// consolidation alone (long for a loose gas)", 3D: "plus a single-thread
// consolidation"), a read from the cache too: now "consolidating the
// prototype (...)" says it only when it consolidates (consolidate_announced),
// 2D (also --consolidate-only) and 3D, as export does.
TEST(VerifyExportWalk, VerifySaysConsolidatingOnlyWhenItConsolidates) {
  const test::TempDir dir("walk_verify_announce");
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir / "cache").string();
  struct Case {
    std::string scene, particles, how;  // how: the announcement's words
    std::vector<std::string> more;
  };
  for (const Case& c :
       {Case{"hex_10x10", "25", "(short for a dense packing)", {}},
        Case{"hex_10x10", "36", "(short for a dense packing)", {"--consolidate-only"}},
        Case{"fcc_4x4x4", "32", "(single-threaded)", {}}}) {
    SCOPED_TRACE(c.scene + " " + c.particles);
    auto verify = [&](const std::string& out) {
      std::vector<std::string> args = {"verify",      test::example_params(c.scene),
                                       "--particles", c.particles,
                                       "-o",          c.scene + c.particles + out};
      args.insert(args.end(), c.more.begin(), c.more.end());
      const test::RunResult r = demcal_with({cache}, args, dir.path());
      EXPECT_TRUE(r.status == 0 || r.status == 1) << r.err;  // PASS or FAIL, both reported
      return r;
    };
    const test::RunResult miss = verify("-miss");
    const test::RunResult hit = verify("-hit");
    const std::string consolidating = "demcal verify: consolidating the prototype ";
    EXPECT_EQ(line_of(miss.err, consolidating), consolidating + c.how) << miss.err;
    EXPECT_FALSE(contains(hit.err, "consolidating")) << hit.err;
    // No forecast of the consolidation's cost either (the old ones: "short
    // for a dense packing", "long for a loose gas", "a single-thread
    // consolidation").
    for (const char* forecast : {"short for", "long for", "single-thread"})
      EXPECT_FALSE(contains(hit.err, forecast)) << forecast << " in:\n" << hit.err;
    EXPECT_TRUE(contains(line_of(hit.err, "demcal verify: consolidated in "),
                         " steps, read from the cache in "))
        << hit.err;
  }
}

// 3D `verify` consolidated its prototype on one thread whatever --threads
// said (the loading alone used them), and a large prototype's
// consolidation is most of its time: it now runs on the loading's threads,
// says so, and reaches the same state, so the same series, bit for bit.
TEST(VerifyExportWalk, Verify3dConsolidatesOnItsThreads) {
  const test::TempDir dir("walk_verify_threads");
  std::string series[2];
  for (const int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    const std::string out = "t" + std::to_string(threads);
    const test::RunResult r =
        demcal_with({"DEMCAL_CACHE_DIR=off"},
                    {"verify", test::example_params("fcc_4x4x4"), "--particles", "256", "--threads",
                     std::to_string(threads), "-o", out},
                    dir.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(line_of(r.err, "demcal verify: consolidating the prototype "),
              threads == 1 ? "demcal verify: consolidating the prototype (single-threaded)"
                           : "demcal verify: consolidating the prototype (on 2 threads)")
        << r.err;
    series[threads - 1] = test::read_text(dir.path() / out / "series.csv");
    ASSERT_FALSE(series[threads - 1].empty());
  }
  EXPECT_TRUE(series[0] == series[1]);
}

// `verify --engine lammps --allow-failed` ran a deck whose header did not
// say that its parameters are not certified, which `export --allow-failed`
// writes (deck_sections.cpp's header_opening, from params.json's success and
// message: uncertified_reason). The deck is written before LAMMPS runs; a
// stand-in lmp that fails at once keeps this test free of LAMMPS.
TEST(VerifyExportWalk, VerifysLammpsDeckSaysNotCertifiedAsExportsDeckDoes) {
  const test::TempDir dir("walk_uncertified");
  nlohmann::json params = test::read_json(test::example_params("hex_10x10"));
  ASSERT_EQ(params["success"], true);
  params["success"] = false;
  params["message"] = "the best passing parameters did not pass the convergence certificate";
  test::write_text(dir / "failed.json", params.dump(1));
  const std::string lmp = test::write_text(dir / "bin" / "lmp", "#!/bin/sh\nexit 3\n");
  ASSERT_EQ(::chmod(lmp.c_str(), 0755), 0);
  const std::string path = "PATH=" + (dir / "bin").string() + ":/usr/bin:/bin";
  const test::RunResult verified = demcal_with({path},
                                               {"verify", "failed.json", "--particles", "25",
                                                "--engine", "lammps", "--allow-failed", "-o", "v"},
                                               dir.path());
  EXPECT_NE(verified.status, 0);  // the stand-in lmp failed
  EXPECT_TRUE(contains(verified.err, "LAMMPS failed")) << verified.err;
  const test::RunResult exported = test::run_demcal(
      {"export", "failed.json", "--particles", "25", "--allow-failed", "-o", "e.lammps"},
      dir.path());
  ASSERT_EQ(exported.status, 0) << exported.err;
  // The header's NOT CERTIFIED lines, up to the header's first "#" line.
  auto uncertified_of = [](const std::string& deck) {
    const auto at = deck.find("# NOT CERTIFIED");
    return at == std::string::npos ? std::string() : deck.substr(at, deck.find("\n#\n", at) - at);
  };
  const std::string verify_deck = test::read_text(dir / "v" / "lammps" / "deck.lammps");
  ASSERT_FALSE(verify_deck.empty());
  const std::string header = uncertified_of(test::read_text(dir / "e.lammps"));
  ASSERT_FALSE(header.empty());
  EXPECT_EQ(uncertified_of(verify_deck), header) << verify_deck.substr(0, 1500);
  EXPECT_LT(verify_deck.find("# NOT CERTIFIED"), verify_deck.find("\n#\n"));
  // The estimate's run length (deck_steps) is the one the deck runs.
  const std::string nstep = line_of(verify_deck, "variable nstep ");
  const std::string estimated = line_of(verified.err, "demcal verify: LAMMPS loading = ");
  const size_t at = estimated.find(" = ") + 3;
  const std::string steps = estimated.substr(at, estimated.find(' ', at) - at);
  EXPECT_TRUE(contains(nstep, " equal " + steps + " ")) << nstep << "\n" << estimated;
  // A certified calibration's deck has no such line.
  const test::RunResult certified =
      demcal_with({path},
                  {"verify", test::example_params("hex_10x10"), "--particles", "25", "--engine",
                   "lammps", "-o", "c"},
                  dir.path());
  EXPECT_NE(certified.status, 0);
  EXPECT_FALSE(contains(test::read_text(dir / "c" / "lammps" / "deck.lammps"), "CERTIFIED"));
}

// `export --particles N` with N the REV's own count said "88140 steps
// upscaled from 100 particles / 88140 steps (linear law ...)" although
// nothing is upscaled; it says so now (factor 1), as verify does; another
// count still names the law.
TEST(VerifyExportWalk, APrototypeOfTheRevsSizeIsSaidNotUpscaled) {
  const test::TempDir dir("walk_rev_size");
  struct Case {
    std::string scene, rev, other, what;
  };
  for (const Case& c :
       {Case{"hex_10x10", "100", "400", "particles"}, Case{"fcc_4x4x4", "256", "500", "spheres"}}) {
    SCOPED_TRACE(c.scene);
    const std::string params = test::example_params(c.scene);
    const int64_t steps = test::read_json(params)["rev"]["steps"].get<int64_t>();
    const std::string same = "demcal export: " + std::to_string(steps) +
                             " steps, the REV's: not upscaled (the prototype has the REV's " +
                             c.rev + " " + c.what + ", factor 1)";
    // The deck consolidates (--consolidate-in deck): nothing runs here.
    const test::RunResult at_rev =
        test::run_demcal({"export", params, "--particles", c.rev, "--consolidate-in", "deck", "-o",
                          c.scene + "-rev.lammps"},
                         dir.path());
    ASSERT_EQ(at_rev.status, 0) << at_rev.err;
    EXPECT_FALSE(contains(at_rev.err, "upscaled from")) << at_rev.err;
    EXPECT_EQ(line_of(at_rev.err, "demcal export: " + std::to_string(steps) + " steps"), same)
        << at_rev.err;
    const test::RunResult other =
        test::run_demcal({"export", params, "--particles", c.other, "--consolidate-in", "deck",
                          "-o", c.scene + "-other.lammps"},
                         dir.path());
    ASSERT_EQ(other.status, 0) << other.err;
    EXPECT_TRUE(contains(other.err, " steps upscaled from " + c.rev + " " + c.what + " / " +
                                        std::to_string(steps) + " steps ("))
        << other.err;
  }
  // verify's line says the same (--consolidate-only: the line comes first).
  const test::RunResult verified =
      test::run_demcal({"verify", test::example_params("hex_10x10"), "--particles", "100",
                        "--consolidate-only", "-o", "v"},
                       dir.path());
  ASSERT_EQ(verified.status, 0) << verified.err;
  EXPECT_FALSE(contains(verified.err, "steps upscaled (")) << verified.err;
  EXPECT_TRUE(contains(verified.err,
                       "; 88140 steps, the REV's: not upscaled (the prototype has "
                       "the REV's 100 particles, factor 1)\n"))
      << verified.err;
}

// The deck's run length has one home, deck_steps (Nstep/f): the 2D and 3D
// decks of both formats write it, and `verify --engine lammps` estimates
// from it instead of building a throwaway deck.
TEST(VerifyExportWalk, DeckStepsIsTheRunLengthEveryDeckWrites) {
  const SceneConfig disks = load_config(test::shipped_config("hex_5x5"));
  const Assembly assembly = make_assembly(disks);
  const SceneConfig spheres = load_config(test::shipped_config("fcc_4x4x4"));
  const SphereAssembly balls = make_sphere_assembly(spheres);
  for (const double zeta : {0.0, 0.3, 0.7, 1.5})
    for (const int64_t steps : {1, 7, 1000, 88140}) {
      SCOPED_TRACE("zeta_t " + std::to_string(zeta) + ", Nstep " + std::to_string(steps));
      AlgorithmSpec p = disks.algorithm;
      p.damping_ratio_translation = zeta;
      p.steps = steps;
      const int64_t expected = std::max<int64_t>(
          1, std::llround(static_cast<double>(steps) / dashpot_step_factor(zeta)));
      EXPECT_EQ(deck_steps(p), expected);
      for (const char* format : {"lammps", "liggghts"}) {
        SCOPED_TRACE(format);
        ExportOptions o;
        o.format = format;
        EXPECT_EQ(export_deck(disks, p, assembly, o).steps, deck_steps(p));
        Export3dOptions o3;
        o3.format = format;
        EXPECT_EQ(export_3d_decks(spheres, p, balls, o3).steps, deck_steps(p));
      }
    }
}

// `export -o FOLDER/` (a name ending in a separator) passed export's own
// check of the destination, consolidated the prototype, then failed with
// "OutputTransaction: not a name inside the folder" (exit 1). The deck's
// destination is checked as every -o FILE is (check_output_file): exit 2
// before anything runs, nothing made.
TEST(VerifyExportWalk, ExportToAFolderNameIsRefusedBeforeAnythingRuns) {
  const test::TempDir dir("walk_deck_dir");
  fs::create_directory(dir / "there");
  for (const std::string out : {"new/", "there", "there/"}) {
    SCOPED_TRACE(out);
    const test::RunResult r = test::run_demcal(
        {"export", test::example_params("hex_10x10"), "--particles", "25", "-o", out}, dir.path());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "is a folder; give a file name")) << r.err;
    EXPECT_FALSE(contains(r.err, "consolidat")) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "new"));
  EXPECT_TRUE(fs::is_empty(dir / "there"));
}

}  // namespace
}  // namespace demcal
