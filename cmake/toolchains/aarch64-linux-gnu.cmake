# Cross-compiling for 64-bit ARM Linux with Debian's toolchain (g++-aarch64-linux-gnu) against
# arm64 packages installed through multiarch; tests run under qemu-user (scripts/cross-aarch64.sh).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
# The arm64 C library of multiarch (libc6:arm64) serves at run time: the cross toolchain's own copy
# (qemu -L /usr/aarch64-linux-gnu) hangs threads when mixed with it.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64)
