# Finds Debian's Bullet through pkg-config and wraps it in the imported target QuatHinge::Bullet.
#
# Debian's BulletConfig.cmake is unusable (relative paths, names of libraries libbullet-dev lacks, no targets, no
# version), so it is not used. pkg-config `bullet` is the float build, `bullet-float64` the double build; the double
# build's BT_USE_DOUBLE_PRECISION becomes an INTERFACE definition of QuatHinge::Bullet, so everything that links it —
# QuatHinge itself and every consumer — is compiled with the precision of the libraries it links. Mixing the two
# corrupts memory silently (btScalar changes every struct layout), so this is the one place that decides it.
#
# Used both in-tree and from the installed package (QuatHingeConfig.cmake includes this file).
# Also defines QuatHinge::BulletExtras (world importer + file loader) when libbullet-extras-dev is installed.

function(quathinge_find_bullet)
  if(TARGET QuatHinge::Bullet)
    # Made earlier in this project (it is GLOBAL): a second call may not ask for the other precision.
    get_target_property(_defs QuatHinge::Bullet INTERFACE_COMPILE_DEFINITIONS)
    set(_have_double OFF)
    if("BT_USE_DOUBLE_PRECISION" IN_LIST _defs)
      set(_have_double ON)
    endif()
    if((_have_double AND NOT QUATHINGE_DOUBLE_PRECISION) OR (NOT _have_double AND QUATHINGE_DOUBLE_PRECISION))
      message(FATAL_ERROR "QuatHinge: QuatHinge::Bullet already exists with BT_USE_DOUBLE_PRECISION=${_have_double}, "
                          "now asked for QUATHINGE_DOUBLE_PRECISION=${QUATHINGE_DOUBLE_PRECISION}: float and double "
                          "Bullet cannot be mixed in one program.")
    endif()
    return()
  endif()
  find_package(PkgConfig REQUIRED)
  if(QUATHINGE_DOUBLE_PRECISION)
    set(_module bullet-float64)
    set(_suffix -float64)
  else()
    set(_module bullet)
    set(_suffix "")
  endif()
  pkg_check_modules(QUATHINGE_PC_BULLET QUIET ${_module})
  if(NOT QUATHINGE_PC_BULLET_FOUND)
    message(FATAL_ERROR "QuatHinge: pkg-config module '${_module}' not found. On Debian: apt-get install libbullet-dev "
                        "(or run cmake/setup-debian.sh).")
  endif()

  add_library(QuatHinge::Bullet INTERFACE IMPORTED GLOBAL)
  set(_libs "")
  foreach(_lib IN LISTS QUATHINGE_PC_BULLET_LIBRARIES)
    find_library(_path_${_lib} NAMES ${_lib} HINTS ${QUATHINGE_PC_BULLET_LIBRARY_DIRS} NO_CACHE)
    if(NOT _path_${_lib})
      message(FATAL_ERROR "QuatHinge: Bullet library ${_lib} (from pkg-config ${_module}) not found")
    endif()
    list(APPEND _libs "${_path_${_lib}}")
  endforeach()
  set_target_properties(QuatHinge::Bullet PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${QUATHINGE_PC_BULLET_INCLUDE_DIRS}"
    INTERFACE_LINK_LIBRARIES "${_libs}")
  if(QUATHINGE_DOUBLE_PRECISION)
    set_property(TARGET QuatHinge::Bullet APPEND PROPERTY INTERFACE_COMPILE_DEFINITIONS BT_USE_DOUBLE_PRECISION)
  endif()

  # The extras (BulletWorldImporter, BulletFileLoader) have no pkg-config file: only the same libdir as the core
  # libraries is searched, so a different Bullet elsewhere can never be mixed in.
  find_library(_importer NAMES BulletWorldImporter${_suffix} PATHS ${QUATHINGE_PC_BULLET_LIBRARY_DIRS}
               NO_DEFAULT_PATH NO_CACHE)
  find_library(_loader NAMES BulletFileLoader${_suffix} PATHS ${QUATHINGE_PC_BULLET_LIBRARY_DIRS}
               NO_DEFAULT_PATH NO_CACHE)
  find_path(_importer_include NAMES BulletWorldImporter/btBulletWorldImporter.h
            HINTS ${QUATHINGE_PC_BULLET_INCLUDE_DIRS} NO_CACHE)
  if(_importer AND _loader AND _importer_include)
    add_library(QuatHinge::BulletExtras INTERFACE IMPORTED GLOBAL)
    set_target_properties(QuatHinge::BulletExtras PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${_importer_include};${_importer_include}/BulletWorldImporter"
      INTERFACE_LINK_LIBRARIES "${_importer};${_loader};QuatHinge::Bullet")
    set(_extras "QuatHinge::BulletExtras: ${_importer}")
  else()
    set(_extras "no world importer (libbullet-extras-dev): .bullet scenes are skipped")
  endif()
  message(STATUS "QuatHinge: Bullet ${QUATHINGE_PC_BULLET_VERSION} (${_module}); ${_extras}")
endfunction()
