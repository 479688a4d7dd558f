/*
 * Processor-in-the-loop link: the frames between the PC, which runs the plant
 * (the simulator's engine), and a target that runs the firmware (QEMU or a
 * board). One exchange per PWM period: the PC sends what the sensors read at
 * the period start (ADC codes, encoder counter, trip comparator) and the
 * commands given since the last period; the target runs fw_isr on them and
 * answers with what it applied (compare values, gate request) and a digest
 * of its telemetry record. hal/pil/hal_pil.h is the target's hal.h back-end,
 * firmware/apps/pil_target the target's side, host_sim/sim_pil.h the PC's.
 *
 * Wire format: the telemetry frames' (telemetry_frame.h, PROTOCOL.md):
 *   0x00, COBS(body), 0x00
 *   body = type u8, seq u16 (little-endian), payload, CRC-16/CCITT-FALSE of
 *          everything before it (high byte first, tel_crc16)
 * Every multi-byte field is little-endian; doubles are IEEE-754 binary64.
 * Types:
 *   SETUP  PC -> target, seq 0: controller, machine, tunables, firmware and
 *          HAL configuration (pil_setup_t)
 *   READY  target -> PC, seq 0: fw_init's result (pil_ready_t)
 *   SAMPLE PC -> target, seq 1, 2, ... (wraps): one period's inputs
 *   APPLY  target -> PC, the SAMPLE's seq: that period's outputs
 *   STOP   PC -> target: end of the run (the target stops answering)
 *   FAULT  target -> PC: the link fault the target latched (pil_err_t in
 *          the payload's first byte, the seq it expected next after it)
 * A frame that fails its CRC or its format, a seq other than the one
 * expected, and a frame that does not arrive within the time-out are link
 * faults (pil_err_t), named, with the gates off: never skipped.
 */
#ifndef FIRMWARE_PIL_FRAME_H
#define FIRMWARE_PIL_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "hal.h"

#define PIL_T_SETUP 0x21u
#define PIL_T_READY 0x22u
#define PIL_T_SAMPLE 0x23u
#define PIL_T_APPLY 0x24u
#define PIL_T_STOP 0x25u
#define PIL_T_FAULT 0x26u

#define PIL_BODY_MAX 1024u /* type + seq + payload + CRC */
#define PIL_WIRE_MAX (PIL_BODY_MAX + PIL_BODY_MAX / 254u + 3u)

/* Link faults (pil_err_name). */
typedef enum {
    PIL_OK = 0,
    PIL_E_TIMEOUT = 1,  /* a frame did not arrive in time (lost or late) */
    PIL_E_CRC = 2,      /* a frame failed its CRC (corrupted) */
    PIL_E_SEQ = 3,      /* a frame out of sequence (one lost, repeated or reordered) */
    PIL_E_FORMAT = 4,   /* bad COBS, unknown type, wrong length, overlong frame */
    PIL_E_CLOSED = 5,   /* the other side closed the link or exited */
    PIL_E_DIVERGED = 6, /* the target's outputs differ from the host firmware's */
    PIL_E_SETUP = 7,    /* the target refused the configuration */
    PIL_E_COUNT
} pil_err_t;

const char *pil_err_name(int err);

/* SAMPLE command bits: what the main loop did since the last period. */
#define PIL_CMD_ARM 0x01u
#define PIL_CMD_DISARM 0x02u
#define PIL_CMD_CLEAR 0x04u
#define PIL_CMD_TORQUE 0x08u /* fw_set_torque_ref(torque_ref) */
#define PIL_CMD_SPEED 0x10u  /* fw_set_speed_ref(speed_ref) */
#define PIL_CMD_KICK 0x20u   /* fw_watchdog_kick after this period's fw_isr */

typedef struct {
    hal_adc_raw_t adc;
    hal_encoder_raw_t enc;
    bool trip;          /* hardware trip comparator latched */
    uint8_t cmd;        /* PIL_CMD_* */
    int32_t torque_ref; /* Q24 pu, with PIL_CMD_TORQUE */
    int32_t speed_ref;  /* Q24 pu electrical, with PIL_CMD_SPEED */
} pil_sample_t;

/* APPLY flags. */
#define PIL_OUT_PWM 0x01u        /* hal_pwm_write was called in this period */
#define PIL_OUT_GATES 0x02u      /* gates requested on at the end of fw_isr */
#define PIL_OUT_TRIP_CLEAR 0x04u /* hal_trip_clear was called */

typedef struct {
    hal_pwm_t pwm;      /* the last compare values written in this period */
    uint8_t flags;      /* PIL_OUT_* */
    uint8_t state;      /* fw_state_id_t after fw_isr */
    uint8_t fault;      /* latched fault code */
    uint32_t cycles;    /* fw_isr's duration in the target's hal_cycles */
    uint16_t tm_digest; /* pil_tm_digest of the period's telemetry record */
} pil_apply_t;

#define PIL_NAME_MAX 32u /* controller and tunable names, with the NUL */
#define PIL_SETS_MAX 16u
#define PIL_WHY_MAX 200u

/* Everything fw_init needs that the host does not share with the target by
 * construction: the controller by name, the machine it is configured for,
 * the tunables set by name, the pipeline configuration the simulator changes
 * from fw_config_default, and the hal_info of the simulated hardware (the
 * target's own cycle clock replaces cycle_clock_hz). */
typedef struct {
    char ctrl[PIL_NAME_MAX];
    ctrl_machine_t machine; /* name not sent (the target calls it "pil") */
    uint8_t n_sets;
    struct {
        char name[PIL_NAME_MAX];
        double value;
    } sets[PIL_SETS_MAX];
    uint32_t calib_samples;
    double speed_bw_hz, speed_pm_deg, speed_kp, speed_ki;
    uint8_t speed_unit; /* ctrl_speed_unit_t */
    double overspeed_rpm;
    bool psi_adapt, sensorless;
    bool hfi; /* fw_config_t.hfi; its settings among the sets ("hfi.<field>") */
    double dead_time_s, v_fwd_v;
    uint32_t enc_offset; /* fx_angle_t */
    int8_t enc_direction;
    uint32_t enc_cpr;
    hal_info_t info;
} pil_setup_t;

typedef struct {
    int32_t rc;              /* fw_init's (FW_OK = 0), or -100 - field for a bad setup */
    uint32_t cycle_clock_hz; /* the target's hal_cycles rate (0 = unknown) */
    char why[PIL_WHY_MAX];   /* fw_explain on a refusal, else empty */
} pil_ready_t;

/* A decoded frame: the type, the seq and the payload (bytes). */
typedef struct {
    uint8_t type;
    uint16_t seq;
    uint16_t len;
    uint8_t payload[PIL_BODY_MAX];
} pil_frame_t;

/* Payload <-> struct. pack: the payload length, 0 if cap is too small.
 * unpack: 0, or PIL_E_FORMAT for a wrong length or an out-of-range field. */
size_t pil_sample_pack(const pil_sample_t *s, uint8_t *out, size_t cap);
int pil_sample_unpack(const uint8_t *p, size_t n, pil_sample_t *s);
size_t pil_apply_pack(const pil_apply_t *a, uint8_t *out, size_t cap);
int pil_apply_unpack(const uint8_t *p, size_t n, pil_apply_t *a);
size_t pil_setup_pack(const pil_setup_t *s, uint8_t *out, size_t cap);
int pil_setup_unpack(const uint8_t *p, size_t n, pil_setup_t *s);
size_t pil_ready_pack(const pil_ready_t *r, uint8_t *out, size_t cap);
int pil_ready_unpack(const uint8_t *p, size_t n, pil_ready_t *r);

/* body (type, seq, payload, CRC) -> COBS -> delimiters. Returns the wire
 * length, or 0 when the payload is too long or cap too small. */
size_t pil_frame_encode(uint8_t type, uint16_t seq, const uint8_t *payload, size_t len,
                        uint8_t *wire, size_t cap);

/* Streaming decoder: bytes between two 0x00 delimiters are one frame. */
typedef struct {
    uint8_t buf[PIL_WIRE_MAX];
    size_t len;
    bool overflow;
} pil_dec_t;

void pil_dec_init(pil_dec_t *d);
/* Feed one byte: PIL_OK with *got = true when it completed a valid frame
 * (written to *out); PIL_E_CRC or PIL_E_FORMAT when it completed a bad one;
 * PIL_OK with *got = false otherwise. */
int pil_dec_feed(pil_dec_t *d, uint8_t byte, pil_frame_t *out, bool *got);
/* A frame is partly received (a time-out then loses it). */
bool pil_dec_busy(const pil_dec_t *d);

/* The next seq after s in the SAMPLE sequence (1 .. 65535, then 1). */
uint16_t pil_seq_next(uint16_t s);

#endif /* FIRMWARE_PIL_FRAME_H */
