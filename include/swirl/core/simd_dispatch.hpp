// Runtime choice of the SIMD instruction set, so that one binary runs its
// explicit-SIMD kernels at the widest width the CPU has.
//
// A kernel source file is compiled once per instruction set of
// compiled_isas() by CMake's swirl_simd_sources(<target> <file>...): each copy
// gets its own -march (sse2: x86-64, avx2: haswell — AVX2 + FMA, avx512:
// skylake-avx512 — AVX-512 F/CD/BW/DQ/VL) and -DSWIRL_SIMD_NS=isa_<name>, so
// in it xsimd::batch<T> (the default architecture) is that width and every
// function must live in namespace SWIRL_SIMD_NS (then the copies do not
// clash). Off x86-64 there is one copy, `generic` (the build's own flags).
//
// The caller declares the copies and picks one per call:
//
//   #define SWIRL_DECLARE(isa) namespace isa { void pass(const Args&); }
//   SWIRL_SIMD_FOR_EACH_NS(SWIRL_DECLARE)
//   void pass(const Args& a) { SWIRL_SIMD_DISPATCH(pass, a); }
//
// active() is the widest instruction set both compiled and supported by the
// CPU, unless the environment variable SWIRL_SIMD names another (sse2, avx2,
// avx512, generic: for benchmarks and tests; an unknown or unsupported name is
// an error naming the variable), or set_active() was called (tests, benches:
// call it outside parallel regions). Results are bit-identical for any thread
// count within one instruction set, not across them (the batch widths, and so
// the summation orders, differ).
//
// Inline functions shared with the baseline code (std:: templates not inlined)
// may be emitted by a wider copy too; the linker keeps one definition, and
// tools/check_simd_objects.sh checks that the wider objects define no such
// weak symbol outside their namespace.
#pragma once

#include <array>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace swirl::simd {

enum class Isa { Generic, Sse2, Avx2, Avx512 };

#if defined(__x86_64__) || defined(_M_X64)
#define SWIRL_SIMD_FOR_EACH_NS(X) X(isa_sse2) X(isa_avx2) X(isa_avx512)
inline constexpr std::array<Isa, 3> kCompiledIsas{Isa::Sse2, Isa::Avx2, Isa::Avx512};
#else
#define SWIRL_SIMD_FOR_EACH_NS(X) X(isa_generic)
inline constexpr std::array<Isa, 1> kCompiledIsas{Isa::Generic};
#endif

constexpr std::string_view isa_name(Isa isa) {
  switch (isa) {
    case Isa::Generic: return "generic";
    case Isa::Sse2: return "sse2";
    case Isa::Avx2: return "avx2";
    case Isa::Avx512: return "avx512";
  }
  return "?";
}

// Lanes of a float batch in the copy for isa (generic: unknown, 0).
constexpr int float_lanes(Isa isa) {
  switch (isa) {
    case Isa::Sse2: return 4;
    case Isa::Avx2: return 8;
    case Isa::Avx512: return 16;
    case Isa::Generic: return 0;
  }
  return 0;
}

inline std::optional<Isa> parse_isa(std::string_view name) {
  for (Isa isa : {Isa::Generic, Isa::Sse2, Isa::Avx2, Isa::Avx512})
    if (isa_name(isa) == name) return isa;
  return std::nullopt;
}

inline bool is_compiled(Isa isa) {
  for (Isa c : kCompiledIsas)
    if (c == isa) return true;
  return false;
}

// Whether this CPU (and OS) runs the copy for isa.
inline bool cpu_supports(Isa isa) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  switch (isa) {
    case Isa::Sse2: return true;  // part of x86-64
    case Isa::Avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case Isa::Avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512vl");
    case Isa::Generic: return false;
  }
  return false;
#else
  return isa == Isa::Generic;
#endif
}

inline bool usable(Isa isa) { return is_compiled(isa) && cpu_supports(isa); }

// The widest compiled instruction set this CPU runs.
inline Isa best_supported() {
  Isa best = kCompiledIsas.front();
  for (Isa isa : kCompiledIsas)
    if (cpu_supports(isa)) best = isa;
  return best;
}

namespace detail {
inline Isa from_environment() {
  const char* value = std::getenv("SWIRL_SIMD");
  if (value == nullptr || *value == '\0') return best_supported();
  const std::optional<Isa> isa = parse_isa(value);
  std::string choices;
  for (Isa c : kCompiledIsas)
    if (cpu_supports(c)) choices += std::string(choices.empty() ? "" : ", ") + std::string(isa_name(c));
  if (!isa) throw std::runtime_error("SWIRL_SIMD=" + std::string(value) + ": unknown instruction set (this CPU runs: " + choices + ")");
  if (!usable(*isa))
    throw std::runtime_error("SWIRL_SIMD=" + std::string(value) + ": not " +
                             (is_compiled(*isa) ? "supported by this CPU" : "compiled into this binary") +
                             " (this CPU runs: " + choices + ")");
  return *isa;
}
inline Isa& active_slot() {
  static Isa isa = from_environment();
  return isa;
}
}  // namespace detail

inline Isa active() { return detail::active_slot(); }

// Chooses the instruction set of later calls; throws if it is not usable here.
inline void set_active(Isa isa) {
  if (!usable(isa)) throw std::invalid_argument("SIMD instruction set " + std::string(isa_name(isa)) + " is not usable here");
  detail::active_slot() = isa;
}

// Sets the active instruction set for a scope (tests, benchmarks).
class ScopedIsa {
 public:
  explicit ScopedIsa(Isa isa) : previous_(active()) { set_active(isa); }
  ~ScopedIsa() { detail::active_slot() = previous_; }
  ScopedIsa(const ScopedIsa&) = delete;
  ScopedIsa& operator=(const ScopedIsa&) = delete;

 private:
  Isa previous_;
};

}  // namespace swirl::simd

// Calls isa_<isa>::function(args...) (declared by the caller, see above);
// SWIRL_SIMD_DISPATCH picks the active set.
#if defined(__x86_64__) || defined(_M_X64)
#define SWIRL_SIMD_DISPATCH_TO(isa, function, ...)                               \
  do {                                                                           \
    switch (isa) {                                                               \
      case ::swirl::simd::Isa::Avx512: return isa_avx512::function(__VA_ARGS__); \
      case ::swirl::simd::Isa::Avx2: return isa_avx2::function(__VA_ARGS__);     \
      default: return isa_sse2::function(__VA_ARGS__);                           \
    }                                                                            \
  } while (false)
#else
#define SWIRL_SIMD_DISPATCH_TO(isa, function, ...) return isa_generic::function(__VA_ARGS__)
#endif
#define SWIRL_SIMD_DISPATCH(function, ...) SWIRL_SIMD_DISPATCH_TO(::swirl::simd::active(), function, __VA_ARGS__)
