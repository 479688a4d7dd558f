# Image checks of a stm32f4 build (included from the top-level CMakeLists.txt;
# ctest --preset vesc6 / odrive-v36): the ELF as the chip boots it, its
# messages' formats, tools/flash for the board, the image booted in QEMU's
# emulated STM32F405 (netduinoplus2), and the board's PIL image there under
# ./tools/sim --target board:DEV.
set(PMSM_F405_ELF ${CMAKE_BINARY_DIR}/firmware/apps/f405/pmsm-${PMSM_BOARD}.elf)
# Per board: the console's USART as QEMU numbers its serial ports (USART1,
# USART2, USART3, UART4, ...: -serial options in that order) and its IRQ
# (RM0090 table 61), nFAULT's EXTI IRQ; the board's tools/flash name.
if(PMSM_BOARD STREQUAL "vesc6")
  set(f405_qemu_serial 2)  # USART3 (PB10/PB11, the COMM port)
  set(f405_console_irq 39) # USART3
  set(f405_nfault_irq 23)  # PB7: EXTI9_5
  set(f405_flash_board vesc6)
elseif(PMSM_BOARD STREQUAL "odrive_v36")
  set(f405_qemu_serial 3)  # UART4 (PA0/PA1, GPIO 1/2)
  set(f405_console_irq 52) # UART4
  set(f405_nfault_irq 8)   # PD2: EXTI2
  set(f405_flash_board odrive-v36)
else()
  message(FATAL_ERROR "f4_image_tests.cmake: no checks for board '${PMSM_BOARD}'")
endif()
set(f405_tests ${PMSM_BOARD}_image ${PMSM_BOARD}_image_printf ${PMSM_BOARD}_flash
    ${PMSM_BOARD}_qemu_boot ${PMSM_BOARD}_qemu_wdg ${PMSM_BOARD}_isr_fpu_free
    ${PMSM_BOARD}_stack ${PMSM_BOARD}_stack_limit_fails)
# The static stack check (tools/stack_check.py), as the B-G431B-ESC1's: every
# entry point's worst depth from the image's call graph and its
# -fstack-usage frames, the priority levels nested, within 75 % of the
# reserved stack; the control interrupt and the medium-rate task free of FPU
# instructions. And its failure path: a limit below the image's share.
set(PMSM_F405_STACK_CFG ${PROJECT_SOURCE_DIR}/firmware/apps/f405/stack_check.json)
set(f405_stack_args --elf ${PMSM_F405_ELF} --config ${PMSM_F405_STACK_CFG}
    --su-dir ${CMAKE_BINARY_DIR}/firmware/apps/f405 --su-dir ${CMAKE_BINARY_DIR}/hal)
add_test(NAME ${PMSM_BOARD}_stack
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/stack_check.py ${f405_stack_args}
                 --verbose)
add_test(NAME ${PMSM_BOARD}_stack_limit_fails
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/stack_check.py ${f405_stack_args}
                 --limit 0.30)
set_tests_properties(${PMSM_BOARD}_stack_limit_fails PROPERTIES WILL_FAIL TRUE)
# The control interrupt and the medium-rate task without FPU instructions
# (pmsm_no_fpu): no lazy stacking of the FP context when they preempt.
add_test(NAME ${PMSM_BOARD}_isr_fpu_free
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_isr_fpu_free.py ${PMSM_F405_ELF}
                 ADC_IRQHandler PendSV_Handler)
add_test(NAME ${PMSM_BOARD}_image
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_f4_image.py ${PMSM_F405_ELF}
                 ${f405_console_irq} ${f405_nfault_irq} ${PMSM_CONTROLLERS_ALL})
# Its messages print their numbers: every conversion one its formatter has.
add_test(NAME ${PMSM_BOARD}_image_printf
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_printf.py ${PMSM_F405_ELF})
add_test(NAME ${PMSM_BOARD}_flash
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_flash.py ${PROJECT_SOURCE_DIR}
                 ${PMSM_F405_ELF} ${f405_flash_board})
# The stack's high-water mark after "config default" against the static
# worst case (tools/stack_check.py run beside QEMU).
add_test(NAME ${PMSM_BOARD}_qemu_boot
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/qemu_f405_boot.py ${PMSM_F405_ELF}
                 ${PMSM_BOARD} ${f405_qemu_serial} ${f405_console_irq}
                 ${PROJECT_SOURCE_DIR}/tools/stack_check.py ${f405_stack_args})
# The start-up on the fall-back clock (QEMU's path) within the watchdog's
# boot window: its instructions counted with the bench's QEMU plugin.
add_test(NAME ${PMSM_BOARD}_qemu_wdg
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/qemu_f405_wdg.py ${PROJECT_SOURCE_DIR}
                 ${PMSM_F405_ELF})
# The board's PIL image in QEMU, its console on a pseudo-terminal:
# ./tools/sim --target board:/dev/pts/N against it (the simulator from
# build/host-release, which tools/sim builds when missing).
set(PMSM_F405_PIL_ELF ${CMAKE_BINARY_DIR}/firmware/apps/f405_pil/pmsm-${PMSM_BOARD}-pil.elf)
add_test(NAME ${PMSM_BOARD}_qemu_pil
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/qemu_f405_pil.py ${PROJECT_SOURCE_DIR}
                 ${PMSM_F405_PIL_ELF} ${f405_qemu_serial})
set_tests_properties(${f405_tests} PROPERTIES LABELS "board")
set_tests_properties(${PMSM_BOARD}_qemu_boot PROPERTIES LABELS "board;qemu" TIMEOUT 150)
set_tests_properties(${PMSM_BOARD}_qemu_wdg PROPERTIES LABELS "board;qemu" TIMEOUT 120)
set_tests_properties(${PMSM_BOARD}_qemu_pil PROPERTIES LABELS "board;qemu;pil" TIMEOUT 300)
