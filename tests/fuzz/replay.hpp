// What every fuzz target and its regression test share: the documented
// behaviour of a reader of untrusted bytes. A reader may accept its input or
// throw its documented exception with a message naming the file; a crash, a
// sanitizer report, a hang, a huge allocation or any other exception is a bug.
// A broken promise that is not a crash is reported as ContractViolation, which
// nobody catches, so the fuzzer records the input like a crash.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace swirl::fuzz {

struct ContractViolation : std::logic_error {
  using std::logic_error::logic_error;
};

inline void require(bool ok, std::string_view what, std::string_view detail = {}) {
  if (!ok) throw ContractViolation(std::string(what) + (detail.empty() ? "" : ": ") + std::string(detail));
}

// A documented error's message: not empty, starting with the file's name.
inline void check_error_message(std::string_view message, std::string_view file) {
  require(!message.empty(), "empty error message");
  require(message.substr(0, file.size()) == file, "error message does not start with the file name",
          message.substr(0, 200));
}

}  // namespace swirl::fuzz
