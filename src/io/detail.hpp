// Internal helpers of the io module: a minimal XML tag
// scanner for the files this module writes, strict number parsing, and the
// countdown behind the tests' injected write failures (io/write_faults.hpp).
#pragma once

#include <atomic>
#include <charconv>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace swirl::io::detail {

// The n-th of a writer's operations from arm(n) on is to fail (1-based; 0:
// none). now() counts one operation and says whether it is that one.
// Thread-safe; per process.
class InjectedFault {
 public:
  void arm(int n) { left_.store(n > 0 ? n : 0); }
  bool now() {
    int left = left_.load();
    while (left > 0 && !left_.compare_exchange_weak(left, left - 1)) {
    }
    return left == 1;
  }

 private:
  std::atomic<int> left_{0};
};

// A parse error; readers rethrow it as IoError prefixed with the file name.
struct Malformed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Escapes text for use inside a double-quoted XML attribute.
std::string xml_escape(std::string_view text);

struct XmlTag {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;  // values unescaped
  bool closing = false;       // </name>
  bool self_closing = false;  // <name .../>

  // The attribute's value, or nullptr if absent.
  const std::string* find(std::string_view key) const;
  // The attribute's value; Malformed if absent.
  const std::string& get(std::string_view key) const;
};

// Yields the tags of a document one by one, skipping character data, the XML
// declaration and comments. Throws Malformed on bad syntax; never reads past
// the end of the text.
class XmlScanner {
 public:
  explicit XmlScanner(std::string_view text) : text_(text) {}

  // The next tag, or nullopt at the end of the text.
  std::optional<XmlTag> next();
  // Index just after the '>' of the last tag returned.
  std::size_t position() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

// Parses all of `text` as a number of type T; Malformed naming `what` otherwise.
template <class T>
T parse_number(std::string_view text, std::string_view what) {
  T value{};
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size())
    throw Malformed(std::string(what) + ": invalid number '" + std::string(text.substr(0, 40)) + "'");
  return value;
}

}  // namespace swirl::io::detail
