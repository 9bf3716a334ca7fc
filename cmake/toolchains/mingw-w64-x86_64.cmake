# Cross-compiling Windows x64 binaries on Linux with MinGW-w64 (Debian: g++-mingw-w64-x86-64-posix).
# The -posix compilers: the -win32 thread model has no std::thread. With wine installed, ctest runs
# the Windows test executables through it (CMAKE_CROSSCOMPILING_EMULATOR).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)

set(SOFTDECA_MINGW_PREFIX x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${SOFTDECA_MINGW_PREFIX}-gcc-posix)
set(CMAKE_CXX_COMPILER ${SOFTDECA_MINGW_PREFIX}-g++-posix)
set(CMAKE_RC_COMPILER ${SOFTDECA_MINGW_PREFIX}-windres)

# Target headers and libraries from the MinGW sysroot only; programs (python, ninja) from the host.
set(CMAKE_FIND_ROOT_PATH /usr/${SOFTDECA_MINGW_PREFIX})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# No MinGW runtime DLLs beside ours: libgcc, libstdc++ and winpthread linked in statically.
# winpthread's archive goes whole onto every link line: the compiler driver's own -lpthread then
# finds nothing left to import, so nothing needs libwinpthread-1.dll.
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static-libgcc -static-libstdc++")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static-libgcc -static-libstdc++")
set(SOFTDECA_MINGW_PTHREAD "-Wl,-Bstatic,--whole-archive -lwinpthread -Wl,--no-whole-archive,-Bdynamic")
set(CMAKE_C_STANDARD_LIBRARIES "${SOFTDECA_MINGW_PTHREAD}" CACHE STRING "" FORCE)
set(CMAKE_CXX_STANDARD_LIBRARIES "${SOFTDECA_MINGW_PTHREAD}" CACHE STRING "" FORCE)

find_program(SOFTDECA_WINE wine)
if(SOFTDECA_WINE)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${SOFTDECA_WINE})
endif()

# Eigen is header-only: the host's package serves (the sysroot has none).
set(Eigen3_DIR /usr/share/eigen3/cmake CACHE PATH "Eigen3 CMake package (header-only)")
