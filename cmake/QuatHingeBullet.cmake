# The one place that decides which Bullet QuatHinge is built against, and with which precision.
#
# quathinge_find_bullet() makes the imported targets
#   QuatHinge::Bullet        BulletDynamics, BulletCollision, LinearMath (+ what the Bullet found lists), its include
#                            directories, and BT_USE_DOUBLE_PRECISION as an INTERFACE definition when it is double
#   QuatHinge::BulletExtras  BulletWorldImporter + BulletFileLoader, when that Bullet has them; it links
#                            QuatHinge::Bullet itself, so a static Bullet links in the right order
# from the first of these that exists:
#   (a) targets LinearMath, BulletCollision, BulletDynamics already in the build (a super-project add_subdirectory()'d
#       Bullet's source): headers from ${BULLET_PHYSICS_SOURCE_DIR}/src, precision from USE_DOUBLE_PRECISION. A system
#       Bullet is then never looked at.
#   (b) Bullet's own BulletConfig.cmake (find_package(Bullet CONFIG)): only one the user pointed at (-DBullet_DIR=…,
#       Bullet_ROOT or CMAKE_PREFIX_PATH), never the one in /usr (Debian's: relative paths that only work for its own
#       float build); its libraries and headers must exist. BULLET_ROOT_DIR is absolute, BULLET_INCLUDE_DIRS and
#       BULLET_LIBRARY_DIRS relative to it, BULLET_DEFINITIONS carries -DBT_USE_DOUBLE_PRECISION for a double build.
#   (c) pkg-config `bullet`, then `bullet-float64` (Debian ships both; a double Bullet built from source installs
#       `bullet.pc`): the precision is read from the module's Cflags.
# The precision is that of the Bullet found. QUATHINGE_DOUBLE_PRECISION, when set (ON/OFF), is a requirement: an
# automatic candidate of the other precision is passed over, and a Bullet the user named (targets, Bullet_DIR) of the
# other precision stops the configuration with both named. Mixing float and double corrupts memory silently (btScalar
# changes every struct layout). Sets in the caller's scope: QUATHINGE_DOUBLE_PRECISION (ON/OFF),
# QUATHINGE_BULLET_FOUND_BY (targets | config | pkg-config), QUATHINGE_BULLET_PC_MODULE (pkg-config module, or empty),
# QUATHINGE_BULLET_VERSION, QUATHINGE_BULLET_DESCRIPTION.
#
# quathinge_record_bullet(<file>) writes what the installed QuatHingeConfig.cmake loads instead of searching again:
# the very files (absolute paths) this build linked, checked to still exist.

# Static link order: a library before the ones it uses.
set(_QUATHINGE_BULLET_ORDER BulletSoftBody BulletInverseDynamics BulletDynamics BulletCollision Bullet3Common LinearMath)

function(_quathinge_requested out)
  if(DEFINED QUATHINGE_DOUBLE_PRECISION AND NOT "${QUATHINGE_DOUBLE_PRECISION}" STREQUAL "")
    if(QUATHINGE_DOUBLE_PRECISION)
      set(${out} ON PARENT_SCOPE)
    else()
      set(${out} OFF PARENT_SCOPE)
    endif()
  else()
    set(${out} "" PARENT_SCOPE)
  endif()
endfunction()

# A Bullet the user named: its precision must be the one asked for, if any.
function(_quathinge_require_precision found_double what)
  _quathinge_requested(_asked)
  if(NOT _asked STREQUAL "" AND NOT _asked STREQUAL found_double)
    message(FATAL_ERROR "QuatHinge: QUATHINGE_DOUBLE_PRECISION=${QUATHINGE_DOUBLE_PRECISION}, but the Bullet found "
                        "(${what}) is built with BT_USE_DOUBLE_PRECISION=${found_double}. Float and double Bullet "
                        "cannot be mixed in one program: drop QUATHINGE_DOUBLE_PRECISION to follow that Bullet, or "
                        "point QuatHinge at a Bullet of the other precision.")
  endif()
endfunction()

# One imported target per library file (QuatHinge::Bullet_<name>), each linking the next one of the list and the last
# one linking `tail`: with a static Bullet, CMake then puts every archive after the ones that use it, whatever links
# them (plain file paths on two interface targets are emitted in first-seen order: the world importer after the core).
function(_quathinge_imported_chain files tail out)
  set(_targets "")
  foreach(_f IN LISTS files)
    get_filename_component(_name "${_f}" NAME_WE)
    string(REGEX REPLACE "^lib" "" _name "${_name}")
    string(MAKE_C_IDENTIFIER "${_name}" _name)
    set(_t QuatHinge::Bullet_${_name})
    if(_f MATCHES "\\.dll\\.a$")   # a MinGW import library: that Bullet is DLLs, linked through it as given
      add_library(${_t} UNKNOWN IMPORTED GLOBAL)
    elseif(_f MATCHES "\\.a$")
      add_library(${_t} STATIC IMPORTED GLOBAL)
    else()
      add_library(${_t} SHARED IMPORTED GLOBAL)
    endif()
    set_target_properties(${_t} PROPERTIES IMPORTED_LOCATION "${_f}")
    set_property(GLOBAL APPEND PROPERTY QUATHINGE_BULLET_LIBRARY_TARGETS ${_t})
    list(APPEND _targets ${_t})
  endforeach()
  set(_next "${tail}")
  list(REVERSE _targets)
  foreach(_t IN LISTS _targets)
    set_target_properties(${_t} PROPERTIES INTERFACE_LINK_LIBRARIES "${_next}")
    set(_next ${_t})
  endforeach()
  list(REVERSE _targets)
  set(${out} "${_targets}" PARENT_SCOPE)
endfunction()

function(_quathinge_make_bullet_target includes libs double)
  if(NOT QUATHINGE_BULLET_FOUND_BY_TARGETS)   # files: one imported target each, chained in link order
    _quathinge_imported_chain("${libs}" "" libs)
  endif()
  add_library(QuatHinge::Bullet INTERFACE IMPORTED GLOBAL)
  set_target_properties(QuatHinge::Bullet PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${includes}"
    INTERFACE_LINK_LIBRARIES "${libs}")
  if(double)
    set_property(TARGET QuatHinge::Bullet APPEND PROPERTY INTERFACE_COMPILE_DEFINITIONS BT_USE_DOUBLE_PRECISION)
  endif()
endfunction()

# The extras of an installed Bullet: only in the core libraries' own directories, so another Bullet elsewhere is
# never mixed in.
function(_quathinge_make_extras_target libdirs includedirs suffix)
  if(NOT QUATHINGE_WORLD_IMPORTER)
    return()
  endif()
  find_library(_importer NAMES BulletWorldImporter${suffix} PATHS ${libdirs} NO_DEFAULT_PATH NO_CACHE)
  find_library(_loader NAMES BulletFileLoader${suffix} PATHS ${libdirs} NO_DEFAULT_PATH NO_CACHE)
  find_path(_importer_include NAMES BulletWorldImporter/btBulletWorldImporter.h PATHS ${includedirs}
            NO_DEFAULT_PATH NO_CACHE)
  if(_importer AND _loader AND _importer_include)
    string(REGEX REPLACE "/$" "" _importer_include "${_importer_include}")
    _quathinge_imported_chain("${_importer};${_loader}" QuatHinge::Bullet _extras)
    set_property(GLOBAL APPEND PROPERTY QUATHINGE_BULLET_OPTIONAL_TARGETS ${_extras})
    add_library(QuatHinge::BulletExtras INTERFACE IMPORTED GLOBAL)
    set_target_properties(QuatHinge::BulletExtras PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${_importer_include};${_importer_include}/BulletWorldImporter"
      INTERFACE_LINK_LIBRARIES "${_extras}")
  endif()
endfunction()

# (a) Bullet's own targets in this build.
function(_quathinge_bullet_from_targets result)
  set(${result} FALSE PARENT_SCOPE)
  set(_suffix NONE)
  foreach(_s "" "-float64")  # Debian's patched source names its double targets LinearMath-float64, …
    if(TARGET LinearMath${_s} AND TARGET BulletCollision${_s} AND TARGET BulletDynamics${_s})
      set(_suffix "${_s}")
      break()
    endif()
  endforeach()
  if(_suffix STREQUAL "NONE")
    return()
  endif()
  if(DEFINED BULLET_PHYSICS_SOURCE_DIR AND EXISTS "${BULLET_PHYSICS_SOURCE_DIR}/src/btBulletDynamicsCommon.h")
    set(_root "${BULLET_PHYSICS_SOURCE_DIR}")
  else()
    get_target_property(_dir LinearMath${_suffix} SOURCE_DIR)   # <bullet>/src/LinearMath
    get_filename_component(_root "${_dir}/../.." ABSOLUTE)
  endif()
  if(NOT EXISTS "${_root}/src/btBulletDynamicsCommon.h")
    message(FATAL_ERROR "QuatHinge: targets LinearMath${_suffix}, BulletCollision${_suffix}, BulletDynamics${_suffix} "
                        "exist but Bullet's headers are not in ${_root}/src (BULLET_PHYSICS_SOURCE_DIR)")
  endif()
  set(_double OFF)
  if(USE_DOUBLE_PRECISION)
    set(_double ON)
  endif()
  _quathinge_require_precision(${_double} "the Bullet targets of this build, ${_root}, USE_DOUBLE_PRECISION=${_double}")
  set(QUATHINGE_BULLET_FOUND_BY_TARGETS TRUE)
  _quathinge_make_bullet_target("${_root}/src"
    "BulletDynamics${_suffix};BulletCollision${_suffix};LinearMath${_suffix}" ${_double})
  if(QUATHINGE_WORLD_IMPORTER AND TARGET BulletWorldImporter${_suffix} AND TARGET BulletFileLoader${_suffix})
    add_library(QuatHinge::BulletExtras INTERFACE IMPORTED GLOBAL)
    set_target_properties(QuatHinge::BulletExtras PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES
        "${_root}/Extras/Serialize;${_root}/Extras/Serialize/BulletWorldImporter;${_root}/Extras/Serialize/BulletFileLoader"
      INTERFACE_LINK_LIBRARIES "BulletWorldImporter${_suffix};BulletFileLoader${_suffix};QuatHinge::Bullet")
  endif()
  if(EXISTS "${_root}/VERSION")
    file(STRINGS "${_root}/VERSION" _version LIMIT_COUNT 1)
  endif()
  set(QUATHINGE_BULLET_VERSION "${_version}" PARENT_SCOPE)
  set(QUATHINGE_BULLET_DESCRIPTION "the targets LinearMath${_suffix}, BulletCollision${_suffix}, BulletDynamics${_suffix} of this build (${_root})" PARENT_SCOPE)
  set(_quathinge_found_double ${_double} PARENT_SCOPE)
  set(${result} TRUE PARENT_SCOPE)
endfunction()

# (b) BulletConfig.cmake that the user pointed at.
function(_quathinge_bullet_from_config result)
  set(${result} FALSE PARENT_SCOPE)
  set(_explicit FALSE)
  if(Bullet_DIR AND NOT "${Bullet_DIR}" STREQUAL "${_QUATHINGE_BULLET_DIR_AUTO}")
    set(_explicit TRUE)
  endif()
  # Not the system prefixes: Debian's /usr/lib/<arch>/cmake/bullet/BulletConfig.cmake is found through pkg-config.
  find_package(Bullet CONFIG QUIET NO_CMAKE_SYSTEM_PATH NO_SYSTEM_ENVIRONMENT_PATH NO_CMAKE_PACKAGE_REGISTRY
               NO_CMAKE_SYSTEM_PACKAGE_REGISTRY)
  if(NOT Bullet_FOUND)
    if(_explicit)
      message(FATAL_ERROR "QuatHinge: Bullet_DIR=${Bullet_DIR} holds no BulletConfig.cmake")
    endif()
    return()
  endif()
  if(NOT _explicit)
    set(_QUATHINGE_BULLET_DIR_AUTO "${Bullet_DIR}" CACHE INTERNAL "Bullet_DIR as found by search, not given")
  endif()
  set(_root "${BULLET_ROOT_DIR}")
  set(_includes "")
  foreach(_d IN LISTS BULLET_INCLUDE_DIRS BULLET_INCLUDE_DIR)
    if(NOT IS_ABSOLUTE "${_d}")
      set(_d "${_root}/${_d}")
    endif()
    get_filename_component(_d "${_d}" ABSOLUTE)
    list(APPEND _includes "${_d}")
  endforeach()
  list(REMOVE_DUPLICATES _includes)
  set(_libdirs "")
  foreach(_d IN LISTS BULLET_LIBRARY_DIRS)
    if(NOT IS_ABSOLUTE "${_d}")
      set(_d "${_root}/${_d}")
    endif()
    list(APPEND _libdirs "${_d}")
  endforeach()
  set(_double OFF)
  set(_suffix "")
  if(BULLET_DEFINITIONS MATCHES "BT_USE_DOUBLE_PRECISION")
    set(_double ON)
  endif()
  if(BULLET_LIBRARIES MATCHES "-float64")
    set(_suffix "-float64")
  endif()
  # What it lists, in link order; the three QuatHinge needs must be there.
  set(_libs "")
  set(_missing "")
  foreach(_name IN LISTS _QUATHINGE_BULLET_ORDER)
    if(NOT "${_name}${_suffix}" IN_LIST BULLET_LIBRARIES AND NOT _name MATCHES "^(BulletDynamics|BulletCollision|LinearMath)$")
      continue()
    endif()
    find_library(_lib_${_name} NAMES ${_name}${_suffix} PATHS ${_libdirs} NO_DEFAULT_PATH NO_CACHE)
    if(_lib_${_name})
      list(APPEND _libs "${_lib_${_name}}")
    else()
      list(APPEND _missing "${_name}${_suffix}")
    endif()
  endforeach()
  find_path(_header btBulletDynamicsCommon.h PATHS ${_includes} NO_DEFAULT_PATH NO_CACHE)
  set(_what "BulletConfig.cmake in ${Bullet_DIR}, BULLET_ROOT_DIR ${_root}")
  if(_missing OR NOT _header)
    set(_why "libraries not found in ${_libdirs}: ${_missing}; btBulletDynamicsCommon.h in ${_includes}: ${_header}")
    if(_explicit)
      message(FATAL_ERROR "QuatHinge: ${_what} is unusable (${_why})")
    endif()
    message(STATUS "QuatHinge: ignoring ${_what} (${_why})")
    return()
  endif()
  _quathinge_requested(_asked)
  if(NOT _explicit AND NOT _asked STREQUAL "" AND NOT _asked STREQUAL _double)
    message(STATUS "QuatHinge: passing over ${_what}: BT_USE_DOUBLE_PRECISION=${_double}")
    set(_quathinge_passed_over "${_what} (BT_USE_DOUBLE_PRECISION=${_double})" PARENT_SCOPE)
    return()
  endif()
  _quathinge_require_precision(${_double} "${_what}, BULLET_DEFINITIONS '${BULLET_DEFINITIONS}'")
  _quathinge_make_bullet_target("${_includes}" "${_libs}" ${_double})
  _quathinge_make_extras_target("${_libdirs}" "${_includes}" "${_suffix}")
  set(QUATHINGE_BULLET_VERSION "${BULLET_VERSION_STRING}" PARENT_SCOPE)
  set(QUATHINGE_BULLET_DESCRIPTION "${_what}" PARENT_SCOPE)
  set(_quathinge_found_double ${_double} PARENT_SCOPE)
  set(${result} TRUE PARENT_SCOPE)
endfunction()

# (c) pkg-config.
function(_quathinge_bullet_from_pkgconfig result)
  set(${result} FALSE PARENT_SCOPE)
  find_package(PkgConfig QUIET)
  if(NOT PKG_CONFIG_FOUND)
    return()
  endif()
  _quathinge_requested(_asked)
  if(_asked STREQUAL "ON")
    set(_modules bullet-float64 bullet)
  else()
    set(_modules bullet bullet-float64)
  endif()
  set(_passed "${_quathinge_passed_over}")
  foreach(_module IN LISTS _modules)
    string(MAKE_C_IDENTIFIER "QUATHINGE_PC_${_module}" _p)
    pkg_check_modules(${_p} QUIET ${_module})
    if(NOT ${_p}_FOUND)
      continue()
    endif()
    set(_double OFF)
    if("${${_p}_CFLAGS_OTHER}" MATCHES "BT_USE_DOUBLE_PRECISION")
      set(_double ON)
    endif()
    set(_where "${${_p}_PREFIX}")
    if(_where STREQUAL "")   # Bullet 2.88's bullet.pc has no prefix= variable
      set(_where "${${_p}_LIBRARY_DIRS}")
    endif()
    set(_what "pkg-config ${_module} ${${_p}_VERSION} in ${_where}")
    if(NOT _asked STREQUAL "" AND NOT _asked STREQUAL _double)
      list(APPEND _passed "${_what} (BT_USE_DOUBLE_PRECISION=${_double})")
      continue()
    endif()
    set(_libs "")
    foreach(_lib IN LISTS ${_p}_LIBRARIES)
      find_library(_path_${_lib} NAMES ${_lib} PATHS ${${_p}_LIBRARY_DIRS} NO_DEFAULT_PATH NO_CACHE)
      if(NOT _path_${_lib})
        message(FATAL_ERROR "QuatHinge: Bullet library ${_lib} (from ${_what}) not found in ${${_p}_LIBRARY_DIRS}")
      endif()
      list(APPEND _libs "${_path_${_lib}}")
    endforeach()
    _quathinge_make_bullet_target("${${_p}_INCLUDE_DIRS}" "${_libs}" ${_double})
    set(_suffix "")
    if(_module MATCHES "-float64$")
      set(_suffix "-float64")
    endif()
    _quathinge_make_extras_target("${${_p}_LIBRARY_DIRS}" "${${_p}_INCLUDE_DIRS}" "${_suffix}")
    set(QUATHINGE_BULLET_PC_MODULE ${_module} PARENT_SCOPE)
    set(QUATHINGE_BULLET_VERSION "${${_p}_VERSION}" PARENT_SCOPE)
    set(QUATHINGE_BULLET_DESCRIPTION "${_what}" PARENT_SCOPE)
    set(_quathinge_found_double ${_double} PARENT_SCOPE)
    set(${result} TRUE PARENT_SCOPE)
    return()
  endforeach()
  if(_passed)
    message(FATAL_ERROR "QuatHinge: QUATHINGE_DOUBLE_PRECISION=${QUATHINGE_DOUBLE_PRECISION}, but every Bullet found is "
                        "of the other precision: ${_passed}. Float and double Bullet cannot be mixed in one program.")
  endif()
endfunction()

macro(quathinge_find_bullet)
  if(TARGET QuatHinge::Bullet)
    # Made earlier in this build (it is GLOBAL): keep it, but a second call may not ask for the other precision.
    get_target_property(_quathinge_defs QuatHinge::Bullet INTERFACE_COMPILE_DEFINITIONS)
    set(_quathinge_found_double OFF)
    if("BT_USE_DOUBLE_PRECISION" IN_LIST _quathinge_defs)
      set(_quathinge_found_double ON)
    endif()
    _quathinge_require_precision(${_quathinge_found_double} "QuatHinge::Bullet, made earlier in this build")
  else()
    set(QUATHINGE_BULLET_PC_MODULE "")
    set(_quathinge_passed_over "")
    _quathinge_bullet_from_targets(_quathinge_ok)
    if(_quathinge_ok)
      set(QUATHINGE_BULLET_FOUND_BY targets)
    else()
      _quathinge_bullet_from_config(_quathinge_ok)
      if(_quathinge_ok)
        set(QUATHINGE_BULLET_FOUND_BY config)
      else()
        _quathinge_bullet_from_pkgconfig(_quathinge_ok)
        set(QUATHINGE_BULLET_FOUND_BY pkg-config)
      endif()
    endif()
    if(NOT _quathinge_ok)
      message(FATAL_ERROR "QuatHinge: no Bullet found. On Debian: apt-get install libbullet-dev libbullet-extras-dev "
                          "(cmake/setup-debian.sh). Or point at one: -DBullet_DIR=<prefix>/lib/cmake/bullet, "
                          "-DCMAKE_PREFIX_PATH=<prefix> (its bullet.pc), or add_subdirectory(<bullet source>) before "
                          "QuatHinge in a super-project.")
    endif()
    if(TARGET QuatHinge::BulletExtras)
      set(_quathinge_extras "with its world importer (QuatHinge::BulletExtras)")
    elseif(NOT QUATHINGE_WORLD_IMPORTER)
      string(CONCAT _quathinge_extras "its world importer left out (QUATHINGE_WORLD_IMPORTER=OFF): no .bullet scene, and the "
                            ".bullet import tests are not registered")
    else()
      string(CONCAT _quathinge_extras "without a world importer (BulletWorldImporter; on Debian libbullet-extras-dev): no .bullet "
                            "scene, and the .bullet import tests are not registered")
    endif()
    message(STATUS "QuatHinge: Bullet ${QUATHINGE_BULLET_VERSION}, BT_USE_DOUBLE_PRECISION=${_quathinge_found_double}: "
                   "${QUATHINGE_BULLET_DESCRIPTION}; ${_quathinge_extras}")
  endif()
  set(QUATHINGE_DOUBLE_PRECISION ${_quathinge_found_double})
endmacro()

# The installed package loads this instead of searching: exactly the Bullet this build used.
function(quathinge_record_bullet file)
  set(_body "")
  get_property(_lib_targets GLOBAL PROPERTY QUATHINGE_BULLET_LIBRARY_TARGETS)
  get_property(_optional GLOBAL PROPERTY QUATHINGE_BULLET_OPTIONAL_TARGETS)
  foreach(_t IN LISTS _lib_targets)
    get_target_property(_type ${_t} TYPE)
    string(REPLACE "_LIBRARY" "" _type "${_type}")
    get_target_property(_location ${_t} IMPORTED_LOCATION)
    get_target_property(_next ${_t} INTERFACE_LINK_LIBRARIES)
    if(NOT _next)
      set(_next "")
    endif()
    if(_t IN_LIST _optional)   # the world importer: only the demos need it
      set(_on_missing "message(STATUS \"QuatHinge: ${_location} is missing: no QuatHinge::BulletExtras\")")
    else()
      set(_on_missing "message(FATAL_ERROR \"QuatHinge (\${CMAKE_CURRENT_LIST_DIR}) was built against \"
    \"${QUATHINGE_BULLET_DESCRIPTION}; ${_location} is no longer there. Reinstall that Bullet, or rebuild QuatHinge \"
    \"against the Bullet you have.\")")
    endif()
    string(APPEND _body "
if(NOT EXISTS \"${_location}\")
  ${_on_missing}
elseif(NOT TARGET ${_t})
  add_library(${_t} ${_type} IMPORTED)
  set_target_properties(${_t} PROPERTIES IMPORTED_LOCATION \"${_location}\" INTERFACE_LINK_LIBRARIES \"${_next}\")
endif()
")
  endforeach()
  foreach(_target QuatHinge::Bullet QuatHinge::BulletExtras)
    if(NOT TARGET ${_target})
      continue()
    endif()
    get_target_property(_inc ${_target} INTERFACE_INCLUDE_DIRECTORIES)
    get_target_property(_libs ${_target} INTERFACE_LINK_LIBRARIES)
    get_target_property(_defs ${_target} INTERFACE_COMPILE_DEFINITIONS)
    if(NOT _defs)
      set(_defs "")
    endif()
    set(_files "")
    set(_links "")
    foreach(_lib IN LISTS _libs)
      if(_lib MATCHES "^QuatHinge::")
        list(APPEND _links "${_lib}")
      elseif(TARGET ${_lib})   # (a): a Bullet target of the super-project, recorded by its file in that build
        list(APPEND _links "$<TARGET_LINKER_FILE:${_lib}>")
        list(APPEND _files "$<TARGET_LINKER_FILE:${_lib}>")
      else()
        list(APPEND _links "${_lib}")
        list(APPEND _files "${_lib}")
      endif()
    endforeach()
    list(APPEND _files ${_inc})
    if(_target STREQUAL "QuatHinge::Bullet")
      set(_on_missing "message(FATAL_ERROR \"QuatHinge (\${CMAKE_CURRENT_LIST_DIR}) was built against \"
        \"${QUATHINGE_BULLET_DESCRIPTION}; \${_quathinge_file} is no longer there. Reinstall that Bullet, or \"
        \"rebuild QuatHinge against the Bullet you have.\")")
    else()   # only the demos need the world importer: the package works without it, just without this target
      set(_on_missing "message(STATUS \"QuatHinge: no ${_target}: \${_quathinge_file} is missing\")
      set(_quathinge_complete FALSE)")
    endif()
    string(APPEND _body "
set(_quathinge_complete TRUE)
foreach(_quathinge_file IN ITEMS ${_files})
  if(NOT EXISTS \"\${_quathinge_file}\")
    ${_on_missing}
  endif()
endforeach()
foreach(_quathinge_link IN ITEMS ${_links})
  if(_quathinge_link MATCHES \"^QuatHinge::Bullet_\" AND NOT TARGET \${_quathinge_link})
    set(_quathinge_complete FALSE)
  endif()
endforeach()
if(_quathinge_complete AND NOT TARGET ${_target})
  add_library(${_target} INTERFACE IMPORTED)
  set_target_properties(${_target} PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES \"${_inc}\"
    INTERFACE_LINK_LIBRARIES \"${_links}\"
    INTERFACE_COMPILE_DEFINITIONS \"${_defs}\")
endif()
")
  endforeach()
  if(QUATHINGE_BULLET_FOUND_BY STREQUAL "targets")
    message(WARNING "QuatHinge: installing a QuatHinge built against the Bullet targets of this build: the installed "
                    "package records their files in this build tree.")
  endif()
  file(GENERATE OUTPUT "${file}" CONTENT "# Written by QuatHinge's build: the Bullet it was built with, never looked up again.
# Bullet ${QUATHINGE_BULLET_VERSION}, BT_USE_DOUBLE_PRECISION=${QUATHINGE_DOUBLE_PRECISION}: ${QUATHINGE_BULLET_DESCRIPTION}
set(QUATHINGE_BULLET_VERSION \"${QUATHINGE_BULLET_VERSION}\")
set(QUATHINGE_BULLET_PC_MODULE \"${QUATHINGE_BULLET_PC_MODULE}\")
${_body}")
endfunction()
