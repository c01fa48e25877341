# Cross-compiling for Linux ARM64 with Debian's aarch64 GCC (g++-aarch64-linux-gnu, libc6-dev-arm64-cross), programs
# run under qemu-aarch64 (Debian's qemu-user) by ctest and gtest_discover_tests.
#   cmake -S . -B build-arm64 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/aarch64-linux-gnu.cmake \
#         -DCMAKE_FIND_ROOT_PATH="<Bullet prefix>;<GoogleTest prefix>"
# Libraries, headers and packages are looked up only under CMAKE_FIND_ROOT_PATH (the prefixes given, then the cross
# root /usr/aarch64-linux-gnu), so no x86-64 library of this machine is ever taken. Header-only Eigen is the exception
# the caller names: -DEigen3_DIR=/usr/share/eigen3/cmake. cmake/ci-cross.sh is the worked example.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
list(APPEND CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
if(NOT CMAKE_CROSSCOMPILING_EMULATOR)
  find_program(_quathinge_qemu NAMES qemu-aarch64 qemu-aarch64-static)
  if(_quathinge_qemu)
    set(CMAKE_CROSSCOMPILING_EMULATOR ${_quathinge_qemu} -L /usr/aarch64-linux-gnu)
  endif()
endif()
