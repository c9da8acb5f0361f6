// Shared helpers of the io tests: a private temporary directory per test and a
// ParticleSet whose every value is distinct.
#pragma once

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_set.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io::test {

namespace fs = std::filesystem;

// The message of the IoError that `f` throws, or a note that it threw
// something else or nothing.
template <class F>
std::string io_error_of(F&& f) {
  try {
    f();
  } catch (const IoError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("(not an IoError) ") + e.what();
  }
  return "(no exception)";
}

class TempDir {
 public:
  TempDir() {
    static std::atomic<unsigned> counter{0};
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    do {
      path_ = fs::temp_directory_path() / fmt::format("swirl-io-test-{}-{}-{}", ::getpid(), counter++, stamp);
    } while (!fs::create_directory(path_));
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  fs::path operator/(const fs::path& name) const { return path_ / name; }

 private:
  fs::path path_;
};

inline std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void spit(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// File names in `dir`, sorted.
inline std::set<std::string> list_dir(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// n particles with two extra real fields ("temperature", scalar; "vorticity",
// vector) and an integer field ("kind"); every value of every real field is
// distinct and needs all its digits to round-trip, pressure holds a subnormal
// and a -0, and "kind" holds negative values and both int32 extremes.
template <class Real>
ParticleSet<Real> make_particles(std::size_t n) {
  ParticleSet<Real> p(n);
  p.add_field("temperature", 1);
  p.add_field("vorticity", 3);
  auto& kind = p.int_field(p.add_int_field("kind"));
  for (std::size_t i = 0; i < n; ++i) kind[i] = static_cast<std::int32_t>(i % 5) * 1000003 - 2000000;
  if (n > 2) {
    kind[0] = std::numeric_limits<std::int32_t>::min();
    kind[2] = std::numeric_limits<std::int32_t>::max();
  }
  int k = 0;
  for (auto& f : p.fields()) {
    ++k;
    for (int c = 0; c < f.components; ++c)
      for (std::size_t i = 0; i < n; ++i)
        f.data[c][i] = (Real(k * 1000 + c * 100) + Real(i)) / Real(7) - Real(3.3);
  }
  if (n > 1) {
    p.pressure[0] = std::numeric_limits<Real>::denorm_min();
    p.pressure[1] = Real(-0.0);
  }
  for (std::size_t i = 0; i < n; ++i) p.id[i] = 0x9e3779b97f4a7c15ULL * (i + 1);
  return p;
}

// The values of one field, interleaved as the writers store them.
template <class Real>
std::vector<Real> interleaved(const FieldView<const Real>& f, std::size_t n) {
  std::vector<Real> out;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < f.components; ++c) out.push_back(f.data[c][i]);
  return out;
}

// Bit-exact comparison (distinguishes -0 from 0 and compares NaNs by payload).
template <class T>
std::vector<std::byte> bytes_of(const std::vector<T>& v) {
  std::vector<std::byte> out(v.size() * sizeof(T));
  if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
  return out;
}

}  // namespace swirl::io::test
