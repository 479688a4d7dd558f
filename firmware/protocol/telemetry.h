/*
 * Telemetry producer: which signals exist, how to scale them to SI, and the
 * decimated, framed stream of chosen signals (PROTOCOL.md, "Telemetry").
 *
 * Data flow: the control interrupt writes one record per period into a ring
 * and publishes one in `every` (pipeline.h, fw_tm_stream); the main loop
 * turns each into a tel_sample_t (fw_link) and a wire frame with
 * tel_encode_sample() and writes it to the UART whole (a frame and a text
 * response line are never interleaved byte-wise). If the link is too slow
 * whole samples are dropped; the PC sees the gap in seq. Nothing here runs
 * in the interrupt.
 */
#ifndef FIRMWARE_TELEMETRY_H
#define FIRMWARE_TELEMETRY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "telemetry_frame.h"

/* Signal indices = bit numbers in the mask. Append only (PC tools use the numbers). */
typedef enum {
    TEL_SIG_I_A = 0,     /* phase current a */
    TEL_SIG_I_B,         /* phase current b */
    TEL_SIG_I_D,         /* d-axis current (estimate at k) */
    TEL_SIG_I_Q,         /* q-axis current */
    TEL_SIG_PSI,         /* stator-flux amplitude |psi_s| (4.3) */
    TEL_SIG_PSI_REF,     /* flux reference in use */
    TEL_SIG_TORQUE,      /* estimated torque (3.6) */
    TEL_SIG_TORQUE_REF,  /* torque reference */
    TEL_SIG_SPEED,       /* electrical speed omega_e, shown as mechanical r/min */
    TEL_SIG_SPEED_REF,   /* speed reference */
    TEL_SIG_VECTOR,      /* selected voltage vector 0..7 (plan segment 0) */
    TEL_SIG_DUTY,        /* duty of the selected vector (plan segment 0 duration) */
    TEL_SIG_VDC,         /* DC-link voltage */
    TEL_SIG_THETA,       /* rotor electrical angle */
    TEL_SIG_SECTOR,      /* stator-flux sector 1..6 (4.5) */
    TEL_SIG_STATE,       /* firmware state code (fw_state_id_t) */
    TEL_SIG_FAULT,       /* latched fault code (FW_FAULT_*) */
    TEL_SIG_CYCLES,      /* ISR execution time, CPU cycles */
    TEL_SIG_CM_STEP,     /* commissioning step running (cm_step_id_t, 0 none) */
    TEL_SIG_CM_PROGRESS, /* its progress, per mille */
    TEL_SIG_TORQUE_MAX,  /* |torque| limit of the period (current, voltage, MTPV) */
    TEL_SIG_FW_LIMIT,    /* what bounds it (ctrl_fieldweak_limit_t) + 4 clipped + 8 flux weakened
                            + 16 torque not following its reference (torque_follow.h) */
#if CTRL_SL_HFI
    /* an image with the injection (CMake option PMSM_SL_HFI) */
    TEL_SIG_SL_STATE,  /* sensorless: mode, start phase, polarity's source (pipeline.h) */
    TEL_SIG_ANGLE_ERR, /* the injection's angle error estimate (rotor minus tracked) */
#endif
    TEL_SIG_COUNT
} tel_sig_t;

#define TEL_MASK_ALL ((uint32_t)((1ul << TEL_SIG_COUNT) - 1ul))

/*
 * One sample, filled by the pipeline. Units of the raw int32 values:
 *   i_a i_b i_d i_q      Q24 pu of the current base (ctrl_bases_t.i_a)
 *   psi psi_ref          Q24 pu of the flux base (Wb)
 *   torque torque_ref torque_max   Q24 pu of the torque base (N*m)
 *   speed speed_ref      Q24 pu of the speed base, electrical (w_rad_s)
 *   vdc                  Q24 pu of the voltage base (V)
 *   duty                 Q24 fraction of the period (FX_ONE = 100 %)
 *   theta                theta_e >> 8: Q24 fraction of a turn, [0, 2^24)
 *   vector sector state fault cycles cm_step cm_progress fieldweak_limit sl_state
 *                        plain integers
 *   angle_err            (fw_telemetry_t.hfi_err) / 2^8: Q24 fraction of a turn, signed
 */
typedef struct {
    uint32_t tick; /* control period index k (wraps), sent in every frame */
    int32_t i_a, i_b, i_d, i_q;
    int32_t psi, psi_ref;
    int32_t torque, torque_ref;
    int32_t speed, speed_ref;
    int32_t vector, duty, vdc, theta, sector;
    int32_t state, fault, cycles;
    int32_t cm_step, cm_progress;
    int32_t torque_max, fieldweak_limit;
#if CTRL_SL_HFI
    int32_t sl_state, angle_err;
#endif
} tel_sample_t;

/* How a raw value turns into SI. */
typedef enum {
    TEL_KIND_CURRENT = 0, /* * i_base / 2^24 -> A */
    TEL_KIND_VOLTAGE,     /* * v_base / 2^24 -> V */
    TEL_KIND_FLUX,        /* * psi_base / 2^24 -> Wb */
    TEL_KIND_TORQUE,      /* * torque_base / 2^24 -> N*m */
    TEL_KIND_SPEED,       /* * w_base / p * 60 / (2 pi) / 2^24 -> r/min (mechanical) */
    TEL_KIND_ANGLE,       /* * 2 pi / 2^24 -> rad */
    TEL_KIND_FRACTION,    /* / 2^24 -> 1 */
    TEL_KIND_INTEGER      /* * 1 */
} tel_kind_t;

typedef struct {
    const char *name; /* lower case, used by "tel start" */
    const char *unit; /* SI unit after scaling ("" for integers) */
    const char *help;
    uint8_t kind;    /* tel_kind_t */
    uint16_t offset; /* offsetof(tel_sample_t, field) */
} tel_signal_t;

/* The signal table (const, in flash). NULL past the end. */
const tel_signal_t *tel_signal_at(size_t index);
/* Index of a signal by name (s[0..len)), or -1. */
int tel_signal_find(const char *s, size_t len);
/* SI scale of a signal for these bases (configuration, not per sample). */
double tel_signal_scale(size_t index, const ctrl_bases_t *bases, int32_t pole_pairs);

/* Producer state. */
typedef struct {
    uint32_t mask;  /* signals being sent, 0 = stopped */
    uint32_t every; /* decimation: one sample in `every` periods (the producer's) */
    uint16_t seq;   /* sequence number of the next frame */
} tel_t;

#define TEL_EVERY_MAX 100000u

void tel_init(tel_t *t);
/* Returns 0, or -1 for mask 0 / unknown bits / every outside 1..TEL_EVERY_MAX
 * (then nothing changes). Restarting keeps seq running. */
int tel_start(tel_t *t, uint32_t mask, uint32_t every);
void tel_stop(tel_t *t);
bool tel_active(const tel_t *t);
/* Wire bytes of a sample frame for this mask (for link-budget checks):
 * bytes/s = tel_wire_size(mask) * fs / every. */
size_t tel_wire_size(uint32_t mask);

/* Build the wire frame (0x00, COBS, 0x00) of a sample with the active mask.
 * Returns its length, or 0 when stopped or cap < TEL_WIRE_MAX. */
size_t tel_encode_sample(tel_t *t, const tel_sample_t *s, uint8_t *wire, size_t cap);
/* The META frame (sent once after "tel start" ok): fs, decimation and the SI
 * scale of each active signal. Returns its length or 0. */
size_t tel_encode_meta(tel_t *t, uint32_t fs_hz, const ctrl_bases_t *bases, int32_t pole_pairs,
                       uint8_t *wire, size_t cap);

#endif /* FIRMWARE_TELEMETRY_H */
