/*
 * The firmware's own configuration on the link (PROTOCOL.md "Parameters"):
 * machine, encoder, estimation, inverter, speed loop, limits and protections,
 * named by the settings record's keys (settings.h: one name for each value),
 * each with its unit, range and help, listed by "param list" after the
 * controller's tunables and before the application's own parameters.
 *
 * Read from the running firmware (fw_settings_capture). Written:
 *  - live, in any state: the speed loop's bandwidth, phase margin and gains
 *    (listed " live"; fw_speed_retune: the PI's integrator carried over
 *    bumplessly);
 *  - the others with the gates off (refused while running or commissioning,
 *    or with an arm pending: err 8 naming the parameter): the configuration
 *    as a record with the one value changed, applied through the
 *    application's fw_settings_t.apply, the same reconfiguration as at
 *    start-up from a record (controller and tunables kept, the drive
 *    calibrates again). When the core or the board refuses it, the
 *    configuration before it is applied again and the refusal's reason is the
 *    answer's detail (err 10 failed <reason>).
 *
 * Two tables: fw_params_machine (the machine data m.* and the encoder's
 * resolution enc.cpr) and fw_params_drive (the rest). An application whose
 * board lists machine data with its own limits (the B-G431B-ESC1: its
 * ratings, esc1_params.c) attaches only the second; an unattached table is
 * not linked. Main loop only.
 */
#ifndef FIRMWARE_FW_PARAMS_H
#define FIRMWARE_FW_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#include "fw_link.h"
#include "help_text.h"

/* One parameter: its key in the settings record, unit (index into the
 * units of fw_params.c), range, and how it is written. */
typedef struct {
    double min, max; /* accepted range (an integer field: whole numbers within it) */
    const char *key;
#if PMSM_HELP_TEXT
    const char *help;
#endif
    uint8_t unit;
    uint8_t flags; /* FW_PARAM_* */
} fw_param_t;

#define FW_PARAM_LIVE 1u /* the speed loop's: fw_speed_retune, in any state */
#define FW_PARAM_TURN 2u /* an angle kept in 2^-32 turn, shown in degrees */

struct fw_params_table {
    const fw_param_t *p;
    size_t n;
};

extern const fw_params_table_t fw_params_machine;
extern const fw_params_table_t fw_params_drive;

/* Attaches a table to the link (after fw_link_set_settings: its writes go
 * through that store's apply); listed in the order attached, at most
 * FW_LINK_TABLES. */
void fw_params_attach(fw_link_t *l, const fw_params_table_t *t);

#endif /* FIRMWARE_FW_PARAMS_H */
