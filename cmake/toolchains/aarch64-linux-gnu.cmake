# Cross-compiling Linux arm64 (aarch64) binaries on Debian x86-64 (g++-aarch64-linux-gnu; make
# arm64 installs it). The compilers' own sysroot /usr/aarch64-linux-gnu holds the target's libc
# and libstdc++; ctest runs the test executables under qemu-user, emulating a Cortex-A76 (the core
# of many arm64 phones), with SOFTDECA_QEMU_PREFIX as its library prefix (make arm64 passes the
# one plugin/platforms/linux-arm64/setup-cross.sh makes: the sysroot's libraries and a
# /proc/cpuinfo for ONNX Runtime).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(SOFTDECA_CROSS_PREFIX aarch64-linux-gnu)
set(CMAKE_C_COMPILER ${SOFTDECA_CROSS_PREFIX}-gcc)
set(CMAKE_CXX_COMPILER ${SOFTDECA_CROSS_PREFIX}-g++)

# Target headers and libraries from the sysroot only (no host METIS or assimp); programs (python,
# ninja) from the host.
set(SOFTDECA_CROSS_SYSROOT /usr/${SOFTDECA_CROSS_PREFIX})
set(CMAKE_FIND_ROOT_PATH ${SOFTDECA_CROSS_SYSROOT})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

set(SOFTDECA_QEMU_PREFIX ${SOFTDECA_CROSS_SYSROOT} CACHE PATH "qemu-aarch64's library prefix (-L)")
find_program(SOFTDECA_QEMU qemu-aarch64)
if(SOFTDECA_QEMU)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${SOFTDECA_QEMU} -cpu cortex-a76 -L ${SOFTDECA_QEMU_PREFIX})
endif()

# Eigen is header-only: the host's package serves (the sysroot has none).
set(Eigen3_DIR /usr/share/eigen3/cmake CACHE PATH "Eigen3 CMake package (header-only)")
