# pmsm_add_unit_test(NAME n SOURCES a.c ... [LIBS l ...] [LABELS x ...])
#   A Unity-API C test. Built for the host (and, from the cm4 build, for QEMU).
# pmsm_add_reference_test(NAME n SOURCES a.cpp ... [LIBS l ...])
#   A C++ test with an Eigen double-precision reference; label "reference".
set(PMSM_UNITY_DIR ${CMAKE_CURRENT_LIST_DIR}/../../tests/unity)

function(pmsm_add_unit_test)
  cmake_parse_arguments(T "" "NAME" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE pmsm_unity ${T_LIBS})
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  set_tests_properties(${T_NAME} PROPERTIES LABELS "unit;${T_LABELS}")
endfunction()

function(pmsm_add_reference_test)
  cmake_parse_arguments(T "" "NAME" "SOURCES;LIBS;LABELS" ${ARGN})
  find_package(Eigen3 3.3 REQUIRED NO_MODULE)
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE pmsm_unity Eigen3::Eigen ${T_LIBS})
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  set_tests_properties(${T_NAME} PROPERTIES LABELS "reference;${T_LABELS}")
endfunction()
