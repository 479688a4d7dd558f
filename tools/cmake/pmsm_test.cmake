# pmsm_add_unit_test(NAME n SOURCES a.c ... [LIBS l ...] [LABELS x ...])
#   A Unity-API C test. Built for the host (label "unit"); from the cm4 build it is
#   built as a QEMU mps2-an386 ELF (startup + harness, output on UART0, exit status
#   through semihosting) and run with tools/qemu-run (labels "unit;qemu").
#   In the cm4 build a test is skipped at configure time (with a status message) when
#   one of its LIBS is not a target of that build (host-only libraries) or when it
#   has C++ sources.
# pmsm_add_reference_test(NAME n SOURCES a.cpp ... [LIBS l ...])
#   A C++ test with an Eigen double-precision reference; label "reference".
#   Host only: a no-op in the cm4 build.
# pmsm_add_expect_fail_test(NAME n TARGET t PATTERNS regex ...)
#   Runs the already defined test executable t, which must exit non-zero with output
#   matching every regex (used to test that failures are reported).
# pmsm_add_fuzz_test(NAME n SECONDS s [LABELS l ...])
#   The short run of the calling folder's libFuzzer targets: test n runs
#   fuzz/run_fuzz.sh OUTDIR CLANG s (labels "fuzz" and l, 180 s time-out), added
#   only when clang (clang-14 or clang) links a libFuzzer target; probed once per
#   configure.
# pmsm_test_alone(test ...)
#   RUN_SERIAL for tests that talk to an image running in QEMU (a console session):
#   QEMU runs unpaced (-icount sleep=off), so the emulated time between two commands
#   the PC sends is the host's spare CPU, and a test beside them starves it (a speed
#   not yet settled, a calibration not yet begun when the next command comes).
set(PMSM_UNITY_DIR ${CMAKE_CURRENT_LIST_DIR}/../../tests/unity)
set(PMSM_QEMU_RUN ${CMAKE_CURRENT_LIST_DIR}/../qemu-run)
set(PMSM_QEMU_TEST_TIMEOUT 120 CACHE STRING "Wall-time limit (s) of one QEMU test run")
# Libraries that are not CMake targets but exist on every target.
set(PMSM_TARGET_SYSTEM_LIBS m c)

# The command line that runs test executable `target` on the current target.
function(pmsm_test_command target out_var)
  if(PMSM_TARGET STREQUAL "cm4")
    set(${out_var} ${PMSM_QEMU_RUN} --timeout ${PMSM_QEMU_TEST_TIMEOUT}
        $<TARGET_FILE:${target}> PARENT_SCOPE)
  else()
    set(${out_var} $<TARGET_FILE:${target}> PARENT_SCOPE)
  endif()
endfunction()

function(pmsm_add_unit_test)
  cmake_parse_arguments(T "" "NAME" "SOURCES;LIBS;LABELS" ${ARGN})
  if(PMSM_TARGET STREQUAL "cm0")
    return()
  endif()
  set(labels unit ${T_LABELS})
  if(PMSM_TARGET STREQUAL "cm4")
    foreach(lib IN LISTS T_LIBS)
      if(NOT TARGET ${lib} AND NOT lib IN_LIST PMSM_TARGET_SYSTEM_LIBS)
        message(STATUS "cm4: test ${T_NAME} skipped (library ${lib} is not in the target build)")
        return()
      endif()
    endforeach()
    foreach(src IN LISTS T_SOURCES)
      if(src MATCHES "\\.(cpp|cc|cxx)$")
        message(STATUS "cm4: test ${T_NAME} skipped (C++ source ${src})")
        return()
      endif()
    endforeach()
    list(APPEND labels qemu)
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE pmsm_unity ${T_LIBS})
  if(PMSM_TARGET STREQUAL "cm4")
    pmsm_qemu_firmware(${T_NAME})
  endif()
  pmsm_test_command(${T_NAME} cmd)
  add_test(NAME ${T_NAME} COMMAND ${cmd})
  set_tests_properties(${T_NAME} PROPERTIES LABELS "${labels}")
endfunction()

function(pmsm_add_reference_test)
  cmake_parse_arguments(T "" "NAME" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT PMSM_TARGET STREQUAL "host")
    return()
  endif()
  find_package(Eigen3 3.3 REQUIRED NO_MODULE)
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE pmsm_unity Eigen3::Eigen ${T_LIBS})
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  set_tests_properties(${T_NAME} PROPERTIES LABELS "reference;${T_LABELS}")
endfunction()

function(pmsm_add_expect_fail_test)
  cmake_parse_arguments(T "" "NAME;TARGET" "PATTERNS;LABELS" ${ARGN})
  if(NOT TARGET ${T_TARGET})
    return()
  endif()
  pmsm_test_command(${T_TARGET} cmd)
  add_test(NAME ${T_NAME}
           COMMAND ${CMAKE_COMMAND} "-DCMD=${cmd}" "-DPATTERNS=${T_PATTERNS}"
                   -P ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/pmsm_expect_fail.cmake)
  set(labels unit ${T_LABELS})
  if(PMSM_TARGET STREQUAL "cm4")
    list(APPEND labels qemu)
  endif()
  set_tests_properties(${T_NAME} PROPERTIES LABELS "${labels}")
endfunction()

function(pmsm_test_alone)
  set_tests_properties(${ARGN} PROPERTIES RUN_SERIAL TRUE)
endfunction()

function(pmsm_add_fuzz_test)
  cmake_parse_arguments(F "" "NAME;SECONDS" "LABELS" ${ARGN})
  find_program(PMSM_CLANG NAMES clang-14 clang)
  if(NOT PMSM_CLANG)
    return()
  endif()
  get_property(probed GLOBAL PROPERTY PMSM_LIBFUZZER_RC SET)
  if(NOT probed)
    execute_process(
      COMMAND sh -c "printf 'int LLVMFuzzerTestOneInput(const unsigned char*d,unsigned long n){(void)d;(void)n;return 0;}' | ${PMSM_CLANG} -fsanitize=fuzzer -x c - -o /dev/null"
      RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
    set_property(GLOBAL PROPERTY PMSM_LIBFUZZER_RC ${rc})
  endif()
  get_property(rc GLOBAL PROPERTY PMSM_LIBFUZZER_RC)
  if(NOT rc EQUAL 0)
    return()
  endif()
  add_test(NAME ${F_NAME}
           COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/run_fuzz.sh
                   ${CMAKE_CURRENT_BINARY_DIR}/fuzz ${PMSM_CLANG} ${F_SECONDS})
  set(labels fuzz ${F_LABELS})
  set_tests_properties(${F_NAME} PROPERTIES LABELS "${labels}" TIMEOUT 180)
endfunction()
