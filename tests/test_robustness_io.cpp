// Robustness of the io layer and the output folder (issue 14 §2): files that
// are not demcal's are never touched, only regular files are written, and a
// command's outputs change together or not at all. One regression test per
// class; the full-disk case mounts a small tmpfs (skipped where it cannot).
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/io/files.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/run_status.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

using test::names_in;
using test::read_text;

using test::dead_pid;

class RobustIo : public ::testing::Test {
 protected:
  void put(const fs::path& p, const std::string& content) { test::write_text(p, content); }
  test::TempDir tmp_{"robust_io"};
  const fs::path dir_ = tmp_.path();
};

// A user's thesis.tmp.4242 was deleted as a "stale temporary".
TEST_F(RobustIo, OnlyDemcalTemporariesOfDeadProcessesAreRemoved) {
  EXPECT_EQ(temporary_name("params.json", 42), ".demcal-tmp-42-params.json");
  const pid_t dead = dead_pid();
  const std::string d = std::to_string(dead);
  const fs::path stale = dir_ / temporary_name("params.json", dead);
  const fs::path stale_stage = dir_ / temporary_name("stage1", dead);
  const fs::path live = dir_ / temporary_name("report.html", ::getppid());
  // Names a user might choose, even with the dead PID in them.
  const std::vector<fs::path> users = {dir_ / ("thesis.tmp." + d), dir_ / ("params.json.tmp." + d),
                                       dir_ / ".demcal-tmp-", dir_ / ".demcal-tmp-x-1",
                                       dir_ / (".demcal-tmp-" + d)};
  for (const auto& p : users) put(p, "mine");
  put(stale, "x");
  put(stale_stage / "summary.json", "x");
  put(live, "x");
  remove_stale_temporaries(dir_.string());
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(stale_stage));
  EXPECT_TRUE(fs::exists(live));
  for (const auto& p : users) EXPECT_EQ(read_text(p), "mine") << p;
}

// An atomic write leaves nothing but the file (its temporary is renamed).
TEST_F(RobustIo, AtomicWriteLeavesOnlyTheFile) {
  write_file_atomic((dir_ / "a.json").string(), "{}\n");
  write_file_atomic((dir_ / "a.json").string(), "{\"b\": 1}\n");
  EXPECT_EQ(read_text(dir_ / "a.json"), "{\"b\": 1}\n");
  EXPECT_EQ(names_in(dir_), (std::set<std::string>{"a.json"}));
}

// -o nullnode (a device node) was replaced by a regular file; as root -o
// /dev/null would have replaced /dev/null.
TEST_F(RobustIo, OnlyRegularFilesAreWritten) {
  const fs::path fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::create_directories(dir_ / "folder.json");
  fs::create_symlink("/dev/null", dir_ / "link");
  for (const fs::path& target :
       {fs::path("/dev/null"), fifo, dir_ / "folder.json", dir_ / "link"}) {
    SCOPED_TRACE(target.string());
    try {
      write_file_atomic(target.string(), "x");
      ADD_FAILURE() << "written";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), target.string());
      EXPECT_NE(std::string(e.what()).find("only regular files"), std::string::npos) << e.what();
    }
    EXPECT_THROW(append_line_durable(target.string(), "x"), InputError);
  }
  struct stat s {};
  ASSERT_EQ(::stat("/dev/null", &s), 0);
  EXPECT_TRUE(S_ISCHR(s.st_mode));
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_TRUE(fs::is_symlink(dir_ / "link"));
  // A transaction refuses such a target when the file is added.
  OutputTransaction t(dir_.string());
  EXPECT_THROW(t.add("fifo", "x"), InputError);
}

// Reading: a folder, a device, a symlink loop are one line naming the path.
TEST_F(RobustIo, UnreadableInputsAreOneLine) {
  fs::create_symlink(dir_ / "b", dir_ / "a");
  fs::create_symlink(dir_ / "a", dir_ / "b");
  for (const fs::path& p : {dir_ / "a", dir_, fs::path("/dev/zero"), dir_ / "missing"}) {
    SCOPED_TRACE(p.string());
    EXPECT_THROW(read_text_file(p.string()), InputError);
  }
  put(dir_ / "ok.txt", "text");
  EXPECT_EQ(read_text_file((dir_ / "ok.txt").string()), "text");
}

void put_old_run(const fs::path& out) {
  fs::create_directories(out);
  std::ofstream(out / "summary.json") << "old summary";
  std::ofstream(out / "series.csv") << "old series";
  std::ofstream(out / "final.vtk") << "old vtk";
  std::ofstream(out / "keep.txt") << "mine";
}

// Without commit (a failure half-way) the folder is exactly as it was.
TEST_F(RobustIo, UncommittedTransactionChangesNothing) {
  const fs::path out = dir_ / "out";
  put_old_run(out);
  const auto before = names_in(out);
  {
    OutputTransaction t(out.string());
    t.add("summary.json", "new summary");
    t.add("series/a.csv", "new series");
  }
  EXPECT_EQ(names_in(out), before);
  EXPECT_EQ(read_text(out / "summary.json"), "old summary");
  EXPECT_EQ(read_text(out / "series.csv"), "old series");
}

// A commit replaces every file at once; retired files of the earlier run go.
TEST_F(RobustIo, CommittedTransactionReplacesTogether) {
  const fs::path out = dir_ / "out";
  put_old_run(out);
  OutputTransaction t(out.string());
  t.add("summary.json", "new summary");
  t.add("series.csv", "new series");
  t.add("series/a.csv", "a");
  t.retire("final.vtk");  // this run writes no vtk
  t.retire("never-there.txt");
  t.commit();
  EXPECT_EQ(names_in(out),
            (std::set<std::string>{"summary.json", "series.csv", "series", "keep.txt"}));
  EXPECT_EQ(read_text(out / "summary.json"), "new summary");
  EXPECT_EQ(read_text(out / "series/a.csv"), "a");
  EXPECT_EQ(read_text(out / "keep.txt"), "mine");
}

/// A tmpfs of `kb` kilobytes at `at` (root only): false when it cannot be
/// mounted (not root, no permission in a container).
bool mount_small_disk(const fs::path& at, int kb) {
  fs::create_directories(at);
  const std::string options = "size=" + std::to_string(kb) + "k";
  return ::mount("tmpfs", at.c_str(), "tmpfs", 0, options.c_str()) == 0;
}

/// Fill the file system holding `dir` to the last byte.
void fill_disk(const fs::path& dir) {
  std::FILE* f = std::fopen((dir / "filler").c_str(), "wb");
  ASSERT_NE(f, nullptr);
  std::vector<char> block(4096, 'f');
  while (std::fwrite(block.data(), 1, block.size(), f) == block.size()) {
  }
  std::fclose(f);
}

// On a full disk a run into a folder holding an earlier run overwrote and
// then deleted the old summary.json. Now nothing changes, and the error
// says why.
TEST_F(RobustIo, FullDiskChangesNothingAndSaysSo) {
  const fs::path disk = dir_ / "disk";
  if (!mount_small_disk(disk, 256)) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  const fs::path out = disk / "out";
  put_old_run(out);
  fill_disk(disk);
  const auto before = names_in(out);
  std::string message;
  try {
    OutputTransaction t(out.string());
    t.add("summary.json", std::string(8192, 's'));
    t.add("series.csv", std::string(65536, 'c'));
    t.commit();
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("No space left on device"), std::string::npos) << message;
  EXPECT_NE(message.find("summary.json"), std::string::npos) << message;
  EXPECT_EQ(names_in(out), before);
  EXPECT_EQ(read_text(out / "summary.json"), "old summary");
  EXPECT_EQ(read_text(out / "series.csv"), "old series");
  // The single-file write: the same, the old file kept.
  message.clear();
  try {
    write_file_atomic((out / "series.csv").string(), std::string(65536, 'c'));
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("No space left on device"), std::string::npos) << message;
  EXPECT_EQ(read_text(out / "series.csv"), "old series");
  EXPECT_EQ(names_in(out), before);
  ::umount(disk.c_str());
}

// --- the demcal binary: the output folder every command shares ----------------

using Result = test::RunResult;
using test::run_demcal;

const std::string kHex5 = test::shipped_config("hex_5x5");

// -o naming a device node or a fifo: exit 2, the node untouched.
TEST_F(RobustIo, CliRefusesANonRegularOutput) {
  const fs::path fifo = dir_ / "nullnode";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const Result r =
      run_demcal({"run", kHex5, "--set", "algorithm.steps=200", "-o", fifo.string()}, dir_);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("nullnode"), std::string::npos) << r.err;
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
}

// A command that fails leaves no output folder it made (here consolidation
// runs out of steps: exit 1, after the folder was checked).
TEST_F(RobustIo, FailedCommandLeavesNoFolderItMade) {
  test::write_text(dir_ / "gas.json", "{" + test::kMaterialMember + R"(,
             "assembly": {"type": "random", "count": 60},
             "test": {"consolidation_max_steps": 1000}})");
  const fs::path out = dir_ / "new" / "deeper";
  const Result r = run_demcal({"run", "gas.json", "-o", out.string()}, dir_);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "new")) << r.err;
}

// A run into a folder holding an earlier run replaces its files together
// and leaves the user's files and no temporary.
TEST_F(RobustIo, CliRunReplacesAnEarlierRunAndKeepsUserFiles) {
  const fs::path out = dir_ / "out";
  put_old_run(out);
  const pid_t dead = dead_pid();
  std::ofstream(out / ("thesis.tmp." + std::to_string(dead))) << "mine";
  // A killed earlier run's staging folder is cleared.
  fs::create_directories(out / temporary_name("stage1", dead));
  std::ofstream(out / temporary_name("stage1", dead) / "summary.json") << "half";
  const Result r =
      run_demcal({"run", kHex5, "--set", "algorithm.steps=400", "-o", out.string()}, dir_);
  test::expect_run_status(r.status, out, r.err);  // 400 steps: FAIL, 1
  EXPECT_NE(read_text(out / "summary.json"), "old summary");
  EXPECT_NE(read_text(out / "final.vtk"), "old vtk");
  EXPECT_EQ(read_text(out / "keep.txt"), "mine");
  for (const auto& name : names_in(out))
    EXPECT_EQ(name.find(".demcal-tmp-"), std::string::npos) << name;
  EXPECT_EQ(names_in(out).size(), 5u);
}

// The full-disk run through the binary: exit 1, the reason, the old run kept.
TEST_F(RobustIo, CliRunOnAFullDiskKeepsTheEarlierRun) {
  const fs::path disk = dir_ / "disk";
  if (!mount_small_disk(disk, 512)) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  const fs::path out = disk / "out";
  put_old_run(out);
  fill_disk(disk);
  const Result r =
      run_demcal({"run", kHex5, "--set", "algorithm.steps=400", "-o", out.string()}, dir_);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(out / "summary.json"), "old summary");
  EXPECT_EQ(read_text(out / "series.csv"), "old series");
  EXPECT_EQ(read_text(out / "final.vtk"), "old vtk");
  EXPECT_EQ(names_in(out).size(), 4u);
  ::umount(disk.c_str());
}

// The other commands write through the same output folder: an export on a
// nearly full disk keeps the earlier deck and its data file (never a new
// data file beside an old deck), and a later export replaces both together.
TEST_F(RobustIo, ExportReplacesDeckAndDataTogetherOrNotAtAll) {
  const Result cal = run_demcal({"calibrate", kHex5, "-o", "cal", "-q"}, dir_);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const fs::path params = dir_ / "cal" / "params.json";
  const fs::path disk = dir_ / "disk";
  if (!mount_small_disk(disk, 512)) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  const fs::path out = disk / "out";
  fs::create_directories(out);
  std::ofstream(out / "deck.lammps") << "old deck";
  std::ofstream(out / "deck.lammps.data") << "old data";
  std::ofstream(out / "keep.txt") << "mine";
  fill_disk(disk);
  // Room for the data file (6 kB) but not the deck (17 kB) as well: written
  // one by one, the new data file landed beside the old deck.
  fs::resize_file(disk / "filler", fs::file_size(disk / "filler") - 3 * 4096);
  const std::vector<std::string> args{
      "export", params.string(), "--particles", "100", "-o", (out / "deck.lammps").string()};
  const Result full = run_demcal(args, dir_);
  EXPECT_NE(full.status, 0);
  EXPECT_NE(full.err.find("No space left on device"), std::string::npos) << full.err;
  EXPECT_EQ(read_text(out / "deck.lammps"), "old deck");
  EXPECT_EQ(read_text(out / "deck.lammps.data"), "old data");
  EXPECT_EQ(names_in(out).size(), 3u);

  fs::remove(disk / "filler");
  const Result r = run_demcal(args, dir_);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(read_text(out / "deck.lammps").find("read_data"), std::string::npos);
  EXPECT_NE(read_text(out / "deck.lammps.data"), "old data");
  EXPECT_EQ(read_text(out / "keep.txt"), "mine");
  EXPECT_EQ(names_in(out).size(), 3u);
  ::umount(disk.c_str());
}

}  // namespace
}  // namespace demcal
