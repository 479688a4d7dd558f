/*
 * The main stack's high-water mark (board images): the start-up code paints
 * the stack's free part with a pattern, and the deepest word no longer
 * holding it marks how much has been used since (status, the start-up
 * report). A measurement of what ran, not a bound: the bound is the static
 * check of the image (tools/stack_check.py).
 */
#ifndef FIRMWARE_LINK_FW_STACK_H
#define FIRMWARE_LINK_FW_STACK_H

#include <stdint.h>

/* Distinct bytes, so that no byte-wise fill (memset) writes it by chance. */
#define FW_STACK_PAINT 0xC5A3E17Du

/* Paint the words [lo, end). Called from the start-up code with end a few
 * words below its own stack pointer: a leaf without a frame of its own. */
void fw_stack_paint(uint32_t *lo, uint32_t *end);

/* Bytes of [lo, hi) used since the painting: from hi down to the lowest word
 * that no longer holds FW_STACK_PAINT (the stack grows down from hi). */
uint32_t fw_stack_used(const uint32_t *lo, const uint32_t *hi);

#endif /* FIRMWARE_LINK_FW_STACK_H */
