# Cross build for 64-bit ARM with Debian's g++-aarch64-linux-gnu; ctest runs the test
# binaries under qemu-aarch64 (Debian's qemu-user), so NEON kernels are tested on x86.
# Two ways:
#   the inference core alone, against the cross compiler's own libc and libstdc++:
#     cmake -S . -B build-aarch64 -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
#           -DAMPI_WITH_OPENCV=OFF
#   the whole program, against an arm64 Debian sysroot (scripts/arm64_sysroot.sh):
#     cmake -S . -B build-aarch64 -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
#           -DAMPI_ARM64_SYSROOT=$PWD/build-aarch64-sysroot
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# try_compile projects see the sysroot too
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES AMPI_ARM64_SYSROOT)
if(AMPI_ARM64_SYSROOT)
  set(CMAKE_SYSROOT ${AMPI_ARM64_SYSROOT})
  set(ampi_arm_root ${AMPI_ARM64_SYSROOT})
  set(OpenCV_DIR ${AMPI_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/cmake/opencv4 CACHE PATH "arm64 OpenCV")
else()
  set(ampi_arm_root /usr/aarch64-linux-gnu)
endif()

# Libraries, headers and packages come only from the ARM tree, never the host's
# /usr/include or /usr/lib (the cross compiler itself never searches those); host
# programs (the build tools) are still found on the host.
set(CMAKE_FIND_ROOT_PATH ${ampi_arm_root})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# -L points qemu's dynamic loader at the ARM libc, libstdc++ (and OpenCV).
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64;-L;${ampi_arm_root})
