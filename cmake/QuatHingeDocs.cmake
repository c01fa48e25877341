# The API reference: `cmake --build build --target docs` runs Debian's doxygen (1.9.4; cmake/setup-debian.sh installs
# it) over the public headers plugin/include/quathinge/*.h into <build>/docs/html, with XML beside it (<build>/docs/xml,
# which the test api_reference reads), and copies the manual (README.md, CHANGELOG.md, docs/) into html/ so that the
# main page's links to it work. Each header has a \file block, so its free functions, enums, typedefs, constants and
# macros are documented entities; warnings are errors (WARN_AS_ERROR), so an undocumented public class, function,
# member, enum or macro fails the target. The main page (cmake/doxygen-mainpage.md) includes demos/hello/hello.cpp.
# Without doxygen the target is not defined (a status line says so).
find_package(Doxygen 1.9 QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "QuatHinge: doxygen not found: no 'docs' target (apt-get install doxygen)")
  return()
endif()
set(QUATHINGE_DOXYGEN_INPUT "${PROJECT_SOURCE_DIR}/plugin/include/quathinge")
set(QUATHINGE_DOXYGEN_OUTPUT "${PROJECT_BINARY_DIR}/docs")
configure_file(${CMAKE_CURRENT_LIST_DIR}/Doxyfile.in ${PROJECT_BINARY_DIR}/Doxyfile @ONLY)
file(GLOB _quathinge_public_headers CONFIGURE_DEPENDS ${QUATHINGE_DOXYGEN_INPUT}/*.h)
file(GLOB _quathinge_manual CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/docs/*.md)
set(_quathinge_html ${QUATHINGE_DOXYGEN_OUTPUT}/html)
add_custom_command(OUTPUT ${_quathinge_html}/index.html
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${QUATHINGE_DOXYGEN_OUTPUT}/xml
  COMMAND ${CMAKE_COMMAND} -E make_directory ${QUATHINGE_DOXYGEN_OUTPUT}
  COMMAND Doxygen::doxygen ${PROJECT_BINARY_DIR}/Doxyfile
  COMMAND ${CMAKE_COMMAND} -E copy_directory ${PROJECT_SOURCE_DIR}/docs ${_quathinge_html}/docs
  COMMAND ${CMAKE_COMMAND} -E copy ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md
          ${PROJECT_SOURCE_DIR}/LICENSE ${_quathinge_html}
  DEPENDS ${_quathinge_public_headers} ${PROJECT_BINARY_DIR}/Doxyfile ${CMAKE_CURRENT_LIST_DIR}/doxygen-mainpage.md
          ${PROJECT_SOURCE_DIR}/demos/hello/hello.cpp ${_quathinge_manual} ${PROJECT_SOURCE_DIR}/README.md
          ${PROJECT_SOURCE_DIR}/CHANGELOG.md
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "Doxygen ${DOXYGEN_VERSION}: the API reference in ${_quathinge_html}"
  VERBATIM)
add_custom_target(docs DEPENDS ${_quathinge_html}/index.html)
