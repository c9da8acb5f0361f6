// CSV output of one frame: a header row naming the columns (id, x, y, z, then
// every real field, vector fields as name_x, name_y, name_z, then every
// integer field; internal fields are left out) and one row per particle,
// values printed with enough digits to round-trip exactly (integers as
// integers).
#pragma once

#include <filesystem>

#include "swirl/core/particle_set.hpp"

namespace swirl::io {

// Writes one frame atomically (see atomic_file.hpp).
template <class Real>
void write_csv(const std::filesystem::path& path, const ParticleSet<Real>& particles, double time);

extern template void write_csv<float>(const std::filesystem::path&, const ParticleSet<float>&, double);
extern template void write_csv<double>(const std::filesystem::path&, const ParticleSet<double>&, double);

}  // namespace swirl::io
