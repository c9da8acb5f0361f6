// Parameters of the SPH fluid (sph_fluid.hpp), in SI units.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

#include "swirl/core/enum_names.hpp"
#include "swirl/spatial/cell_order.hpp"
#include "swirl/spatial/hash_options.hpp"

namespace swirl::sph {

// Which symmetrisation of the pressure force (see sph_fluid.hpp: eq. 2.8
// estimates only half of ∇p).
enum class PressureForm {
  Thesis,      // (p_i + p_j) / (2 ρ_j): eq. 2.8, Müller et al. 2003
  Consistent,  // (p_i + p_j) / ρ_j: a consistent estimate of ∇p
};

// What the equation of state does below the rest density (sph_fluid.hpp).
enum class NegativePressure {
  Keep,  // p = c² (ρ − ρ0) as eq. 2.9: the fluid resists stretching (tension)
  Zero,  // p = max(0, c² (ρ − ρ0)): no tension, so free surfaces do not clump
};

// How neighbours are found (sph_fluid.hpp).
enum class NeighbourSearch {
  Grid,  // sorted cell grid, particles reordered in memory, passes on the fly (spatial/cell_grid.hpp)
  Hash,  // the thesis's spatial hash with CSR interaction lists (spatial/spatial_hash.hpp)
};

// The pressure solver (sph.method).
enum class SphMethod {
  Wcsph,  // the thesis's weakly compressible fluid: p = c² (ρ − ρ0), explicit forces (sph_fluid.hpp)
  Dfsph,  // divergence-free SPH (Bender & Koschier 2015, 2017): iterative solves in the stepper (sph/dfsph_stepper.hpp)
};

// The smoothing kernels of DFSPH's passes (sph.kernel).
enum class SphKernel {
  Thesis,       // W_poly6 for density, ∇W_spiky for gradients (Müller et al. 2003, the thesis's set)
  CubicSpline,  // Monaghan 1992's cubic spline, W and its own gradient (sph/kernels.hpp)
};

// The names scenes use (sph.pressure, sph.negative_pressure, sph.neighbour_search, sph.method, sph.kernel).
inline constexpr std::array<EnumName<SphMethod>, 2> kSphMethodNames{
    {{"wcsph", SphMethod::Wcsph}, {"dfsph", SphMethod::Dfsph}}};
inline constexpr std::array<EnumName<SphKernel>, 2> kSphKernelNames{
    {{"thesis", SphKernel::Thesis}, {"cubic_spline", SphKernel::CubicSpline}}};
inline constexpr std::array<EnumName<PressureForm>, 2> kPressureFormNames{
    {{"thesis", PressureForm::Thesis}, {"consistent", PressureForm::Consistent}}};
inline constexpr std::array<EnumName<NegativePressure>, 2> kNegativePressureNames{
    {{"keep", NegativePressure::Keep}, {"zero", NegativePressure::Zero}}};
inline constexpr std::array<EnumName<NeighbourSearch>, 2> kNeighbourSearchNames{
    {{"grid", NeighbourSearch::Grid}, {"hash", NeighbourSearch::Hash}}};

// The DFSPH solver's settings (sph.dfsph.*; sph/dfsph_stepper.hpp).
struct DfsphOptions {
  double density_tolerance = 5e-4;     // η: the average compression max(ρ* − ρ0, 0)/ρ0 the density solve stops below
  double divergence_tolerance = 1e-3;  // η_v: the average max(Dρ/Dt, 0)·Δt/ρ0 the divergence solve stops below
  std::uint32_t max_iterations = 100;  // of either solve; more is a blow-up ("solver did not converge")
  double cfl = 0.2;                    // C: Δt ≤ C·h/|v|max (0.2·h ≈ 0.4 particle spacings at h ≈ 2 spacings)
};

struct SphParameters {
  double smoothing_length = 0;     // h, m (> 0): kernel support and hash cell length
  double rest_density = 1000;      // ρ0, kg/m³
  double sound_speed = 10;         // c, m/s
  double viscosity = 0.1;          // μ, Pa·s (≥ 0)
  std::uint32_t buckets = 0;       // hash: table size M; 0 = the thesis's ≈ 1.6·N (made odd)
  bool gradient_correction = false;  // L_i = M_i⁻¹ on the pressure force (sph/laws.hpp, GradientCorrection)
  bool duplicate_check = true;     // hash: the cell-relation check of section 4.2.3
  spatial::DuplicateCheck check_placement = spatial::DuplicateCheck::BeforeDistance;  // hash: where it runs
  spatial::TableBuild table_build = spatial::TableBuild::Parallel;  // hash: the table on every thread or one
  spatial::NeighbourHashes neighbour_hashes = spatial::NeighbourHashes::OnTheFly;  // hash: the 26 cells' hashes
  PressureForm pressure_form = PressureForm::Thesis;
  NegativePressure negative_pressure = NegativePressure::Keep;
  NeighbourSearch neighbour_search = NeighbourSearch::Grid;
  bool simd = true;                // grid: explicit SIMD passes (false: their scalar twin)
  spatial::CellOrder cell_order = spatial::CellOrder::Rows;  // grid: cell order (spatial/cell_order.hpp)
  double grid_skin = 0;            // grid: Verlet skin, m (≥ 0); 0 = sort every evaluation
  spatial::CellTable cell_table = spatial::CellTable::Auto;  // grid: dense or hashed cell lookup
  SphMethod method = SphMethod::Wcsph;
  SphKernel kernel = SphKernel::Thesis;  // DFSPH's kernels (the thesis's solver always uses its own set)
  DfsphOptions dfsph;                    // method = Dfsph only
  // Non-pressure terms of DFSPH (sph_fluid.hpp, docs/sph.md; 0 = off):
  double xsph = 0;             // ε of the XSPH velocity filter, dimensionless, in [0, 1]
  double surface_tension = 0;  // γ of Akinci et al. 2013's cohesion and curvature (≥ 0; see sph_fluid.hpp for units)
  double adhesion = 0;         // β of Akinci et al. 2013's fluid–boundary adhesion (≥ 0)
};

// The thesis's table size for n particles: 1.6·n, odd (24001 for 15000).
inline std::uint32_t default_bucket_count(std::size_t n) {
  const auto m = static_cast<std::uint64_t>(1.6 * static_cast<double>(n));
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(m | 1u, 0xffffffffu));
}

}  // namespace swirl::sph
