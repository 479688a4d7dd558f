# Command interpreter and telemetry of the firmware.
# Included from firmware/CMakeLists.txt and from tests/proto/CMakeLists.txt;
# builds for host, cm4 and cm0 (no host libraries).
if(NOT TARGET pmsm_fw_proto)
  add_library(pmsm_fw_proto STATIC
    ${CMAKE_CURRENT_LIST_DIR}/cmd.c
    ${CMAKE_CURRENT_LIST_DIR}/cmd_num.c
    ${CMAKE_CURRENT_LIST_DIR}/telemetry.c
    ${CMAKE_CURRENT_LIST_DIR}/telemetry_frame.c)
  target_include_directories(pmsm_fw_proto PUBLIC ${CMAKE_CURRENT_LIST_DIR})
  target_link_libraries(pmsm_fw_proto PUBLIC pmsm_control)
  pmsm_strict(pmsm_fw_proto)
  # The interpreter runs in the main loop, never per period: optimised for
  # size on the targets (the board image's flash; -8.7 kB there).
  if(NOT PMSM_TARGET STREQUAL "host")
    set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/cmd.c ${CMAKE_CURRENT_LIST_DIR}/cmd_num.c
                                PROPERTIES COMPILE_OPTIONS "-Os")
  endif()
endif()
