// KernelPath: which implementation of a pair kernel runs. Every fast kernel
// (the SPH grid passes, the gravity interaction kernels) has a scalar twin it
// is tested against; both are chosen at run time, and scene keys reach both
// (sph.grid.simd, nbody.simd), so a user can compare them on any scene.
//   Simd    explicit SIMD (xsimd), compiled per instruction set and chosen at
//           start-up (core/simd_dispatch.hpp);
//   Scalar  the same laws one pair at a time, in a plain loop: the reference.
// The two differ in summation order only (rounding), never in the physics.
#pragma once

namespace swirl {

enum class KernelPath { Simd, Scalar };

}  // namespace swirl
