#include <string>

#include <fmt/format.h>

#include "cli.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::cli {
namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", static_cast<int>(c));
        else out += c;
    }
  }
  return out + "\"";
}

}  // namespace

scene::Scene load_scene_file(const std::filesystem::path& file, std::span<const std::string> overrides) {
  return scene::parse_scene(io::read_regular_file(file, io::kMaxSceneBytes), file.string(), overrides);
}

std::string summary_text(const sim::RunSummary& s) {
  std::string out;
  out += fmt::format("  scene            {}\n", s.scene_file);
  if (s.particles_end != 0 && s.particles_end != s.particles)  // inlets or outlets changed the count
    out += fmt::format("  particles        {} at the start, {} at the end ({})\n", s.particles, s.particles_end,
                       s.precision);
  else
    out += fmt::format("  particles        {} ({})\n", s.particles, s.precision);
  out += fmt::format("  steps            {} (t = {:.6g}{}{})\n", s.steps, s.sim_time, s.time_unit.empty() ? "" : " ",
                     s.time_unit);
  out += fmt::format("  wall time        {:.3f} s\n", s.wall_seconds);
  out += fmt::format("  steps per second {:.2f}\n", s.steps_per_second);
  out += fmt::format("  threads          {}\n", s.threads);
  out += fmt::format("  SIMD kernels     {}\n", simd::isa_name(simd::active()));
  out += fmt::format("  bytes/particle   {}\n", s.bytes_per_particle);
  out += fmt::format("  frames           {} in {}\n", s.frames, s.out_dir.string());
  for (const auto& [name, value] : s.metrics) out += fmt::format("  {:<16} {:.6g}\n", name, value);
  out += "  time per phase  ";
  for (const auto& [name, seconds] : s.phases)
    out += fmt::format(" {} {:.3f} s ({:.0f}%)", name, seconds, s.wall_seconds > 0 ? 100 * seconds / s.wall_seconds : 0.0);
  out += "\n";
  return out;
}

std::string summary_json(const sim::RunSummary& s) {
  std::string phases, metrics, failed;
  for (const auto& line : s.failed_checks) failed += fmt::format("{}{}", failed.empty() ? "" : ", ", json_string(line));
  for (const auto& [name, value] : s.metrics) metrics += fmt::format("  {}: {:.9g},\n", json_string(name), value);
  for (const auto& [name, seconds] : s.phases)
    phases += fmt::format("{}{}: {:.9g}", phases.empty() ? "" : ", ", json_string(name), seconds);
  return fmt::format(
      "{{\n"
      "  \"scene\": {},\n  \"precision\": {},\n  \"out_dir\": {},\n  \"threads\": {},\n  \"simd\": \"{}\",\n"
      "  \"particles\": {},\n  \"particles_end\": {},\n  \"steps\": {},\n  \"sim_time\": {:.17g},\n  \"wall_seconds\": {:.9g},\n"
      "  \"steps_per_second\": {:.9g},\n  \"phase_seconds\": {{{}}},\n  \"bytes_per_particle\": {},\n"
      "  \"frames\": {},\n{}  \"completed\": {},\n  \"failed_checks\": [{}],\n  \"error\": {}\n}}\n",
      json_string(s.scene_file), json_string(s.precision), json_string(s.out_dir.string()), s.threads,
      simd::isa_name(simd::active()), s.particles, s.particles_end,
      s.steps, s.sim_time, s.wall_seconds, s.steps_per_second, phases, s.bytes_per_particle, s.frames, metrics,
      s.error.empty() ? "true" : "false", failed, s.error.empty() ? "null" : json_string(s.error));
}

}  // namespace swirl::cli
