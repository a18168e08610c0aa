# SPDX-License-Identifier: MIT
# arm-none-eabi.cmake - CMake toolchain for the core on a Cortex-M7 with
# double-precision FPU (Debian gcc-arm-none-eabi + libnewlib-arm-none-eabi).
#
#   cmake -S . -B build-arm-cmake -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
#         -DRCAL_BUILD_HOST=OFF -DRCAL_BUILD_TESTS=OFF
#   cmake --build build-arm-cmake        (builds librcalcore.a: the core only)
#
# Contract checks are routed to the firmware's fault handler through
# firmware_host/fw_port.h (force-included), so the archive has no assert()
# and therefore no fprintf. firmware_host/cross_build.sh does the same by
# hand and also links the firmware example and checks its symbols.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_AR arm-none-eabi-ar)
set(CMAKE_RANLIB arm-none-eabi-ranlib)
# No linking in compiler checks: there is no OS to link against.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
get_filename_component(_rcal_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(CMAKE_C_FLAGS_INIT
    "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -ffunction-sections -fdata-sections -include ${_rcal_root}/firmware_host/fw_port.h")
set(CMAKE_C_FLAGS_MINSIZEREL_INIT "-Os")
set(CMAKE_EXE_LINKER_FLAGS_INIT "--specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
