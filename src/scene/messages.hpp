// Internal to the scene module: how SceneError messages are made and how a
// key's value is checked against its declaration (keys.hpp), shared by the
// TOML reader (load.cpp) and validate() (validate.cpp) so that a file and a
// Scene built in code are refused with the same words.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "swirl/scene/keys.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl::scene::detail {

// Throws SceneError(message) with control characters shown as \xNN: messages
// are one line by contract, and keys, values and file names come from the user.
[[noreturn]] void raise(std::string_view message);

// Throws SceneError "file: where: reason".
[[noreturn]] void fail(std::string_view file, std::string_view where, std::string_view reason);

// Why a file of scene format `version` cannot be read (newer than this build,
// or not a version at all); "" when it can.
std::string format_version_problem(std::int64_t version);

std::string vec_text(const Vec3d& v);
std::string box_text(const Box<double>& b);

// Refuses a value the key's declaration does not allow: a number not finite
// or outside the range, a name not among the names, an empty or repeated name
// list. `where` is the key as messages show it ("particles[0].spacing").
template <class Owner>
void check_value(const KeySpec<Owner>& spec, const KeyValue& value, std::string_view file, std::string_view where);

}  // namespace swirl::scene::detail
