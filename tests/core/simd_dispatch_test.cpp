// The choice of the SIMD instruction set (core/simd_dispatch.hpp): names,
// the SWIRL_SIMD environment variable and its errors, scoped choices.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "swirl/core/simd_dispatch.hpp"

namespace swirl::simd {
namespace {

// Sets SWIRL_SIMD for a scope and puts the previous value back.
class ScopedEnvironment {
 public:
  explicit ScopedEnvironment(const char* value) {
    if (const char* old = std::getenv("SWIRL_SIMD")) saved_ = old;
    if (value) setenv("SWIRL_SIMD", value, 1);
    else unsetenv("SWIRL_SIMD");
  }
  ~ScopedEnvironment() {
    if (saved_) setenv("SWIRL_SIMD", saved_->c_str(), 1);
    else unsetenv("SWIRL_SIMD");
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  std::optional<std::string> saved_;
};

// The message of the exception from_environment() throws ("" if none).
std::string environment_error() {
  try {
    detail::from_environment();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(SimdDispatch, NamesRoundTrip) {
  for (Isa isa : {Isa::Generic, Isa::Sse2, Isa::Avx2, Isa::Avx512}) {
    const auto parsed = parse_isa(isa_name(isa));
    ASSERT_TRUE(parsed.has_value()) << isa_name(isa);
    EXPECT_EQ(*parsed, isa);
  }
  EXPECT_FALSE(parse_isa("AVX512").has_value());  // names are lower case
  EXPECT_FALSE(parse_isa("").has_value());
}

TEST(SimdDispatch, UnsetOrEmptyMeansTheWidestTheCpuRuns) {
  {
    ScopedEnvironment env(nullptr);
    EXPECT_EQ(detail::from_environment(), best_supported());
  }
  ScopedEnvironment env("");
  EXPECT_EQ(detail::from_environment(), best_supported());
  EXPECT_TRUE(usable(best_supported()));
}

TEST(SimdDispatch, EveryUsableNameIsTaken) {
  for (Isa isa : kCompiledIsas) {
    if (!usable(isa)) continue;
    ScopedEnvironment env(std::string(isa_name(isa)).c_str());
    EXPECT_EQ(detail::from_environment(), isa);
  }
}

TEST(SimdDispatch, AnUnknownNameIsAnErrorNamingTheVariable) {
  ScopedEnvironment env("avx9000");
  const std::string message = environment_error();
  EXPECT_NE(message.find("SWIRL_SIMD=avx9000"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown instruction set"), std::string::npos) << message;
  // It lists what this CPU runs, so the user can pick one.
  EXPECT_NE(message.find(std::string(isa_name(best_supported()))), std::string::npos) << message;
}

TEST(SimdDispatch, AnUnusableNameIsAnErrorNamingTheVariable) {
  int checked = 0;
  for (Isa isa : {Isa::Generic, Isa::Sse2, Isa::Avx2, Isa::Avx512}) {
    if (usable(isa)) continue;
    const std::string name(isa_name(isa));
    ScopedEnvironment env(name.c_str());
    const std::string message = environment_error();
    EXPECT_NE(message.find("SWIRL_SIMD=" + name), std::string::npos) << message;
    EXPECT_NE(message.find(is_compiled(isa) ? "not supported by this CPU" : "not compiled into this binary"),
              std::string::npos)
        << message;
    ++checked;
  }
  // Every binary leaves at least one name out (generic on x86-64, the x86 ones elsewhere).
  EXPECT_GE(checked, 1);
}

TEST(SimdDispatch, ScopedChoiceIsRestoredAndUnusableOnesRefused) {
  const Isa before = active();
  for (Isa isa : kCompiledIsas) {
    if (!usable(isa)) continue;
    {
      ScopedIsa scope(isa);
      EXPECT_EQ(active(), isa);
    }
    EXPECT_EQ(active(), before);
  }
  for (Isa isa : {Isa::Generic, Isa::Sse2, Isa::Avx2, Isa::Avx512})
    if (!usable(isa)) {
      EXPECT_THROW(ScopedIsa{isa}, std::invalid_argument);
    }
  EXPECT_EQ(active(), before);
}

TEST(SimdDispatch, LanesGrowWithTheInstructionSet) {
  EXPECT_EQ(float_lanes(Isa::Sse2), 4);
  EXPECT_EQ(float_lanes(Isa::Avx2), 2 * float_lanes(Isa::Sse2));
  EXPECT_EQ(float_lanes(Isa::Avx512), 2 * float_lanes(Isa::Avx2));
  EXPECT_TRUE(is_compiled(kCompiledIsas.front()));
}

}  // namespace
}  // namespace swirl::simd
