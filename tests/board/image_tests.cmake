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
