# Cross toolchain: Cortex-M4F (QEMU mps2-an386), hard-float single precision.
set(PMSM_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard")
# newlib-nano; our own startup (hal/qemu_mps2) replaces crt0, syscalls replace libnosys.
set(PMSM_LINK_SPECS "--specs=nano.specs -nostartfiles")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
