# Command interpreter and telemetry of the firmware.
# Included from firmware/CMakeLists.txt and from tests/proto/CMakeLists.txt;
# builds for host, cm4 and cm0 (no host libraries).
if(NOT TARGET pmsm_fw_proto)
  add_library(pmsm_fw_proto STATIC
    ${CMAKE_CURRENT_LIST_DIR}/cmd.c
    ${CMAKE_CURRENT_LIST_DIR}/cmd_num.c
    ${CMAKE_CURRENT_LIST_DIR}/text_fmt.c
    ${CMAKE_CURRENT_LIST_DIR}/telemetry.c
    ${CMAKE_CURRENT_LIST_DIR}/telemetry_frame.c
    ${CMAKE_CURRENT_LIST_DIR}/pil_frame.c)
  # pil_frame.h carries hal.h's sample and compare types.
  target_include_directories(pmsm_fw_proto PUBLIC ${CMAKE_CURRENT_LIST_DIR}
                                                  ${PROJECT_SOURCE_DIR}/hal)
  target_link_libraries(pmsm_fw_proto PUBLIC pmsm_control)
  pmsm_strict(pmsm_fw_proto)
  # The interpreter runs in the main loop, never per period: optimised for
  # size on the targets (the board image's flash; -8.7 kB there). So does the
  # telemetry's encoding (fw_link_poll: the samples the interrupt queued).
  if(NOT PMSM_TARGET STREQUAL "host")
    set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/cmd.c ${CMAKE_CURRENT_LIST_DIR}/cmd_num.c
                                ${CMAKE_CURRENT_LIST_DIR}/text_fmt.c
                                ${CMAKE_CURRENT_LIST_DIR}/telemetry.c
                                ${CMAKE_CURRENT_LIST_DIR}/telemetry_frame.c
                                PROPERTIES COMPILE_OPTIONS "-Os")
  endif()
endif()
# libc functions replaced by smaller ones of the firmware's (libc_small.c:
# snprintf and vsnprintf by the formatter above, strcmp) for target images
# linked with newlib-nano (the B-G431B-ESC1 image): every message of the
# firmware and the core then prints its numbers. An OBJECT library: in the
# link whatever the archives' order.
if(NOT PMSM_TARGET STREQUAL "host" AND NOT TARGET pmsm_libc_small)
  add_library(pmsm_libc_small OBJECT ${CMAKE_CURRENT_LIST_DIR}/libc_small.c)
  set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/libc_small.c PROPERTIES COMPILE_OPTIONS
                              "-Os;-fno-tree-loop-distribute-patterns")
  target_link_libraries(pmsm_libc_small PUBLIC pmsm_fw_proto)
  pmsm_strict(pmsm_libc_small)
endif()
