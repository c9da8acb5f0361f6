# The Open Asset Import Library for the mesh obstacles' STL and OBJ files
# (io/mesh_file.hpp): Debian's libassimp-dev, through its CMake package
# (assimpConfig.cmake). Required, as HDF5 is: a swirl build reads every scene.
# Defines the imported target assimp::assimp; included by the main project and
# by the fuzz project (cmake/fuzz.cmake), which compile src/io/.
include_guard(GLOBAL)
find_package(assimp 5 REQUIRED CONFIG)
