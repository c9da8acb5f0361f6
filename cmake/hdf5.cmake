# HDF5 for the snapshots (io/snapshot.hpp): Debian's serial libhdf5-dev, through
# its pkg-config file (CMake's FindHDF5 would need the C language enabled).
# Defines the imported target PkgConfig::HDF5; included by the main project and
# by the fuzz project (cmake/fuzz.cmake), which compile src/io/.
include_guard(GLOBAL)
find_package(PkgConfig REQUIRED)
pkg_check_modules(HDF5 REQUIRED IMPORTED_TARGET hdf5-serial)
