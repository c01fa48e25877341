# quathinge_require(<package> [find_package arguments...] DEBIAN <Debian packages...> FOR <what> OFF <option>)
# find_package for a part that cannot do without it: when it is missing, configure stops naming the Debian packages
# to install and the option that leaves the part out (instead of CMake's generic "could not find a package
# configuration file"). A macro: the package's variables and targets stay in the caller's scope.
macro(quathinge_require _qr_package)
  cmake_parse_arguments(_qr "" "FOR;OFF" "DEBIAN" ${ARGN})
  find_package(${_qr_package} ${_qr_UNPARSED_ARGUMENTS} QUIET)
  if(NOT ${_qr_package}_FOUND)
    string(REPLACE ";" " " _qr_DEBIAN "${_qr_DEBIAN}")
    message(FATAL_ERROR "QuatHinge: ${_qr_FOR} need ${_qr_package}, which was not found. On Debian: apt-get install "
                        "${_qr_DEBIAN} (bash cmake/setup-debian.sh installs every package), or build without them: "
                        "-D${_qr_OFF}=OFF")
  endif()
endmacro()
