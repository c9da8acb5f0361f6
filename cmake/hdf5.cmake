# HDF5 for the snapshots (io/snapshot.hpp), through Debian's pkg-config files
# (CMake's FindHDF5 would need the C language enabled): with SWIRL_MPI the
# parallel build (libhdf5-openmpi-dev: the ranks of a run write one frame
# together through MPI-IO; SWIRL_PARALLEL_HDF5=1 on whoever links it), else the
# serial one (libhdf5-dev). Both come from the same HDF5 release and write
# the same bytes for the same frame.
# Defines the imported target PkgConfig::HDF5; included by the main project and
# by the fuzz project (cmake/fuzz.cmake, serial), which compile src/io/.
include_guard(GLOBAL)
find_package(PkgConfig REQUIRED)
if(SWIRL_MPI)
  pkg_check_modules(HDF5 IMPORTED_TARGET hdf5-openmpi)
  if(NOT HDF5_FOUND)
    message(FATAL_ERROR "SWIRL_MPI=ON needs parallel HDF5 (Debian: libhdf5-openmpi-dev; make mpi installs it)")
  endif()
  set_property(TARGET PkgConfig::HDF5 APPEND PROPERTY INTERFACE_COMPILE_DEFINITIONS SWIRL_PARALLEL_HDF5=1)
else()
  pkg_check_modules(HDF5 REQUIRED IMPORTED_TARGET hdf5-serial)
endif()
