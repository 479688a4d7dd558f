# Build-wide settings. PMSM_TARGET: host | cm4 | cm0 (set by the presets).
set(PMSM_TARGET "host" CACHE STRING "host, cm4, cm0, stm32g4 or stm32f4")
set_property(CACHE PMSM_TARGET PROPERTY STRINGS host cm4 cm0 stm32g4 stm32f4)
# Board of a stm32g4 build (a folder of hal/boards/ and its app in firmware/apps/).
set(PMSM_BOARD "b_g431b_esc1" CACHE STRING "board of the stm32g4 build")
option(PMSM_SANITIZE "Build host code with ASan and UBSan" OFF)
set(UNITY_ROOT "" CACHE PATH "Upstream Unity checkout to build the tests against (empty: tests/unity)")

# Strict warnings for the product folders (control/, hal/, firmware/).
set(PMSM_STRICT_WARNINGS -Wall -Wextra -Wconversion -Wsign-conversion -Wshadow
    -Wstrict-prototypes -Wmissing-prototypes -Wundef -Werror)
function(pmsm_strict target)
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:C>:${PMSM_STRICT_WARNINGS}>)
endfunction()

if(PMSM_SANITIZE AND PMSM_TARGET STREQUAL "host")
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()

# pmsm_no_fpu(<source>...): the code of the PWM-period interrupt (the control
# core's per-sample files, the pipeline, the commissioning steps, a board's
# interrupt HAL) without the FPU's registers on the hard-float Cortex-M4
# (-mgeneral-regs-only): GCC otherwise moves and spills 64-bit integers
# through d7, the interrupt then counts as FPU code, and its preemption of
# FPU code stacks the FP context (lazy stacking: 17 words, and the extended
# frame for every interrupt above it). These files are float-free (the
# control core's is checked on the Cortex-M0+: control_float_free_cm0); a
# float in them is now a compile error on these targets. Call it in the
# directory that defines the targets of the files (source properties are
# per directory).
function(pmsm_no_fpu)
  if(PMSM_TARGET STREQUAL "cm4" OR PMSM_TARGET STREQUAL "stm32g4" OR PMSM_TARGET STREQUAL "stm32f4")
    set_property(SOURCE ${ARGN} APPEND PROPERTY COMPILE_OPTIONS -mgeneral-regs-only)
  endif()
endfunction()

# pmsm_qemu_firmware(<executable target>)
#   Makes a cm4 executable a QEMU mps2-an386 image: links the board support
#   (startup, linker script, syscalls, UART, timers), names it <target>.elf, writes
#   <target>.map beside it and prints arm-none-eabi-size after the link.
#   Run it with tools/qemu-run <target>.elf.
function(pmsm_qemu_firmware target)
  if(NOT PMSM_TARGET STREQUAL "cm4")
    message(FATAL_ERROR "pmsm_qemu_firmware(${target}) needs the cm4 preset")
  endif()
  set_target_properties(${target} PROPERTIES SUFFIX ".elf")
  target_link_libraries(${target} PRIVATE pmsm_qemu_mps2)
  target_link_options(${target} PRIVATE "-Wl,-Map=$<TARGET_FILE_DIR:${target}>/${target}.map")
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND ${CMAKE_SIZE} $<TARGET_FILE:${target}>
    VERBATIM)
endfunction()
