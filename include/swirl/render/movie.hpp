// Movies from rendered frames, with ffmpeg when it is installed (optional:
// `sudo apt-get install ffmpeg` on Debian).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace swirl::render {

// The executable `name` found on PATH, if any.
std::optional<std::filesystem::path> find_program(const std::string& name);

// What to tell a user who has no ffmpeg.
std::string ffmpeg_missing_hint();

// Encodes the PNGs (all the same size, in this order) into an H.264 MP4 at
// `fps` frames per second: ffmpeg writes a temporary file beside `movie`,
// which is renamed into place, so a failure leaves no partial movie. Throws
// io::IoError (ffmpeg missing, or its exit status and last output lines).
void make_movie(const std::vector<std::filesystem::path>& pngs, const std::filesystem::path& movie, int fps = 25);

}  // namespace swirl::render
