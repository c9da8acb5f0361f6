#include "swirl/io/checkpoint.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "detail.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/write_faults.hpp"

namespace swirl::io {
namespace {

static_assert(std::endian::native == std::endian::little, "checkpoints are written little-endian");

constexpr std::string_view kMagic = "SWIRLCKP";
constexpr std::uint32_t kMaxName = 256, kMaxFields = 64, kMaxValues = 64;
constexpr std::uint64_t kMaxParticles = std::uint64_t{1} << 31;

// The append a test asked to fail (io/write_faults.hpp).
detail::InjectedFault injected_append_fault;

constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325u;

// FNV-1a 64 of `bytes` continued from h (kFnvOffset: from the start).
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = kFnvOffset) {
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3u;
  }
  return h;
}

template <class T>
void put(std::string& out, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  out.append(raw, sizeof(T));
}

void put_name(std::string& out, std::string_view name) {
  put<std::uint32_t>(out, static_cast<std::uint32_t>(name.size()));
  out.append(name);
}

// Reads fixed-size values from the bytes, never past their end.
class Cursor {
 public:
  explicit Cursor(std::string_view bytes) : bytes_(bytes) {}
  template <class T>
  T get(std::string_view what) {
    T v;
    std::memcpy(&v, take(sizeof(T), what).data(), sizeof(T));
    return v;
  }
  std::string_view take(std::size_t n, std::string_view what) {
    if (n > bytes_.size() - pos_) throw detail::Malformed(fmt::format("truncated in {}", what));
    const auto out = bytes_.substr(pos_, n);
    pos_ += n;
    return out;
  }
  std::string name(std::string_view what) {
    const auto n = get<std::uint32_t>(what);
    if (n == 0 || n > kMaxName) throw detail::Malformed(fmt::format("{} has a bad name length {}", what, n));
    return std::string(take(n, what));
  }
  std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  std::string_view bytes_;
  std::size_t pos_ = 0;
};

// "2 and 3", "2, 3 and 4": the versions this build reads, for messages.
std::string readable_versions() {
  std::string out = std::to_string(kOldestReadableCheckpointVersion);
  for (std::uint32_t v = kOldestReadableCheckpointVersion + 1; v <= kCheckpointVersion; ++v)
    out += (v == kCheckpointVersion ? " and " : ", ") + std::to_string(v);
  return out;
}

CheckpointHeader parse_header(Cursor& in) {
  if (in.take(kMagic.size(), "the magic") != kMagic) throw detail::Malformed("not a swirl checkpoint (bad magic)");
  const auto version = in.get<std::uint32_t>("the version");
  if (version < kOldestReadableCheckpointVersion || version > kCheckpointVersion)
    throw detail::Malformed(fmt::format(
        "format version {} is not supported: this swirl reads version{} {}{}", version,
        kOldestReadableCheckpointVersion == kCheckpointVersion ? "" : "s", readable_versions(),
        version == 1 ? " (version 1 was written before the run state moved under owner prefixes such as "
                       "\"frames.written\" and \"clock.previous_dt\"; resume it with the swirl that wrote it)"
        : version < kCheckpointVersion ? " (written by an older swirl)"
                                       : " (written by a newer swirl)"));
  CheckpointHeader h;
  h.version = version;
  h.real_bytes = in.get<std::uint32_t>("the precision");
  if (h.real_bytes != 4 && h.real_bytes != 8)
    throw detail::Malformed(fmt::format("bad precision: {} bytes per real", h.real_bytes));
  h.particles = in.get<std::uint64_t>("the particle count");
  if (h.particles > kMaxParticles) throw detail::Malformed(fmt::format("{} particles is over the limit", h.particles));
  h.scene_hash = in.get<std::uint64_t>("the scene hash");
  h.step = in.get<std::uint64_t>("the step");
  h.time = in.get<double>("the time");
  return h;
}

template <class Real>
CheckpointHeader parse(std::string_view bytes, ParticleSet<Real>& particles, CheckpointValues& values) {
  if (bytes.size() < kMagic.size() + 8) throw detail::Malformed("too short to be a checkpoint");
  // The checksum first: whatever follows reads only bytes that were written as they are.
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  const std::string_view body = bytes.substr(0, bytes.size() - 8);
  Cursor in(body);
  const CheckpointHeader h = parse_header(in);  // a clear "version" or "magic" message beats "checksum"
  if (fnv1a(body) != stored) throw detail::Malformed("checksum mismatch: the file is corrupt or truncated");
  if (h.real_bytes != sizeof(Real))
    throw detail::Malformed(fmt::format("holds {}-byte reals, the run uses {}-byte ones", h.real_bytes, sizeof(Real)));

  const auto field_count = in.get<std::uint32_t>("the field count");
  if (field_count == 0 || field_count > kMaxFields) throw detail::Malformed(fmt::format("bad field count {}", field_count));
  std::vector<std::pair<std::string, std::uint32_t>> fields;
  std::uint64_t reals_per_particle = 0;
  for (std::uint32_t f = 0; f < field_count; ++f) {
    auto name = in.name("a field name");
    for (const auto& [seen, c] : fields)
      if (seen == name) throw detail::Malformed(fmt::format("field '{}' is listed twice", name));
    if (name == "id") throw detail::Malformed("a field may not be called 'id'");
    const auto components = in.get<std::uint32_t>("a field's components");
    if (components != 1 && components != 3)
      throw detail::Malformed(fmt::format("field '{}' has {} components", name, components));
    reals_per_particle += components;
    fields.emplace_back(std::move(name), components);
  }
  // Version 2 has no integer section: its files hold no integer fields.
  std::vector<std::string> int_fields;
  if (h.version >= 3) {
    const auto int_field_count = in.get<std::uint32_t>("the integer field count");
    if (int_field_count > kMaxFields)
      throw detail::Malformed(fmt::format("bad integer field count {}", int_field_count));
    for (std::uint32_t f = 0; f < int_field_count; ++f) {
      auto name = in.name("an integer field name");
      for (const auto& [seen, c] : fields)
        if (seen == name) throw detail::Malformed(fmt::format("field '{}' is listed twice", name));
      for (const auto& seen : int_fields)
        if (seen == name) throw detail::Malformed(fmt::format("field '{}' is listed twice", name));
      if (name == "id") throw detail::Malformed("a field may not be called 'id'");
      int_fields.push_back(std::move(name));
    }
  }
  // A run's integer field that the file lacks would keep values that are not
  // the checkpoint's (not even in its particle order): refused, not guessed.
  for (const auto& run_field : std::as_const(particles).int_fields())
    if (std::find(int_fields.begin(), int_fields.end(), run_field.name) == int_fields.end())
      throw detail::Malformed(fmt::format("has no integer field '{}', which the run declares{}", run_field.name,
                                          h.version < 3 ? " (version 2 files hold no integer fields)" : ""));
  const auto value_count = in.get<std::uint32_t>("the value count");
  if (value_count > kMaxValues) throw detail::Malformed(fmt::format("bad value count {}", value_count));
  CheckpointValues read_values;
  for (std::uint32_t v = 0; v < value_count; ++v) {
    auto name = in.name("a value name");
    read_values.emplace_back(std::move(name), in.get<double>("a value"));
  }
  // The data must fill the rest exactly: checked before anything is allocated.
  using Int = typename ParticleSet<Real>::int_type;
  const std::uint64_t expected =
      h.particles * (reals_per_particle * sizeof(Real) + int_fields.size() * sizeof(Int) + sizeof(std::uint64_t));
  if (in.remaining() != expected)
    throw detail::Malformed(fmt::format("holds {} bytes of particle data, {} particles need {}", in.remaining(),
                                        h.particles, expected));

  const std::size_t n = static_cast<std::size_t>(h.particles);
  particles.resize(n);
  for (const auto& [name, components] : fields) {
    if (name == "position" || name == "velocity" || name == "acceleration" || name == "acceleration_prev" ||
        name == "mass" || name == "density" || name == "pressure")
      continue;
    try {
      particles.add_field(name, static_cast<int>(components));
    } catch (const std::invalid_argument& e) {  // an existing field of another shape
      throw detail::Malformed(fmt::format("field '{}': {}", name, e.what()));
    }
  }
  for (const auto& name : int_fields) {
    try {
      particles.add_int_field(name);
    } catch (const std::invalid_argument& e) {  // a built-in or real field of that name
      throw detail::Malformed(fmt::format("field '{}': {}", name, e.what()));
    }
  }
  auto views = particles.fields();
  for (const auto& [name, components] : fields) {
    FieldView<Real>* view = nullptr;
    for (auto& v : views)
      if (v.name == name) view = &v;
    if (!view || view->components != static_cast<int>(components))
      throw detail::Malformed(fmt::format("field '{}' does not match the run's fields", name));
    for (int c = 0; c < view->components; ++c) {
      const auto raw = in.take(n * sizeof(Real), name);
      if (n) std::memcpy(view->data[c], raw.data(), raw.size());
    }
  }
  for (const auto& name : int_fields) {
    const auto raw = in.take(n * sizeof(Int), name);
    if (n) std::memcpy(particles.int_field(particles.find_int_field(name)).data(), raw.data(), raw.size());
  }
  const auto ids = in.take(n * sizeof(std::uint64_t), "the ids");
  if (n) std::memcpy(particles.id.data(), ids.data(), ids.size());
  values = std::move(read_values);
  return h;
}

}  // namespace

template <class Real>
CheckpointLayout CheckpointLayout::of(const ParticleSet<Real>& particles) {
  CheckpointLayout layout;
  for (const auto& f : particles.fields())
    layout.fields.emplace_back(std::string(f.name), static_cast<std::uint32_t>(f.components));
  for (const auto& f : particles.int_fields()) layout.int_fields.emplace_back(f.name);
  return layout;
}

CheckpointWriter::CheckpointWriter(const std::filesystem::path& path, const CheckpointHeader& header,
                                   const CheckpointLayout& layout, const CheckpointValues& values)
    : file_(path), hash_(kFnvOffset) {
  if (header.real_bytes != 4 && header.real_bytes != 8)
    throw std::invalid_argument("checkpoint writer: reals of 4 or 8 bytes");
  std::uint64_t arrays = 0;
  for (const auto& field : layout.fields) arrays += field.second;
  expected_ = header.particles * (arrays * header.real_bytes + layout.int_fields.size() * sizeof(std::int32_t) +
                                  sizeof(std::uint64_t));
  std::string out;
  out.append(kMagic);
  put<std::uint32_t>(out, kCheckpointVersion);
  put<std::uint32_t>(out, header.real_bytes);
  put<std::uint64_t>(out, header.particles);
  put<std::uint64_t>(out, header.scene_hash);
  put<std::uint64_t>(out, header.step);
  put<double>(out, header.time);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(layout.fields.size()));
  for (const auto& [name, components] : layout.fields) {
    put_name(out, name);
    put<std::uint32_t>(out, components);
  }
  put<std::uint32_t>(out, static_cast<std::uint32_t>(layout.int_fields.size()));
  for (const auto& name : layout.int_fields) put_name(out, name);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(values.size()));
  for (const auto& [name, value] : values) {
    put_name(out, name);
    put<double>(out, value);
  }
  hash_ = fnv1a(out, hash_);
  file_.append(out);
}

void CheckpointWriter::append(std::string_view data) {
  if (data.size() > expected_ - appended_)
    throw std::logic_error("checkpoint writer: more data than the header announces");
  hash_ = fnv1a(data, hash_);
  file_.append(data);
  appended_ += data.size();
  if (injected_append_fault.now())  // a test's (io/write_faults.hpp): as a full disk would refuse
    throw IoError(fmt::format("{}: write failed: no space left on device (injected by a test)", file_.path().string()));
}

void CheckpointWriter::finish() {
  if (appended_ != expected_) throw std::logic_error("checkpoint writer: less data than the header announces");
  std::string checksum;
  put<std::uint64_t>(checksum, hash_);
  file_.append(checksum);
  file_.commit(/*sync=*/true);
}

template <class Real>
void write_checkpoint(const std::filesystem::path& path, const ParticleSet<Real>& particles,
                      const CheckpointHeader& header, const CheckpointValues& values) {
  CheckpointHeader h = header;
  h.real_bytes = sizeof(Real);
  h.particles = particles.size();
  CheckpointWriter out(path, h, CheckpointLayout::of(particles), values);
  for_each_checkpoint_array(particles, [&](const void* data, std::size_t bytes) {
    out.append(std::string_view(static_cast<const char*>(data), bytes));
  });
  out.finish();
}

template <class Real>
CheckpointHeader parse_checkpoint(std::string_view bytes, std::string_view name, ParticleSet<Real>& particles,
                                  CheckpointValues& values) {
  try {
    return parse(bytes, particles, values);
  } catch (const detail::Malformed& e) {
    throw IoError(fmt::format("{}: {}", name, e.what()));
  }
}

template <class Real>
CheckpointHeader read_checkpoint(const std::filesystem::path& path, ParticleSet<Real>& particles,
                                 CheckpointValues& values) {
  return parse_checkpoint(read_regular_file(path, max_particle_file_bytes()), path.string(), particles, values);
}

CheckpointHeader read_checkpoint_header(const std::filesystem::path& path) {
  const std::string bytes = read_regular_file(path, max_particle_file_bytes());
  try {
    Cursor in(bytes);
    return parse_header(in);
  } catch (const detail::Malformed& e) {
    throw IoError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

template CheckpointLayout CheckpointLayout::of<float>(const ParticleSet<float>&);
template CheckpointLayout CheckpointLayout::of<double>(const ParticleSet<double>&);
template void write_checkpoint<float>(const std::filesystem::path&, const ParticleSet<float>&, const CheckpointHeader&,
                                      const CheckpointValues&);
template void write_checkpoint<double>(const std::filesystem::path&, const ParticleSet<double>&,
                                       const CheckpointHeader&, const CheckpointValues&);
template CheckpointHeader read_checkpoint<float>(const std::filesystem::path&, ParticleSet<float>&, CheckpointValues&);
template CheckpointHeader read_checkpoint<double>(const std::filesystem::path&, ParticleSet<double>&,
                                                  CheckpointValues&);
template CheckpointHeader parse_checkpoint<float>(std::string_view, std::string_view, ParticleSet<float>&,
                                                  CheckpointValues&);
template CheckpointHeader parse_checkpoint<double>(std::string_view, std::string_view, ParticleSet<double>&,
                                                   CheckpointValues&);

namespace testing {
void fail_checkpoint_append(int n) { injected_append_fault.arm(n); }
}  // namespace testing

}  // namespace swirl::io
