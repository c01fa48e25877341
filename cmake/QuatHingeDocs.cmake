# The API reference: `cmake --build build --target docs` runs Debian's doxygen (1.9.4; cmake/setup-debian.sh installs
# it) over the public headers plugin/include/quathinge/*.h into <build>/docs/html. Every public class, function,
# member and enumerator must be documented: warnings are errors (WARN_AS_ERROR), so an undocumented addition to the
# public API fails the target. Without doxygen the target is not defined (a status line says so).
find_package(Doxygen 1.9 QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "QuatHinge: doxygen not found: no 'docs' target (apt-get install doxygen)")
  return()
endif()
set(QUATHINGE_DOXYGEN_INPUT "${PROJECT_SOURCE_DIR}/plugin/include/quathinge")
set(QUATHINGE_DOXYGEN_OUTPUT "${PROJECT_BINARY_DIR}/docs")
configure_file(${CMAKE_CURRENT_LIST_DIR}/Doxyfile.in ${PROJECT_BINARY_DIR}/Doxyfile @ONLY)
file(GLOB _quathinge_public_headers CONFIGURE_DEPENDS ${QUATHINGE_DOXYGEN_INPUT}/*.h)
add_custom_command(OUTPUT ${QUATHINGE_DOXYGEN_OUTPUT}/html/index.html
  COMMAND ${CMAKE_COMMAND} -E make_directory ${QUATHINGE_DOXYGEN_OUTPUT}
  COMMAND Doxygen::doxygen ${PROJECT_BINARY_DIR}/Doxyfile
  DEPENDS ${_quathinge_public_headers} ${PROJECT_BINARY_DIR}/Doxyfile ${CMAKE_CURRENT_LIST_DIR}/doxygen-mainpage.md
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "Doxygen ${DOXYGEN_VERSION}: the API reference in ${QUATHINGE_DOXYGEN_OUTPUT}/html"
  VERBATIM)
add_custom_target(docs DEPENDS ${QUATHINGE_DOXYGEN_OUTPUT}/html/index.html)
