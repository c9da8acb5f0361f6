# The live view's page (web/), compiled into swirl as string constants so that
# `swirl view` serves it with no network and no files beside the binary:
# generated/web_assets.hpp, rewritten only when a file of web/ changed (CMake
# re-runs when they do).
set(_web_files index.html:kIndexHtml viewer.js:kViewerJs)
set(_web "// Generated from web/ by cmake/web_assets.cmake: do not edit.\n#pragma once\n#include <string_view>\nnamespace swirl::view::web {\n")
foreach(_entry IN LISTS _web_files)
  string(REPLACE ":" ";" _pair "${_entry}")
  list(GET _pair 0 _file)
  list(GET _pair 1 _name)
  set(_path "${PROJECT_SOURCE_DIR}/web/${_file}")
  file(READ "${_path}" _text)
  string(FIND "${_text}" ")swirl_web\"" _clash)
  if(NOT _clash EQUAL -1)
    message(FATAL_ERROR "web/${_file} contains the raw string delimiter )swirl_web\"")
  endif()
  string(APPEND _web "inline constexpr std::string_view ${_name} = R\"swirl_web(${_text})swirl_web\";\n")
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${_path}")
endforeach()
string(APPEND _web "}  // namespace swirl::view::web\n")
file(WRITE "${PROJECT_BINARY_DIR}/generated/web_assets.hpp.tmp" "${_web}")
configure_file("${PROJECT_BINARY_DIR}/generated/web_assets.hpp.tmp" "${PROJECT_BINARY_DIR}/generated/web_assets.hpp" COPYONLY)
