// Checkpoints: exact round trip of tagged sections in any order; every damaged file or
// misuse gives an InputError naming the file and the tag.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/checkpoint.hpp"
#include "scratch_dir.hpp"

using namespace ff;

namespace {
struct Pod {
  std::int32_t a;
  double b;
};

void write_sample(const std::filesystem::path& p) {
  CheckpointWriter w(p);
  w.put("dem.x", std::vector<Vec3>{{1, 2, 3}, {0.1, 1.0 / 3.0, -0.0}});
  w.put("dem.q", std::vector<Quat>{Quat(0.5, 0.5, 0.5, 0.5)});
  w.put("dem.id", std::vector<std::int32_t>{5, -7});
  w.put("empty", std::vector<double>{});
  w.put_value("step", std::int64_t{123456789012});
  w.put_value("time", 2.5e-3);
  w.put_value("pod", Pod{4, 0.75});
  w.put_string("scenario", std::string("dem.damping = 0.7\n\0x", 21));
  w.commit();
}

std::string error_of(auto&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}
}  // namespace

TEST(io_checkpoint, RoundTripInAnyOrder) {
  test::ScratchDir d;
  const auto p = d / "ck/state.ffck";
  write_sample(p);
  CheckpointReader r(p);
  EXPECT_EQ(r.get_string("scenario"), std::string("dem.damping = 0.7\n\0x", 21));
  EXPECT_EQ(r.get_value<double>("time"), 2.5e-3);
  EXPECT_EQ(r.get_value<std::int64_t>("step"), 123456789012);
  const Pod pod = r.get_value<Pod>("pod");
  EXPECT_EQ(pod.a, 4);
  EXPECT_EQ(pod.b, 0.75);
  std::vector<Vec3> x;
  r.get("dem.x", x);
  ASSERT_EQ(x.size(), 2u);
  EXPECT_EQ(x[1], Vec3(0.1, 1.0 / 3.0, -0.0));
  EXPECT_TRUE(std::signbit(x[1].z()));
  std::vector<Quat> q;
  r.get("dem.q", q);
  EXPECT_EQ(q.at(0).coeffs(), Quat(0.5, 0.5, 0.5, 0.5).coeffs());
  std::vector<std::int32_t> id;
  r.get("dem.id", id);
  EXPECT_EQ(id, (std::vector<std::int32_t>{5, -7}));
  std::vector<double> e{1, 2};
  r.get("empty", e);
  EXPECT_TRUE(e.empty());
  EXPECT_TRUE(r.has("dem.x"));
  EXPECT_FALSE(r.has("lbm.f"));
  EXPECT_EQ(r.tags().size(), 8u);
}

TEST(io_checkpoint, MisuseNamesFileAndTag) {
  test::ScratchDir d;
  const auto p = d / "c.ffck";
  write_sample(p);
  CheckpointReader r(p);
  std::vector<double> v;
  auto e = error_of([&] { r.get("lbm.f", v); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("'lbm.f'"), std::string::npos) << e;
  EXPECT_NE(e.find("dem.x"), std::string::npos) << e;  // lists what is there
  e = error_of([&] { r.get("dem.x", v); });             // 24-byte Vec3 read as 8-byte double
  EXPECT_NE(e.find("'dem.x'"), std::string::npos) << e;
  EXPECT_NE(e.find("24 bytes"), std::string::npos) << e;
  e = error_of([&] { r.get_value<std::int32_t>("dem.id"); });  // two values, not one
  EXPECT_NE(e.find("exactly one"), std::string::npos) << e;
}

TEST(io_checkpoint, DamagedFilesAreRejectedClearly) {
  test::ScratchDir d;
  const auto p = d / "c.ffck";
  write_sample(p);
  const std::string good = test::slurp(p);
  // Truncated anywhere: the checksum or the end marker fails.
  for (std::size_t len : {good.size() - 1, good.size() / 2, std::size_t{20}, std::size_t{10}}) {
    test::spit(p, good.substr(0, len));
    const auto e = error_of([&] { CheckpointReader r(p); });
    EXPECT_NE(e.find("truncated or corrupted"), std::string::npos) << len << ": " << e;
    EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  }
  // One flipped bit in the payload.
  std::string bad = good;
  bad[good.size() / 2] ^= 0x10;
  test::spit(p, bad);
  EXPECT_NE(error_of([&] { CheckpointReader r(p); }).find("checksum"), std::string::npos);
  // Not a checkpoint at all, or an empty file.
  test::spit(p, "dem.damping = 0.7\n");
  EXPECT_NE(error_of([&] { CheckpointReader r(p); }).find("not a fracflow checkpoint"), std::string::npos);
  test::spit(p, "");
  EXPECT_NE(error_of([&] { CheckpointReader r(p); }).find("not a fracflow checkpoint"), std::string::npos);
  // A future format version.
  bad = good;
  bad[8] = 99;
  test::spit(p, bad);
  EXPECT_NE(error_of([&] { CheckpointReader r(p); }).find("format version 99"), std::string::npos);
  EXPECT_NE(error_of([&] { CheckpointReader r(d / "none.ffck"); }).find("none.ffck"), std::string::npos);
}

TEST(io_checkpoint, UncommittedWriterKeepsThePreviousCheckpoint) {
  test::ScratchDir d;
  const auto p = d / "c.ffck";
  write_sample(p);
  {
    CheckpointWriter w(p);
    w.put_value("time", 9.0);
  }  // destroyed without commit (e.g. an exception while collecting state)
  EXPECT_EQ(CheckpointReader(p).get_value<double>("time"), 2.5e-3);
  CheckpointWriter w(d / "x.ffck");
  w.put_value("a", 1);
  EXPECT_THROW(w.put_value("a", 2), Error);  // duplicate tag is a programming error
  w.commit();
  EXPECT_THROW(w.put_value("b", 2), Error);
  EXPECT_EQ(CheckpointReader(d / "x.ffck").get_value<int>("a"), 1);
}

namespace {
void write_time(const std::filesystem::path& p, double t) {
  CheckpointWriter w(p, /*keep_previous=*/true);
  w.put_value("time", t);
  w.commit();
}
}  // namespace

TEST(io_checkpoint, RotationKeepsThePreviousCheckpointBesideTheNewest) {
  test::ScratchDir d;
  const auto p = d / "state.ffcp", prev = d / "state.prev.ffcp";
  EXPECT_EQ(previous_checkpoint_path(p), prev);
  write_time(p, 1.0);
  EXPECT_FALSE(std::filesystem::exists(prev));  // nothing to keep yet
  write_time(p, 2.0);
  write_time(p, 3.0);
  EXPECT_EQ(CheckpointReader(p).get_value<double>("time"), 3.0);
  EXPECT_EQ(CheckpointReader(prev).get_value<double>("time"), 2.0);
  {  // a writer that never commits (killed while writing) leaves both untouched
    CheckpointWriter w(p, true);
    w.put_value("time", 4.0);
  }
  EXPECT_EQ(open_checkpoint(p).get_value<double>("time"), 3.0);
  EXPECT_EQ(CheckpointReader(prev).get_value<double>("time"), 2.0);
  for (auto& e : std::filesystem::directory_iterator(d.path()))  // no temporary file left over
    EXPECT_TRUE(e.path() == p || e.path() == prev) << e.path();
}

TEST(io_checkpoint, ResumeFallsBackToThePreviousCheckpointWhenTheNewestIsDamaged) {
  test::ScratchDir d;
  const auto p = d / "state.ffcp", prev = d / "state.prev.ffcp";
  write_time(p, 1.0);
  write_time(p, 2.0);
  const std::string good = test::slurp(p);
  // Truncated, one flipped bit, missing: the previous one is used.
  test::spit(p, good.substr(0, good.size() / 2));
  EXPECT_EQ(open_checkpoint(p).get_value<double>("time"), 1.0);
  std::string bad = good;
  bad[good.size() / 2] ^= 0x10;
  test::spit(p, bad);
  EXPECT_EQ(open_checkpoint(p).get_value<double>("time"), 1.0);
  std::filesystem::remove(p);
  EXPECT_EQ(open_checkpoint(p).get_value<double>("time"), 1.0);
  // Both damaged: one error naming both files.
  test::spit(p, bad);
  test::spit(prev, good.substr(0, 10));
  const auto e = error_of([&] { open_checkpoint(p); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find(prev.string()), std::string::npos) << e;
  // No previous checkpoint: the newest's own error.
  std::filesystem::remove(prev);
  EXPECT_NE(error_of([&] { open_checkpoint(p); }).find("checksum"), std::string::npos);
}

TEST(io_checkpoint, AdviceNamesOnlyCommandsThatExist) {
  // Was: "restart ... without --resume" (there is no --resume flag).
  test::ScratchDir d;
  const auto p = d / "c.ffck";
  write_sample(p);
  const std::string good = test::slurp(p);
  std::string future = good;
  future[8] = 99;
  for (const std::string& bytes : {good.substr(0, good.size() / 2), future}) {
    test::spit(p, bytes);
    const auto e = error_of([&] { CheckpointReader r(p); });
    EXPECT_EQ(e.find("--resume"), std::string::npos) << e;
    EXPECT_NE(e.find("fracflow run SCENARIO --out DIR --overwrite"), std::string::npos) << e;
  }
}
