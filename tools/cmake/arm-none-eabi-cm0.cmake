# Cross toolchain: Cortex-M0+ without FPU (soft float). Used to build control/ alone
# and check that its per-sample code needs no floating-point helper.
set(PMSM_CPU_FLAGS "-mcpu=cortex-m0plus -mthumb -mfloat-abi=soft")
set(PMSM_LINK_SPECS "--specs=nano.specs --specs=nosys.specs")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
