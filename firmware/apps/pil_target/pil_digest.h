/*
 * The check of processor in the loop (pil_frame.h): the host and the target
 * run the same period, and their telemetry records must agree.
 */
#ifndef FIRMWARE_APPS_PIL_DIGEST_H
#define FIRMWARE_APPS_PIL_DIGEST_H

#include <stdint.h>

#include "pipeline.h"

/* CRC-16 of the telemetry record's fields in a fixed little-endian order,
 * all but `cycles` (the one field a target measures differently): equal
 * digests mean the host and the target computed the same period. */
uint16_t pil_tm_digest(const fw_telemetry_t *tm);

#endif /* FIRMWARE_APPS_PIL_DIGEST_H */
