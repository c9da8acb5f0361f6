// Checkpoints: exact round trip, and every kind of damage refused clearly.
#include "swirl/io/checkpoint.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz/checkpoint_replay.hpp"
#include "io_test_util.hpp"
#include "swirl/io/atomic_file.hpp"

namespace {

using namespace swirl;
using namespace swirl::io;
using swirl::io::test::TempDir;

template <class Real>
class CheckpointTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CheckpointTest, Precisions);

// make_particles (with its integer field "kind") plus a real and an integer
// field of its own.
template <class Real>
ParticleSet<Real> sample(std::size_t n) {
  auto p = swirl::io::test::make_particles<Real>(n);
  p.add_field("potential", 1);
  p.add_field("vorticity", 3);
  const std::size_t flag = p.add_int_field("flag", FieldUse::Internal);
  for (std::size_t i = 0; i < n; ++i) {
    p.extra(0)[i] = Real(-1.5) * Real(i + 1);
    p.extra(1, 2)[i] = Real(0.25) * Real(i);
    p.int_field(flag)[i] = static_cast<std::int32_t>(i % 2);
  }
  return p;
}

template <class Real>
void expect_same(const ParticleSet<Real>& a, const ParticleSet<Real>& b) {
  const auto fa = a.fields(), fb = b.fields();
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t f = 0; f < fa.size(); ++f) {
    EXPECT_EQ(fa[f].name, fb[f].name);
    ASSERT_EQ(fa[f].components, fb[f].components);
    for (int c = 0; c < fa[f].components; ++c)
      EXPECT_EQ(std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(Real)), 0) << fa[f].name;
  }
  // Integer fields by name: a reader that declared some first holds them in another order.
  ASSERT_EQ(a.int_field_count(), b.int_field_count());
  for (const auto& f : a.int_fields()) {
    const std::size_t k = b.find_int_field(f.name);
    ASSERT_NE(k, ParticleSet<Real>::npos) << f.name;
    EXPECT_EQ(std::vector<std::int32_t>(f.data[0], f.data[0] + a.size()),
              std::vector<std::int32_t>(b.int_field(k).begin(), b.int_field(k).end()))
        << f.name;
  }
  EXPECT_EQ(a.id, b.id);
}

TYPED_TEST(CheckpointTest, RoundTripsEveryFieldIdAndValueBitExactly) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = sample<Real>(257);
  const CheckpointValues values{{"frames", 3}, {"initial_energy", -0.2501234567890123}};
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), p.size(), 0xabcdef0123456789u, 42, 0.125}, values);
  ParticleSet<Real> q;  // empty: fields are created from the file
  CheckpointValues read_values;
  const auto h = read_checkpoint(dir / "c.swc", q, read_values);
  EXPECT_EQ(h.particles, 257u);
  EXPECT_EQ(h.scene_hash, 0xabcdef0123456789u);
  EXPECT_EQ(h.step, 42u);
  EXPECT_EQ(h.time, 0.125);
  EXPECT_EQ(h.real_bytes, sizeof(Real));
  EXPECT_EQ(h.version, kCheckpointVersion);
  EXPECT_EQ(read_values, values);
  ASSERT_EQ(q.int_field_count(), 2u);  // "kind" and "flag"
  expect_same(p, q);
  EXPECT_EQ(read_checkpoint_header(dir / "c.swc").step, 42u);
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename(), "c.swc");  // no temporary left
}

TYPED_TEST(CheckpointTest, EmptySetRoundTrips) {
  using Real = TypeParam;
  TempDir dir;
  const ParticleSet<Real> p;
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), 0, 1, 0, 0.0}, {});
  ParticleSet<Real> q(5);
  CheckpointValues v;
  EXPECT_EQ(read_checkpoint(dir / "c.swc", q, v).particles, 0u);
  EXPECT_EQ(q.size(), 0u);
}

// Expects parse_checkpoint to refuse `bytes` with a message containing `words`.
template <class Real>
void expect_refused(const std::string& bytes, const std::string& words) {
  ParticleSet<Real> q;
  CheckpointValues v;
  try {
    parse_checkpoint(bytes, "x.swc", q, v);
    ADD_FAILURE() << "accepted; expected: " << words;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("x.swc: ", 0), 0u) << e.what();
  }
}

TYPED_TEST(CheckpointTest, DamageIsRefusedWithAReason) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = sample<Real>(40);
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), p.size(), 7, 3, 0.5}, {{"frames", 1}});
  const std::string good = swirl::io::test::slurp(dir / "c.swc");

  for (std::size_t at : {std::size_t{60}, good.size() / 2, good.size() - 20}) {
    std::string flipped = good;
    flipped[at] = static_cast<char>(flipped[at] ^ 0x10);
    expect_refused<Real>(flipped, "checksum");
  }
  for (std::size_t keep : {std::size_t{0}, std::size_t{5}, std::size_t{30}, good.size() / 3, good.size() - 1})
    expect_refused<Real>(good.substr(0, keep), keep < 16 ? "short" : "");
  std::string magic = good;
  magic[0] = 'X';
  expect_refused<Real>(magic, "bad magic");
  std::string old = good;
  const std::uint32_t zero = 0;
  std::memcpy(old.data() + 8, &zero, 4);
  expect_refused<Real>(old,
                       "format version 0 is not supported: this swirl reads versions 2, 3 and 4 (written by an older swirl)");
  std::string newer = good;
  const std::uint32_t five = 5;
  std::memcpy(newer.data() + 8, &five, 4);
  expect_refused<Real>(newer, "format version 5 is not supported: this swirl reads versions 2, 3 and 4 (written by a newer swirl)");
  std::string first = good;
  const std::uint32_t one = 1;
  std::memcpy(first.data() + 8, &one, 4);
  expect_refused<Real>(first, "version 1 was written before the run state moved under owner prefixes");
  // The other precision is refused, not misread.
  if constexpr (std::is_same_v<Real, float>) {
    ParticleSet<double> d;
    CheckpointValues v;
    EXPECT_THROW(parse_checkpoint(good, "x.swc", d, v), IoError);
  }
}

TYPED_TEST(CheckpointTest, RandomCorruptionOnlyEverThrowsIoError) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = sample<Real>(9);
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), p.size(), 7, 3, 0.5}, {{"frames", 1}});
  const std::string good = swirl::io::test::slurp(dir / "c.swc");
  std::uint64_t state = 12345;
  for (int trial = 0; trial < 2000; ++trial) {
    std::string bad = good;
    for (int k = 0; k < 1 + trial % 4; ++k) {
      state = state * 6364136223846793005u + 1442695040888963407u;
      bad[(state >> 33) % bad.size()] = static_cast<char>(state >> 56);
    }
    ParticleSet<Real> q;
    CheckpointValues v;
    try {
      parse_checkpoint(bad, "x.swc", q, v);
    } catch (const IoError&) {
    }
  }
}


// The version written matters, not only the one claimed: a version-3 file
// stamped 2 (checksum fixed) has an integer section a version-2 reader does
// not expect, and its data no longer fill the file exactly.
TYPED_TEST(CheckpointTest, AVersion3FileStampedVersion2IsRefused) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = sample<Real>(6);
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), p.size(), 7, 3, 0.5}, {});
  std::string stamped = swirl::io::test::slurp(dir / "c.swc");
  const std::uint32_t two = 2;
  std::memcpy(stamped.data() + 8, &two, 4);
  expect_refused<Real>(swirl::fuzz::with_checksum(stamped), "");
}

// A file written by the version-2 writer (a seed of the fuzz corpus, kept as
// it was written) is still read: it has no integer fields, and it holds what
// its rewrite in the current version holds.
TEST(CheckpointVersions, AVersion2FileIsRead) {
  const std::filesystem::path seeds = std::filesystem::path(SWIRL_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "checkpoint";
  ParticleSet<double> old_file, new_file;
  CheckpointValues old_values, new_values;
  const auto h2 = read_checkpoint(seeds / "nbody_double_4_v2.ckp", old_file, old_values);
  const auto h3 = read_checkpoint(seeds / "nbody_double_4.ckp", new_file, new_values);
  EXPECT_EQ(h2.version, 2u);
  EXPECT_EQ(h3.version, kCheckpointVersion);
  EXPECT_EQ(read_checkpoint_header(seeds / "nbody_double_4_v2.ckp").version, 2u);
  EXPECT_EQ(h2.particles, 4u);
  EXPECT_EQ(h2.step, h3.step);
  EXPECT_EQ(h2.time, h3.time);
  EXPECT_EQ(h2.scene_hash, h3.scene_hash);
  EXPECT_EQ(old_file.int_field_count(), 0u);
  EXPECT_EQ(old_values, new_values);
  EXPECT_FALSE(old_file.fields().empty());
  expect_same(old_file, new_file);
}

// A file of version 3 (the layout of version 4, written before inlets and
// outlets could change the count) is read as its version-4 rewrite.
TEST(CheckpointVersions, AVersion3FileIsRead) {
  const std::filesystem::path seeds = std::filesystem::path(SWIRL_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "checkpoint";
  ParticleSet<float> old_file, new_file;
  CheckpointValues old_values, new_values;
  const auto h3 = read_checkpoint(seeds / "sph_kind_float_3_v3.ckp", old_file, old_values);
  const auto h4 = read_checkpoint(seeds / "sph_kind_float_3.ckp", new_file, new_values);
  EXPECT_EQ(h3.version, 3u);
  EXPECT_EQ(h4.version, 4u);
  EXPECT_EQ(h3.particles, h4.particles);
  EXPECT_EQ(h3.step, h4.step);
  EXPECT_EQ(old_file.int_field_count(), 1u);
  EXPECT_EQ(old_values, new_values);
  expect_same(old_file, new_file);
}

// A run that declares an integer field cannot take it from a file that does
// not hold it (a version-2 file, or one written without the field): refused
// with the field's name, before the particles are touched.
TEST(CheckpointVersions, AnIntegerFieldTheFileLacksIsRefused) {
  const std::filesystem::path seeds = std::filesystem::path(SWIRL_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "checkpoint";
  for (const char* seed : {"nbody_double_4_v2.ckp", "nbody_double_4.ckp"}) {
    ParticleSet<double> p(2);
    p.add_int_field("kind");
    CheckpointValues v;
    try {
      read_checkpoint(seeds / seed, p, v);
      ADD_FAILURE() << seed << " was read";
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("has no integer field 'kind', which the run declares"), std::string::npos) << what;
      EXPECT_EQ(what.find("version 2 files hold no integer fields") != std::string::npos,
                std::string(seed).ends_with("_v2.ckp"))
          << what;
    }
    EXPECT_EQ(p.size(), 2u) << seed;
  }
}

// A field declared before the read keeps its use; one only the file has is
// added as output.
TYPED_TEST(CheckpointTest, DeclaredIntegerFieldsKeepTheirUse) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = sample<Real>(5);
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), p.size(), 7, 3, 0.5}, {});
  ParticleSet<Real> q;
  q.add_int_field("flag", FieldUse::Internal);
  CheckpointValues v;
  read_checkpoint(dir / "c.swc", q, v);
  for (const auto& f : q.int_fields()) EXPECT_EQ(f.internal, f.name == "flag") << f.name;
  expect_same(p, q);
}

// Replaces the first `from` in `bytes` by `to` (the same length) and fixes the
// checksum: a well-formed file with one name changed.
std::string renamed(std::string bytes, const std::string& from, const std::string& to) {
  const std::size_t at = bytes.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(from.size(), to.size());
  if (at != std::string::npos) bytes.replace(at, from.size(), to);
  return swirl::fuzz::with_checksum(bytes);
}

// Names in the integer section are checked like those of the real fields:
// unique across both lists (a built-in's name is always in the real list),
// never "id"; and an integer field of the file cannot meet a real field of
// the run, nor the reverse.
TYPED_TEST(CheckpointTest, BadIntegerFieldNamesAreRefused) {
  using Real = TypeParam;
  TempDir dir;
  ParticleSet<Real> p(3);
  p.add_field("real", 1);
  for (const char* name : {"inta", "intb", "zz", "zzzz"}) p.add_int_field(name);
  write_checkpoint(dir / "c.swc", p, {sizeof(Real), p.size(), 7, 3, 0.5}, {});
  const std::string good = swirl::io::test::slurp(dir / "c.swc");
  {
    ParticleSet<Real> q;
    CheckpointValues v;
    parse_checkpoint(good, "x.swc", q, v);  // as written, the file is fine
    EXPECT_EQ(q.int_field_count(), 4u);
  }
  expect_refused<Real>(renamed(good, "zz", "id"), "a field may not be called 'id'");
  expect_refused<Real>(renamed(good, "zzzz", "mass"), "field 'mass' is listed twice");
  expect_refused<Real>(renamed(good, "inta", "real"), "field 'real' is listed twice");
  expect_refused<Real>(renamed(good, "inta", "intb"), "field 'intb' is listed twice");

  ParticleSet<Real> run_real;  // the run's "inta" is real
  run_real.add_field("inta", 1);
  CheckpointValues v;
  try {
    parse_checkpoint(good, "x.swc", run_real, v);
    ADD_FAILURE() << "read into a run whose 'inta' is real";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'inta' exists as a real field"), std::string::npos) << e.what();
  }
  ParticleSet<Real> run_int;  // the run's "real" is an integer field: the file's real one cannot be added
  run_int.add_int_field("real");
  try {
    parse_checkpoint(good, "x.swc", run_int, v);
    ADD_FAILURE() << "read into a run whose 'real' is an integer field";
  } catch (const IoError& e) {
    // refused as a missing integer field first: the file has no integer "real"
    EXPECT_NE(std::string(e.what()).find("has no integer field 'real'"), std::string::npos) << e.what();
  }
}
}  // namespace
