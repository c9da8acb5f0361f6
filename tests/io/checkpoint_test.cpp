// Checkpoints: exact round trip, and every kind of damage refused clearly.
#include "swirl/io/checkpoint.hpp"

#include <gtest/gtest.h>

#include <cstring>

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

template <class Real>
ParticleSet<Real> sample(std::size_t n) {
  auto p = swirl::io::test::make_particles<Real>(n);
  p.add_field("potential", 1);
  p.add_field("vorticity", 3);
  for (std::size_t i = 0; i < n; ++i) {
    p.extra(0)[i] = Real(-1.5) * Real(i + 1);
    p.extra(1, 2)[i] = Real(0.25) * Real(i);
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
  EXPECT_EQ(read_values, values);
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
  expect_refused<Real>(old, "format version 0 is not supported: this swirl reads version 2 only (written by an older swirl)");
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

}  // namespace
