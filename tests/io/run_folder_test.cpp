// RunFolder: the lock, the manifest, ownership, overwrite, distinct outputs.
#include "swirl/io/run_folder.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>

#include "io/io_test_util.hpp"

namespace swirl::io {
namespace {

using namespace swirl::io::test;

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const RunFolderError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("(not a RunFolderError) ") + e.what();
  }
  return "(no exception)";
}

class RunFolderTest : public ::testing::Test {
 protected:
  TempDir tmp;
  fs::path out = tmp / "out";
};

TEST_F(RunFolderTest, RecordsEveryClaimedFileInTheManifest) {
  {
    RunFolder folder(out, RunFolderMode::Fresh, "scene.toml");
    EXPECT_EQ(folder.claim("particles_000000.vtp"), out / "particles_000000.vtp");
    folder.claim(out / "checkpoints" / "checkpoint_000000000010.swc");  // as run.cpp builds paths
    EXPECT_TRUE(fs::is_directory(out / "checkpoints"));
    EXPECT_TRUE(folder.owns("particles_000000.vtp"));
    EXPECT_TRUE(folder.owns(fs::absolute(out) / "checkpoints" / "checkpoint_000000000010.swc"));
    EXPECT_FALSE(folder.owns("scene.toml"));
  }
  const std::string manifest = slurp(out / "manifest.txt");
  EXPECT_NE(manifest.find("\nfile particles_000000.vtp\n"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\nfile checkpoints/checkpoint_000000000010.swc\n"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\nrun "), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("scene.toml"), std::string::npos) << "the identity names the scene";
}

TEST_F(RunFolderTest, NeverClaimsAFileItDidNotWrite) {
  fs::create_directories(out);
  spit(out / "scene.toml", "user's own scene");
  RunFolder folder(out, RunFolderMode::Fresh, "");
  const std::string e = error_of([&] { folder.claim("scene.toml"); });
  EXPECT_NE(e.find("scene.toml: exists and was not written by this run"), std::string::npos) << e;
  EXPECT_EQ(slurp(out / "scene.toml"), "user's own scene");
  EXPECT_FALSE(folder.owns("scene.toml"));
  for (const char* bad : {"../escape.txt", "/etc/passwd", "manifest.txt", ".swirl.lock"})
    EXPECT_NE(error_of([&] { folder.claim(bad); }).find("not a file a run may write"), std::string::npos) << bad;
}

TEST_F(RunFolderTest, RefusesAnotherRunsFolderUnlessOverwriteWhichDeletesOnlyItsFiles) {
  {
    RunFolder first(out, RunFolderMode::Fresh, "first");
    spit(first.claim("particles_000000.vtp"), "frame");
    spit(first.claim("checkpoints/checkpoint_000000000001.swc"), "cp");
  }
  spit(out / "notes.txt", "the user's notes");
  const std::string e = error_of([&] { RunFolder second(out, RunFolderMode::Fresh, "second"); });
  EXPECT_NE(e.find("holds another run"), std::string::npos) << e;
  EXPECT_NE(e.find("--overwrite"), std::string::npos) << e;
  EXPECT_TRUE(fs::exists(out / "particles_000000.vtp"));

  RunFolder second(out, RunFolderMode::Overwrite, "second");
  EXPECT_FALSE(fs::exists(out / "particles_000000.vtp"));
  EXPECT_FALSE(fs::exists(out / "checkpoints")) << "emptied by the overwrite, so removed";
  EXPECT_EQ(slurp(out / "notes.txt"), "the user's notes");
  EXPECT_TRUE(second.files().empty());
  EXPECT_EQ(slurp(out / "manifest.txt").find("first"), std::string::npos);
}

TEST_F(RunFolderTest, AManifestPointingOutsideTheFolderIsNotFollowed) {
  fs::create_directories(out);
  spit(tmp / "precious.txt", "keep me");
  spit(out / "manifest.txt", "run someone\nfile ../precious.txt\n");
  const std::string e = error_of([&] { RunFolder folder(out, RunFolderMode::Overwrite, ""); });
  EXPECT_NE(e.find("not a path inside the run folder"), std::string::npos) << e;
  EXPECT_EQ(slurp(tmp / "precious.txt"), "keep me");
}

TEST_F(RunFolderTest, ResumeAdoptsTheManifestAndPrunesOnlyItsOwnFiles) {
  std::string identity;
  {
    RunFolder first(out, RunFolderMode::Fresh, "scene");
    identity = first.identity();
    spit(first.claim("checkpoints/checkpoint_000000000001.swc", /*sync=*/true), "mine");
  }
  spit(out / "checkpoints" / "checkpoint_000000000002.swc", "someone else's");
  RunFolder resumed(out, RunFolderMode::Resume, "ignored");
  EXPECT_EQ(resumed.identity(), identity);
  EXPECT_FALSE(resumed.remove(out / "checkpoints" / "checkpoint_000000000002.swc"));
  EXPECT_TRUE(fs::exists(out / "checkpoints" / "checkpoint_000000000002.swc"));
  EXPECT_TRUE(resumed.remove(out / "checkpoints" / "checkpoint_000000000001.swc"));
  EXPECT_FALSE(fs::exists(out / "checkpoints" / "checkpoint_000000000001.swc"));
  EXPECT_EQ(slurp(out / "manifest.txt").find("checkpoint_000000000001"), std::string::npos);

  const fs::path other = tmp / "not_a_run";
  fs::create_directories(other);
  EXPECT_NE(error_of([&] { RunFolder r(other, RunFolderMode::Resume, ""); }).find("no manifest.txt"),
            std::string::npos);
}

TEST_F(RunFolderTest, TheLockExcludesASecondHolderInThisProcess) {
  auto first = std::make_unique<RunFolder>(out, RunFolderMode::Fresh, "");
  const std::string e = error_of([&] { RunFolder second(out, RunFolderMode::Resume, ""); });
  EXPECT_NE(e.find("is using this folder"), std::string::npos) << e;
  EXPECT_NE(e.find(fmt::format("(pid {})", ::getpid())), std::string::npos) << e;
  first.reset();
  EXPECT_NO_THROW(RunFolder again(out, RunFolderMode::Resume, ""));
}

// Two processes: the child holds the folder until told to let go; the parent
// is refused meanwhile (naming the child's pid), and gets it afterwards.
TEST_F(RunFolderTest, TheLockExcludesAnotherProcess) {
  int to_child[2], to_parent[2];
  ASSERT_EQ(::pipe(to_child), 0);
  ASSERT_EQ(::pipe(to_parent), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    int status = 0;
    try {
      RunFolder folder(out, RunFolderMode::Fresh, "child");
      char c = 'L';
      if (::write(to_parent[1], &c, 1) != 1) status = 3;
      if (::read(to_child[0], &c, 1) != 1) status = 4;  // hold the lock until the parent is done
    } catch (...) {
      status = 5;
    }
    ::_exit(status);
  }
  char c = 0;
  ASSERT_EQ(::read(to_parent[0], &c, 1), 1);
  const std::string e = error_of([&] { RunFolder mine(out, RunFolderMode::Resume, "parent"); });
  EXPECT_NE(e.find(fmt::format("(pid {})", child)), std::string::npos) << e;
  EXPECT_NE(e.find(out.string()), std::string::npos) << e;
  ASSERT_EQ(::write(to_child[1], &c, 1), 1);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_NO_THROW(RunFolder mine(out, RunFolderMode::Resume, "parent")) << "released when the holder exits";
  for (int fd : {to_child[0], to_child[1], to_parent[0], to_parent[1]}) ::close(fd);
}

TEST_F(RunFolderTest, TwoOutputsNamingOneFileAreRefused) {
  fs::create_directories(out);
  const std::vector<NamedOutput> same{{"--summary-json", out / "a.json"}, {"--other", out / "sub" / ".." / "a.json"}};
  EXPECT_NE(error_of([&] { check_distinct_outputs(same); }).find("--summary-json and --other name the same file"),
            std::string::npos);
  fs::create_symlink(out, tmp / "link");
  const std::vector<NamedOutput> linked{{"--a", out / "x"}, {"--b", tmp / "link" / "x"}};
  EXPECT_NE(error_of([&] { check_distinct_outputs(linked); }), "(no exception)");
  const std::vector<NamedOutput> distinct{{"--a", out / "x"}, {"--b", out / "y"}};
  EXPECT_EQ(error_of([&] { check_distinct_outputs(distinct); }), "(no exception)");
  const std::vector<NamedOutput> inputs{{"scene file", out / "y"}};
  EXPECT_NE(error_of([&] { check_distinct_outputs(distinct, inputs); }).find("--b"), std::string::npos);
}

}  // namespace
}  // namespace swirl::io
