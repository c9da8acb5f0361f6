# The Python module swirl._swirl (python/, docs/python.md). Included only when
# SWIRL_BUILD_PYTHON=ON, which pyproject.toml sets for `pip install .`; the
# CLI's build trees never see it. nanobind comes from the Python environment
# that builds (pyproject.toml's build requirements, or the developer venv of
# `make python`); nothing is downloaded here.
find_package(Python 3.9 REQUIRED COMPONENTS Interpreter Development.Module)
execute_process(COMMAND "${Python_EXECUTABLE}" -m nanobind --cmake_dir
                OUTPUT_VARIABLE SWIRL_NANOBIND_DIR OUTPUT_STRIP_TRAILING_WHITESPACE
                RESULT_VARIABLE SWIRL_NANOBIND_FOUND)
if(NOT SWIRL_NANOBIND_FOUND EQUAL 0)
  message(FATAL_ERROR "SWIRL_BUILD_PYTHON: nanobind is not installed for ${Python_EXECUTABLE} "
                      "(pip install -r python/requirements-build.txt, or build with `pip install .`)")
endif()
# The nanobind of this configure's environment (pip's isolated build
# environment is a new directory each time: a cached one may be gone).
unset(nanobind_DIR CACHE)
find_package(nanobind CONFIG REQUIRED PATHS "${SWIRL_NANOBIND_DIR}" NO_DEFAULT_PATH)

# The static libraries go into a shared module: position-independent code, in
# this build tree only (the CLI's trees are unchanged). -fno-semantic-interposition
# keeps GCC inlining and calling swirl's own functions directly as it does
# without -fPIC (nothing interposes them: the module hides every symbol).
foreach(lib swirl_core swirl_spatial swirl_force swirl_integrate swirl_dist swirl_io swirl_gravity swirl_scene swirl_sph swirl_sim swirl_render swirl_view swirl_cli_commands)
  set_target_properties(${lib} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  target_compile_options(${lib} PRIVATE -fno-semantic-interposition)
endforeach()

nanobind_add_module(_swirl NB_STATIC
  ${PROJECT_SOURCE_DIR}/python/src/module.cpp
  ${PROJECT_SOURCE_DIR}/python/src/scene.cpp
  ${PROJECT_SOURCE_DIR}/python/src/simulation.cpp
  ${PROJECT_SOURCE_DIR}/python/src/run.cpp
  ${PROJECT_SOURCE_DIR}/python/src/render.cpp
  ${PROJECT_SOURCE_DIR}/python/src/cli.cpp)
target_link_libraries(_swirl PRIVATE swirl::swirl swirl_cli_commands)
# swirl's warnings (errors) on the binding sources; nanobind's and Python's
# headers as system headers (GCC drops a -I for a directory also given with -isystem).
swirl_target_options(_swirl)
target_include_directories(_swirl SYSTEM PRIVATE ${Python_INCLUDE_DIRS} ${SWIRL_NANOBIND_DIR}/../include
                           ${SWIRL_NANOBIND_DIR}/../ext/robin_map/include)
install(TARGETS _swirl LIBRARY DESTINATION swirl)
