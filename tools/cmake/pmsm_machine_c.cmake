# A board image's default motor, generated from a machine file at build time
# (tools/board/machine_c.py): the motor data have one home, the .ini the
# simulator reads.
set(PMSM_ESC1_MACHINE_INI "${PROJECT_SOURCE_DIR}/sim_host/machines/gbm5208_gimbal.ini"
    CACHE FILEPATH "machine file compiled into the B-G431B-ESC1 image as its default motor")
set(PMSM_F405_MACHINE_INI "${PROJECT_SOURCE_DIR}/sim_host/machines/mj5208_drone.ini"
    CACHE FILEPATH "machine file compiled into the STM32F405 board images as their default motor")

# pmsm_machine_c(<out.c> <machine.ini> <symbol>): a rule that writes
# "const ctrl_machine_t <symbol> = {...};" to <out.c>.
function(pmsm_machine_c out ini symbol)
  add_custom_command(OUTPUT ${out}
    COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tools/board/machine_c.py
            --ini ${ini} --symbol ${symbol} --out ${out}
    DEPENDS ${ini} ${PROJECT_SOURCE_DIR}/tools/board/machine_c.py
    COMMENT "machine_c: ${symbol} from ${ini}"
    VERBATIM)
endfunction()
