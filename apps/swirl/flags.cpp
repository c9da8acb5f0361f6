#include "flags.hpp"

#include <charconv>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::cli {
namespace {

// The text as a double, or a message why not.
std::string parse_double(const std::string& text, double& value) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec == std::errc::invalid_argument || ptr != end) return fmt::format("'{}' is not a number", text);
  if (ec == std::errc::result_out_of_range || !std::isfinite(value))
    return fmt::format("'{}' is not a finite number", text);
  return {};
}

}  // namespace

CLI::Validator whole_number(std::uint64_t lo, std::uint64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, value);
        const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || ptr != end) return fmt::format("'{}' is not a whole number from {} to {}", text, lo, hi);
        if (ec == std::errc::result_out_of_range || value < lo || value > hi)
          return fmt::format("{} is out of range: give {} to {}", text, lo, hi);
        return {};
      },
      fmt::format("{}..{}", lo, hi), "whole_number");
}

CLI::Validator positive_finite() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0;
        if (auto error = parse_double(text, value); !error.empty()) return error;
        if (!(value > 0)) return fmt::format("{} is not positive: give a number greater than 0", text);
        return {};
      },
      "> 0", "positive_finite");
}

CLI::Validator number_in(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double value = 0;
        if (auto error = parse_double(text, value); !error.empty()) return error;
        if (!(value >= lo && value <= hi)) return fmt::format("{} is out of range: give {} to {}", text, lo, hi);
        return {};
      },
      fmt::format("{}..{}", lo, hi), "number_in");
}

CLI::Validator non_negative_finite() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0;
        if (auto error = parse_double(text, value); !error.empty()) return error;
        if (!(value >= 0)) return fmt::format("{} is negative: give a number of at least 0", text);
        return {};
      },
      ">= 0", "non_negative_finite");
}

CLI::Validator thread_count() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const std::uint64_t max = static_cast<std::uint64_t>(parallel::max_thread_count());
        std::string error = whole_number(1, max)(text);
        if (!error.empty())
          error += fmt::format(" (swirl starts at most {} threads: 4 per hardware thread, at least 64, at most 1024)", max);
        return error;
      },
      "1..max", "thread_count");
}

}  // namespace swirl::cli
