/*
 * Telemetry frame codec (PROTOCOL.md, "Telemetry frames"): payload layout,
 * CRC-16/CCITT-FALSE, COBS, and a streaming decoder that resynchronises on
 * the 0x00 delimiter. Used by the firmware (encoder) and by the tests, the
 * fuzz targets and host tools (decoder). No heap, no globals.
 *
 * Payload (little-endian unless stated):
 *   off 0  u8   type        TEL_TYPE_SAMPLE or TEL_TYPE_META
 *   off 1  u16  seq         frame counter, +1 per frame sent (wraps)
 *   off 3  u32  mask        signal mask, bit i = signal i of telemetry.h
 *   SAMPLE: off 7 u32 tick (control period index), then one i32 per set bit
 *           of mask, ascending bit order
 *   META:   off 7 u32 fs_hz, off 11 u32 every (decimation), then one
 *           IEEE-754 binary32 per set bit: SI value = raw * scale
 *   last 2 bytes: CRC-16/CCITT-FALSE of everything before it, HIGH byte
 *           first (so the CRC over the whole payload is 0x0000)
 * Wire: 0x00, COBS(payload), 0x00. Every frame is preceded and followed by a
 * delimiter, so a corrupted delimiter costs at most the damaged frame.
 */
#ifndef FIRMWARE_TELEMETRY_FRAME_H
#define FIRMWARE_TELEMETRY_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define TEL_TYPE_SAMPLE 0x01u
#define TEL_TYPE_META 0x02u

#define TEL_HDR_SIZE 7u /* type, seq, mask */
#define TEL_CRC_SIZE 2u
#define TEL_VALUES_MAX 32u /* one per mask bit */
/* Largest payload: header + 8 bytes (tick or fs/every) + values + CRC. */
#define TEL_PAYLOAD_MAX (TEL_HDR_SIZE + 8u + 4u * TEL_VALUES_MAX + TEL_CRC_SIZE)
/* COBS adds one byte per started block of 254 bytes. */
#define TEL_COBS_SIZE(n) ((n) + (n) / 254u + 1u)
/* Largest frame on the wire: two delimiters + encoded payload. */
#define TEL_WIRE_MAX (TEL_COBS_SIZE(TEL_PAYLOAD_MAX) + 2u)

/* CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, no reflection, xorout 0;
 * check value of "123456789" is 0x29B1. */
#define TEL_CRC_INIT 0xFFFFu
uint16_t tel_crc16_update(uint16_t crc, const uint8_t *data, size_t n);
uint16_t tel_crc16(const uint8_t *data, size_t n);

/*
 * COBS (Cheshire & Baker 1999). encode: returns the encoded length (always
 * n + 1 + n/254 at most, no 0x00 in the output), or 0 if cap is too small.
 * decode: input without delimiter; returns 0 and sets *out_len, or -1 on a
 * malformed block (a 0x00 byte, a code running past the end) or overflow.
 */
size_t tel_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap);
int tel_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *out_len);

/* A decoded frame. */
typedef struct {
    uint8_t type;
    uint16_t seq;
    uint32_t mask;
    uint32_t tick;                 /* SAMPLE */
    uint32_t fs_hz;                /* META */
    uint32_t every;                /* META */
    uint8_t n;                     /* number of set bits in mask (values present) */
    int32_t value[TEL_VALUES_MAX]; /* SAMPLE: raw value per set bit */
    float scale[TEL_VALUES_MAX];   /* META: SI scale per set bit */
} tel_frame_t;

/* Payload size of a frame of this type and mask (with CRC). */
size_t tel_payload_size(uint8_t type, uint32_t mask);

/* Serialise f (type, seq, mask and the fields of its type) with its CRC.
 * Returns the payload length, or 0 for a bad type or too small cap. */
size_t tel_frame_serialise(const tel_frame_t *f, uint8_t *out, size_t cap);

/* Parse a payload: CRC, type and exact length must match. Returns 0 or -1. */
int tel_frame_parse(const uint8_t *p, size_t n, tel_frame_t *f);

/* Serialise + COBS + delimiters. Returns wire bytes, or 0 on error. */
size_t tel_frame_encode(const tel_frame_t *f, uint8_t *wire, size_t cap);

/* Streaming decoder for the UART byte stream (frames and text lines mixed). */
typedef struct {
    uint8_t buf[TEL_WIRE_MAX]; /* bytes since the last delimiter */
    size_t len;
    bool overflow;   /* the current chunk is longer than any frame */
    bool all_text;   /* every byte of the chunk is printable or CR/LF */
    uint32_t frames; /* valid frames reported */
    uint32_t bad;    /* chunks dropped: COBS, CRC, length or overlong */
    uint32_t text;   /* text lines / text chunks skipped */
} tel_dec_t;

void tel_dec_init(tel_dec_t *d);

/*
 * Feed one byte. Returns true when it completed a valid frame, written to
 * *out (only then). A chunk between delimiters that is not a valid frame is
 * counted in d->bad (or d->text if it is printable text) and dropped; a text
 * line (printable bytes ending with LF, at least 2 bytes) is skipped at its LF.
 */
bool tel_dec_feed(tel_dec_t *d, uint8_t byte, tel_frame_t *out);

#endif /* FIRMWARE_TELEMETRY_FRAME_H */
