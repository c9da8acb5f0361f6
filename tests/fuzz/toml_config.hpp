// Force-included (-include) into every file of the fuzz build, before toml++.
//
// toml++ is compiled header-only here so that its parser is instrumented.
// Debian's libtomlplusplus, which swirl links in the real build, is built with
// NDEBUG: its assertions are off and, built with g++, its "assume" hints are
// no-ops. The same here without NDEBUG (with clang, NDEBUG would turn every
// assertion into __builtin_assume, i.e. undefined behaviour when it fails).
// Its assertions do fire on malformed input that the library then rejects
// with a parse_error, e.g. "[\x03" (upstream: marzer/tomlplusplus pull request
// #301); those are not swirl's bugs and would stop every fuzz run at once.
#pragma once
#define TOML_ASSERT(expr) static_cast<void>(0)
