# SPDX-License-Identifier: MIT
# arm-none-eabi-m4f.cmake - CMake toolchain for the core on a Cortex-M4F with
# single-precision FPU (Debian gcc-arm-none-eabi + libnewlib-arm-none-eabi):
# rc_real = float (RC_REAL_FLOAT), so the compensation path (rc_kin, rc_comp)
# uses the FPU only; the solvers stay double (software on this FPU).
#
#   cmake -S . -B build-m4f -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi-m4f.cmake \
#         -DRCAL_BUILD_HOST=OFF -DRCAL_BUILD_TESTS=OFF
#   cmake --build build-m4f              (builds librcalcore.a: the core only)
#
# Contract checks are routed to the firmware's fault handler through
# firmware_host/fw_port.h (force-included), so the archive has no assert()
# and therefore no fprintf. firmware_host/cross_build.sh does the same by
# hand, links the firmware example and checks that no double routine is on
# the compensation path.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_AR arm-none-eabi-ar)
set(CMAKE_RANLIB arm-none-eabi-ranlib)
# No linking in compiler checks: there is no OS to link against.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
get_filename_component(_rcal_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(CMAKE_C_FLAGS_INIT
    "-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -mthumb -DRC_REAL_FLOAT -ffunction-sections -fdata-sections -include ${_rcal_root}/firmware_host/fw_port.h")
set(CMAKE_C_FLAGS_MINSIZEREL_INIT "-Os")
set(CMAKE_EXE_LINKER_FLAGS_INIT "--specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
