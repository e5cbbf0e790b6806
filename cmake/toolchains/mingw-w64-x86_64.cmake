# SPDX-License-Identifier: MIT
# Cross-compiling for 64-bit Windows with the mingw-w64 GCC toolchain (Debian: mingw-w64).
#   cmake -S . -B build-windows -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake \
#         -DAGGRELOD_RUNTIME_ONLY=ON
# Other prefixes (e.g. MSYS2's or another distribution's): -DMINGW_TRIPLET=<prefix of the tools>.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)

set(MINGW_TRIPLET "x86_64-w64-mingw32" CACHE STRING "Prefix of the mingw-w64 tools (gcc, g++, windres)")
# Debian ships each compiler in two thread models; its default, win32, has no std::mutex or
# std::thread with GCC 12 (GoogleTest needs them): take the posix one (winpthreads) when present.
find_program(MINGW_CXX NAMES ${MINGW_TRIPLET}-g++-posix ${MINGW_TRIPLET}-g++ REQUIRED)
find_program(MINGW_CC NAMES ${MINGW_TRIPLET}-gcc-posix ${MINGW_TRIPLET}-gcc REQUIRED)
set(CMAKE_C_COMPILER ${MINGW_CC})
set(CMAKE_CXX_COMPILER ${MINGW_CXX})
set(CMAKE_RC_COMPILER ${MINGW_TRIPLET}-windres)

# Libraries and packages only from the Windows sysroot, never the build machine's (its Embree,
# GoogleTest, ... are Linux binaries); programs from the build machine.
set(CMAKE_FIND_ROOT_PATH /usr/${MINGW_TRIPLET})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
