# Image checks of a stm32g4 build (included from the top-level CMakeLists.txt;
# ctest --preset b-g431b-esc1): the ELF's vector table and files, tools/flash.
set(PMSM_ESC1_ELF ${CMAKE_BINARY_DIR}/firmware/apps/esc1/pmsm-esc1.elf)
add_test(NAME esc1_image_vectors
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_image.py ${PMSM_ESC1_ELF})
set_tests_properties(esc1_image_vectors PROPERTIES LABELS "board")
add_test(NAME esc1_flash
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_flash.py ${PROJECT_SOURCE_DIR}
                 ${PMSM_ESC1_ELF})
set_tests_properties(esc1_flash PROPERTIES LABELS "board")
# Its messages print their numbers: no float conversion newlib-nano would drop.
add_test(NAME esc1_image_printf
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_printf.py ${PMSM_ESC1_ELF})
set_tests_properties(esc1_image_printf PROPERTIES LABELS "board")
# The static stack check (tools/stack_check.py): every entry point's worst
# depth from the image's call graph and its -fstack-usage frames, the
# priority levels nested, within 75 % of the reserved stack; the control
# interrupt's code free of FPU instructions.
set(PMSM_ESC1_STACK_CFG ${PROJECT_SOURCE_DIR}/firmware/apps/esc1/stack_check.json)
add_test(NAME esc1_stack
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/stack_check.py --elf ${PMSM_ESC1_ELF}
                 --config ${PMSM_ESC1_STACK_CFG} --su-dir ${CMAKE_BINARY_DIR}/firmware/apps/esc1
                 --su-dir ${CMAKE_BINARY_DIR}/hal --verbose)
set_tests_properties(esc1_stack PROPERTIES LABELS "board")
# The same check fails when the worst case passes the limit: here a limit
# below the image's share (the check's own failure path, which CI relies on).
add_test(NAME esc1_stack_limit_fails
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/stack_check.py --elf ${PMSM_ESC1_ELF}
                 --config ${PMSM_ESC1_STACK_CFG} --su-dir ${CMAKE_BINARY_DIR}/firmware/apps/esc1
                 --su-dir ${CMAKE_BINARY_DIR}/hal --limit 0.30)
set_tests_properties(esc1_stack_limit_fails PROPERTIES LABELS "board" WILL_FAIL TRUE)
# The signal fences of the state shared between the contexts
# (docs/architecture.md), checked in the source, and the check's own failure
# path: each rule fails with its fences removed.
add_test(NAME fence_check COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/fence_check.py
                                  ${PROJECT_SOURCE_DIR})
add_test(NAME fence_check_self_test
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/fence_check.py --self-test
                 ${PROJECT_SOURCE_DIR})
set_tests_properties(fence_check fence_check_self_test PROPERTIES LABELS "board")
# The image's sources without the settings store still compile
# (firmware/apps/esc1/CMakeLists.txt, pmsm_esc1_no_settings).
if(TARGET pmsm_esc1_no_settings)
  add_test(NAME esc1_no_settings_compiles
           COMMAND ${CMAKE_COMMAND} --build ${CMAKE_BINARY_DIR} --target pmsm_esc1_no_settings)
  set_tests_properties(esc1_no_settings_compiles PROPERTIES LABELS "board")
endif()
