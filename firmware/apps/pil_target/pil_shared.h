/*
 * What both sides of processor in the loop (pil_frame.h) share beyond the
 * frames: the pipeline settings SETUP carries, and the check that the host
 * and the target computed the same period (their telemetry records agree).
 */
#ifndef FIRMWARE_APPS_PIL_SHARED_H
#define FIRMWARE_APPS_PIL_SHARED_H

#include <stdint.h>

#include "pil_frame.h"
#include "pipeline.h"

/* The fw_config_t fields the simulator changes from fw_config_default
 * (sim_run_fw_config), into SETUP (PC) and back (target). */
void pil_setup_from_fw_config(pil_setup_t *s, const fw_config_t *fc);
void pil_setup_to_fw_config(const pil_setup_t *s, fw_config_t *fc);

/* CRC-16 of the telemetry record's fields in a fixed little-endian order,
 * all but `cycles` (the one field a target measures differently): equal
 * digests mean the host and the target computed the same period. */
uint16_t pil_tm_digest(const fw_telemetry_t *tm);

#endif /* FIRMWARE_APPS_PIL_SHARED_H */
