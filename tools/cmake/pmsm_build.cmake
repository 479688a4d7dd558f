# Build-wide settings. PMSM_TARGET: host | cm4 | cm0 (set by the presets).
set(PMSM_TARGET "host" CACHE STRING "host, cm4 or cm0")
option(PMSM_SANITIZE "Build host code with ASan and UBSan" OFF)

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
