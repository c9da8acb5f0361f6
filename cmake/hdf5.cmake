# HDF5 for the snapshots (io/snapshot.hpp), through Debian's pkg-config files
# (CMake's FindHDF5 would need the C language enabled): with SWIRL_MPI the
# parallel build (libhdf5-openmpi-dev: the ranks of a run write one frame
# together through MPI-IO; SWIRL_PARALLEL_HDF5=1 on whoever links it), else the
# serial one (libhdf5-dev). Both come from the same HDF5 release and write
# the same bytes for the same frame.
# Defines the interface target swirl_hdf5; included by the main project and
# by the fuzz project (cmake/fuzz.cmake, serial), which compile src/io/.
include_guard(GLOBAL)
find_package(PkgConfig REQUIRED)
# One prefix per flavour: pkg_check_modules caches each library's path under
# its prefix (pkgcfg_lib_<prefix>_hdf5), so one shared prefix kept linking the
# flavour of the first configure after SWIRL_MPI was switched in a build dir.
if(SWIRL_MPI)
  pkg_check_modules(SWIRL_HDF5_PARALLEL IMPORTED_TARGET hdf5-openmpi)
  if(NOT SWIRL_HDF5_PARALLEL_FOUND)
    message(FATAL_ERROR "SWIRL_MPI=ON needs parallel HDF5 (Debian: libhdf5-openmpi-dev; make mpi installs it)")
  endif()
  set(swirl_hdf5_flavour PkgConfig::SWIRL_HDF5_PARALLEL)
  set_property(TARGET ${swirl_hdf5_flavour} APPEND PROPERTY INTERFACE_COMPILE_DEFINITIONS SWIRL_PARALLEL_HDF5=1)
else()
  pkg_check_modules(SWIRL_HDF5_SERIAL REQUIRED IMPORTED_TARGET hdf5-serial)
  set(swirl_hdf5_flavour PkgConfig::SWIRL_HDF5_SERIAL)
endif()
add_library(swirl_hdf5 INTERFACE)
target_link_libraries(swirl_hdf5 INTERFACE ${swirl_hdf5_flavour})
