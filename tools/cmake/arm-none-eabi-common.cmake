# What the cross toolchains (arm-none-eabi-cm0.cmake, arm-none-eabi-cm4.cmake)
# share: Debian's arm-none-eabi GCC, bare metal, one section per function and
# object (-Wl,--gc-sections drops what is not referenced). The including file
# sets PMSM_CPU_FLAGS (core, instruction set, float ABI) and PMSM_LINK_SPECS
# (C library and start files) first.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_SIZE arm-none-eabi-size CACHE FILEPATH "size tool")
set(CMAKE_NM arm-none-eabi-nm CACHE FILEPATH "nm tool")
# No hosted link test: the compiler checks build a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(CMAKE_C_FLAGS_INIT "${PMSM_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${PMSM_CPU_FLAGS} -ffunction-sections -fdata-sections -fno-exceptions -fno-rtti")
set(CMAKE_ASM_FLAGS_INIT "${PMSM_CPU_FLAGS}")

set(CMAKE_EXE_LINKER_FLAGS_INIT "${PMSM_CPU_FLAGS} ${PMSM_LINK_SPECS} -Wl,--gc-sections")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
