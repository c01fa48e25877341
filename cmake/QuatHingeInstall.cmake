# Install rules beyond the libraries' own (plugin/CMakeLists.txt) and the programs' (demos/): quathinge.pc, the models,
# the LICENSE, and CPack (`cpack -G DEB`). Included by the top-level CMakeLists.txt when QUATHINGE_INSTALL is on (by
# default only when QuatHinge is the top-level project, so a FetchContent / add_subdirectory consumer installs none of it).

# ---- quathinge.pc (quathinge-float64.pc from a double build) --------------------------------------------------------
# `g++ app.cpp $(pkg-config --cflags --libs quathinge)`: the precision define and Bullet come along. Bullet is named by
# its pkg-config module when that is how it was found (Requires:), else by the very files this build used.
if(QUATHINGE_DOUBLE_PRECISION)
  set(QUATHINGE_PC_NAME quathinge-float64)
  set(_quathinge_lib_suffix -float64)
else()
  set(QUATHINGE_PC_NAME quathinge)
  set(_quathinge_lib_suffix "")
endif()
get_target_property(_quathinge_bullet_defs QuatHinge::Bullet INTERFACE_COMPILE_DEFINITIONS)
set(QUATHINGE_PC_CFLAGS "")
if("BT_USE_DOUBLE_PRECISION" IN_LIST _quathinge_bullet_defs)
  set(QUATHINGE_PC_CFLAGS "-DBT_USE_DOUBLE_PRECISION")
endif()
set(QUATHINGE_PC_REQUIRES "")
set(QUATHINGE_PC_BULLET_LIBS "")
if(QUATHINGE_BULLET_PC_MODULE)
  set(QUATHINGE_PC_REQUIRES "${QUATHINGE_BULLET_PC_MODULE}")
else()
  get_target_property(_quathinge_bullet_inc QuatHinge::Bullet INTERFACE_INCLUDE_DIRECTORIES)
  foreach(_d IN LISTS _quathinge_bullet_inc)
    string(APPEND QUATHINGE_PC_CFLAGS " -I${_d}")
  endforeach()
  get_target_property(_quathinge_bullet_libs QuatHinge::Bullet INTERFACE_LINK_LIBRARIES)
  foreach(_l IN LISTS _quathinge_bullet_libs)
    if(TARGET ${_l})
      string(APPEND QUATHINGE_PC_BULLET_LIBS " $<TARGET_LINKER_FILE:${_l}>")
    else()
      string(APPEND QUATHINGE_PC_BULLET_LIBS " ${_l}")
    endif()
  endforeach()
endif()
string(STRIP "${QUATHINGE_PC_CFLAGS}" QUATHINGE_PC_CFLAGS)
set(_quathinge_pc_stabilizer "")   # built only with Eigen (plugin/stabilizer/CMakeLists.txt)
if(TARGET QuatHingeStabilizer)
  set(_quathinge_pc_stabilizer "-lQuatHingeStabilizer${_quathinge_lib_suffix} ")
endif()
# Relocatable: the prefix is found from the .pc file's own place (${pcfiledir}), so `cmake --install --prefix` anywhere
# and the .deb (prefix /usr) give the right paths.
file(RELATIVE_PATH _quathinge_pc_up "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
string(REGEX REPLACE "/$" "" _quathinge_pc_up "${_quathinge_pc_up}")
file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/${QUATHINGE_PC_NAME}.pc CONTENT "prefix=\${pcfiledir}/${_quathinge_pc_up}
libdir=\${prefix}/${CMAKE_INSTALL_LIBDIR}
includedir=\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}

Name: QuatHinge
Description: Quaternion hinge constraint for Bullet (btQuaternionHingeConstraint) and its post-stabilizer
Version: ${PROJECT_VERSION}
Requires: ${QUATHINGE_PC_REQUIRES}
Cflags: -I\${includedir} ${QUATHINGE_PC_CFLAGS}
Libs: -L\${libdir} ${_quathinge_pc_stabilizer}-lQuatHinge${_quathinge_lib_suffix}${QUATHINGE_PC_BULLET_LIBS}
")
install(FILES ${PROJECT_BINARY_DIR}/${QUATHINGE_PC_NAME}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# ---- models (the installed programs find them at <prefix>/share/quathinge/models), LICENSE -------------------------
install(DIRECTORY ${PROJECT_SOURCE_DIR}/demos/models/ DESTINATION ${CMAKE_INSTALL_DATADIR}/quathinge/models)
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/quathinge)
# ---- the manual (README.md, CHANGELOG.md, docs/*.md with their images) and the hello-world program ---------------------
# share/doc/quathinge: the programs' --help names it (QUATHINGE_DOC_DIR, demos/CMakeLists.txt); README's links into
# docs/ hold there as in the repository (README.md beside docs/).
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md
        DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/quathinge)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/quathinge/docs
        FILES_MATCHING PATTERN "*.md" PATTERN "*.png" PATTERN "*.svg")
install(FILES ${PROJECT_SOURCE_DIR}/demos/hello/hello.cpp ${PROJECT_SOURCE_DIR}/demos/hello/CMakeLists.txt
        DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/quathinge/hello)

# ---- CPack: `cpack -G DEB` (or TGZ) from a build tree -------------------------------------------------------------
# The .deb's Depends name the Debian package that owns the Bullet headers and link files this build used (dpkg-query
# -S: libbullet-dev), and dpkg-shlibdeps adds the run-time ones of the libraries and programs (libbullet3.24,
# libbullet-extras3.24, fmt, urdfdom, …) with their versions.
set(_quathinge_deb_depends "")
find_program(QUATHINGE_DPKG_QUERY dpkg-query)
if(QUATHINGE_DPKG_QUERY)
  set(_quathinge_bullet_files "")
  get_target_property(_libs QuatHinge::Bullet INTERFACE_LINK_LIBRARIES)
  get_target_property(_incs QuatHinge::Bullet INTERFACE_INCLUDE_DIRECTORIES)
  foreach(_f IN LISTS _libs _incs)
    if(TARGET "${_f}")
      get_target_property(_type ${_f} TYPE)
      if(_type MATCHES "^(STATIC|SHARED)_LIBRARY$")
        get_target_property(_f ${_f} IMPORTED_LOCATION)
      endif()
    endif()
    if(IS_ABSOLUTE "${_f}" AND EXISTS "${_f}")
      list(APPEND _quathinge_bullet_files "${_f}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES _quathinge_bullet_files)
  foreach(_f IN LISTS _quathinge_bullet_files)
    execute_process(COMMAND ${QUATHINGE_DPKG_QUERY} -S "${_f}" OUTPUT_VARIABLE _owner ERROR_QUIET
                    RESULT_VARIABLE _rc OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(_rc EQUAL 0)
      string(REGEX REPLACE ":.*" "" _owner "${_owner}")   # "libbullet-dev:amd64: /usr/…" → libbullet-dev
      string(REPLACE ", " ";" _owner "${_owner}")          # a directory may belong to several
      list(APPEND _quathinge_deb_depends ${_owner})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES _quathinge_deb_depends)
  list(SORT _quathinge_deb_depends)
endif()
if(NOT _quathinge_deb_depends)
  message(STATUS "QuatHinge: the Bullet used is not from a Debian package: the .deb will not depend on one")
endif()
string(REPLACE ";" ", " CPACK_DEBIAN_PACKAGE_DEPENDS "${_quathinge_deb_depends}")
set(CPACK_PACKAGE_NAME ${QUATHINGE_PC_NAME})
set(CPACK_PACKAGE_VENDOR "QuatHinge")
set(CPACK_PACKAGE_CONTACT "QuatHinge maintainers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Quaternion hinge constraint for the Bullet physics engine")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS ${CMAKE_INSTALL_LIBDIR})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
