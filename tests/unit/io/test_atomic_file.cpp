// Atomic file writes: whole file or nothing, folders created, errors name the path.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "scratch_dir.hpp"

using namespace ff;
using ff::test::slurp;

namespace {
// Files in `dir` whose name contains ".tmp." (left-over temporaries).
int temporaries(const std::filesystem::path& dir) {
  int n = 0;
  for (auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) ++n;
  return n;
}
}  // namespace

TEST(io_atomic_file, WritesCreatesFoldersAndReplaces) {
  test::ScratchDir d;
  const auto p = d / "a/b/c.txt";
  write_file_atomic(p, "first");
  EXPECT_EQ(slurp(p), "first");
  write_file_atomic(p, std::string("sec\0ond", 7));
  EXPECT_EQ(slurp(p), std::string("sec\0ond", 7));
  write_file_atomic(p, "");
  EXPECT_TRUE(std::filesystem::exists(p));
  EXPECT_EQ(std::filesystem::file_size(p), 0u);
  write_file_atomic(d / "durable.txt", "x", true);
  EXPECT_EQ(slurp(d / "durable.txt"), "x");
  EXPECT_EQ(temporaries(d.path()), 0);
}

TEST(io_atomic_file, AbandonedWriterLeavesOldFileIntact) {
  test::ScratchDir d;
  const auto p = d / "f.bin";
  write_file_atomic(p, "old");
  {
    AtomicFileWriter w(p);
    w.write("new content that is never committed");
    EXPECT_EQ(slurp(p), "old");  // nothing visible before commit
  }
  EXPECT_EQ(slurp(p), "old");
  EXPECT_EQ(temporaries(d.path()), 0);
  AtomicFileWriter w(p);
  w.write("ab");
  w.write(std::string_view("cd"));
  EXPECT_EQ(w.bytes_written(), 4u);
  w.commit();
  EXPECT_EQ(slurp(p), "abcd");
  EXPECT_THROW(w.write("x"), Error);
}

TEST(io_atomic_file, ErrorNamesThePath) {
  test::ScratchDir d;
  write_file_atomic(d / "plain", "a file, not a folder");
  const auto bad = d / "plain/sub/out.txt";  // parent is a regular file
  try {
    write_file_atomic(bad, "x");
    FAIL() << "expected ff::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
  }
  std::filesystem::create_directories(d / "dir");
  try {
    write_file_atomic(d / "dir", "x");  // cannot rename a file over a folder
    FAIL() << "expected ff::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find((d / "dir").string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(temporaries(d.path()), 0);
}
