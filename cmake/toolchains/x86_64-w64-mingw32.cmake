# Cross-compiling for Windows x86-64 with Debian's MinGW-w64 (g++-mingw-w64-x86-64-posix: the POSIX thread model, for
# std::thread), programs run under wine (Debian's wine64) by ctest and gtest_discover_tests.
#   cmake -S . -B build-mingw -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/x86_64-w64-mingw32.cmake \
#         -DCMAKE_FIND_ROOT_PATH="<Bullet prefix>;<GoogleTest prefix>"
# Libraries, headers and packages are looked up only under CMAKE_FIND_ROOT_PATH (the prefixes given, then MinGW's own
# /usr/x86_64-w64-mingw32), so no Linux library of this machine is ever taken. Header-only Eigen is the exception
# the caller names: -DEigen3_DIR=/usr/share/eigen3/cmake. cmake/ci-cross.sh is the worked example.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc-posix)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)
list(APPEND CMAKE_FIND_ROOT_PATH /usr/x86_64-w64-mingw32)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
if(NOT CMAKE_CROSSCOMPILING_EMULATOR AND EXISTS /usr/lib/wine/wine64)
  set(CMAKE_CROSSCOMPILING_EMULATOR /usr/lib/wine/wine64)
endif()
