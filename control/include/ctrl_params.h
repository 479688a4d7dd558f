/*
 * Machine parameters: SI data-sheet values in, fixed-point per-unit out.
 *
 * Per-unit bases (docs/fixed-point.md): from the machine, so that the
 * formats hold from sub-milliweber drone motors to the 80 kW IPMSM:
 *   psi_base = psi_pm                        [Wb]
 *   w_base   = rated electrical speed        [rad/s]  -> rated speed = 1 pu
 *   t_base   = 1 / w_base                    [s]
 *   v_base   = psi_base w_base               [V]      -> d(psi)/dt = v in pu
 *   l_base   = Ld, i_base = psi_base / l_base [A]
 *   r_base   = v_base / i_base = w_base l_base [ohm]
 *   T_base   = 1.5 p psi_base i_base         [N*m]    -> Te = psi x i in pu (3.6)
 * so Ts in pu is the angle one period turns at rated speed, and the DC link
 * in pu its ratio to the rated back-EMF (not 1). Per-period code uses the
 * fields of ctrl_params_t and assumes no base value. The SI value of 1 pu of
 * each quantity is kept in ctrl_bases_t (configuration only).
 *
 * ctrl_params_init() lives in ctrl_params_config.c: the only place (with the
 * other *_config.c files) where floating point is allowed in control/.
 */
#ifndef CONTROL_CTRL_PARAMS_H
#define CONTROL_CTRL_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#include "fx.h"

/* What a user fills in from a data sheet, SI units. */
typedef struct {
    const char *name;
    int pole_pairs;         /* p */
    double rs_ohm;          /* stator resistance per phase */
    double ld_h, lq_h;      /* d and q inductances */
    double psi_pm_wb;       /* permanent-magnet flux linkage (peak, per phase) */
    double vdc_v;           /* nominal DC-link voltage */
    double inertia_kgm2;    /* J, for the speed loop */
    double torque_rated_nm; /* rated torque */
    double speed_rated_rpm; /* rated mechanical speed */
    double current_rated_a; /* rated current (peak of the phase current) */
    double current_max_a;   /* over-current trip level (peak), > rated */
    double psi_ref_wb;      /* stator-flux reference; 0 = MTPA (4.15) */
    double speed_max_rpm;   /* maximum mechanical speed (>= rated); 0 = the firmware's
                               default, fw_speed_max_rpm (firmware/isr/protect.h); last
                               so that positional initialisers need not name it */
} ctrl_machine_t;

/* SI value of 1 pu of each quantity (configuration and host tools only). */
typedef struct {
    double psi_wb, v_v, w_rad_s, t_s, i_a, torque_nm, r_ohm, l_h;
} ctrl_bases_t;

#define CTRL_MTPA_N 64 /* segments of the IPMSM MTPA table */
/* Encoder-speed filter cut-off, Hz (docs/algorithms.md). */
#define CTRL_SPEED_LPF_HZ_DEFAULT 500.0
#define CTRL_DANGLE_SHIFT 26u /* fractional bits of dangle_to_omega */
/* Range of Ts in pu, the angle one period turns at rated speed (rad). */
#define CTRL_TS_PU_MIN 1.0e-3
#define CTRL_TS_PU_MAX 1.0

/* Fixed-point parameters used per sample; all q24_t fields are Q24 per-unit. */
typedef struct {
    uint32_t fs_hz;       /* control (sampling) frequency */
    int32_t pole_pairs;   /* p (integer) */
    q24_t ts;             /* control period Ts, pu time (Ts * w_base) */
    q24_t rs;             /* stator resistance, pu */
    q24_t ts_rs;          /* Ts * Rs, pu (precomputed product) */
    q24_t ld, lq;         /* pu */
    q24_t inv_ld, inv_lq; /* 1/Ld, 1/Lq, pu */
    q24_t psi_pm;         /* pu */
    q24_t vdc_nom;        /* nominal DC link, pu (its ratio to the rated back-EMF) */
    q24_t torque_rated;   /* pu */
    q24_t speed_rated_e;  /* rated electrical speed, pu */
    q24_t current_rated;  /* pu */
    q24_t current_max;    /* pu */
    q24_t psi_ref;        /* fixed flux reference, pu; 0 = MTPA */
    uint8_t salient;      /* 1 when Ld != Lq (IPMSM) */
    /* Angle increment per control period for 1.0 pu electrical speed, in
     * fx_angle_t units (2^32 = one turn), integer (Q0):
     * omega_to_dangle = round(Ts_pu / (2 pi) * 2^32); then
     * dtheta = round(omega_q24 * omega_to_dangle / 2^24) (ctrl_angle_step()). */
    int32_t omega_to_dangle;
    /* Inverse, Q26 (CTRL_DANGLE_SHIFT): omega_q24 = round(dtheta * dangle_to_omega
     * / 2^26) for a signed angle difference dtheta (angle units per period). */
    int32_t dangle_to_omega;
    /* First-order low-pass (EMA) coefficient of the encoder speed, Q24:
     * 1 - exp(-2 pi fc Ts), fc = CTRL_SPEED_LPF_HZ_DEFAULT unless changed with
     * ctrl_params_set_speed_lpf(). */
    q24_t speed_lpf_k;
    /* MTPA (mtpa.c), one table for every user. SPMSM: psi_s = |(psi_pm, T * mtpa_k)|,
     * mtpa_k = Lq / psi_pm, Q24; i_d = 0, i_q = T / psi_pm.
     * IPMSM: the exact MTPA locus at CTRL_MTPA_N + 1 uniform torques
     * |T| = i * mtpa_t_max / CTRL_MTPA_N: mtpa_psi (|psi_s|), mtpa_id (i_d <= 0 for
     * Lq > Ld), mtpa_iq (i_q >= 0), all Q24 pu; index position = |T| * mtpa_scale
     * / 2^16 (mtpa_scale is Q16: CTRL_MTPA_N / mtpa_t_max). Filled for the SPMSM
     * too (closed forms), for tools that read them. */
    q24_t mtpa_k;
    q24_t mtpa_t_max;                /* torque at current_max on the MTPA locus, pu */
    int32_t mtpa_scale;              /* Q16 */
    q24_t mtpa_psi[CTRL_MTPA_N + 1]; /* Q24 pu */
    q24_t mtpa_id[CTRL_MTPA_N + 1];  /* Q24 pu */
    q24_t mtpa_iq[CTRL_MTPA_N + 1];  /* Q24 pu */
    q24_t inv_psi_pm;                /* 1 / psi_pm, Q24 pu */
} ctrl_params_t;

/* Error codes shared by configuration functions. */
#define CTRL_OK 0
#define CTRL_EINVAL (-1) /* a parameter is missing, non-finite or out of range */
#define CTRL_ERANGE (-2) /* a parameter does not fit the Q format */
#define CTRL_ENOENT (-3) /* unknown name */

/* Why a configuration was refused: the quantity, its value and the range the
 * core accepts (for a derived quantity, the data it follows from). */
typedef struct {
    int code;             /* CTRL_OK, CTRL_EINVAL (SI datum), CTRL_ERANGE (per-unit range) */
    const char *quantity; /* e.g. "psi_pm_wb", "rated electrical speed x Ts" */
    const char *unit;     /* "Wb", "rad per period", "" for a ratio */
    double value, min, max;
    const char *depends; /* the SI data a derived quantity follows from, or NULL */
} ctrl_diag_t;

/* Fill *d (if not NULL) with the refusal and return code (configuration
 * only; one home for ctrl_params_init_diag's and ctrl_setup_refuse's records). */
int ctrl_diag_refuse(ctrl_diag_t *d, int code, const char *quantity, const char *unit, double value,
                     double lo, double hi, const char *depends);
/* 1 if value is finite and inside [lo, hi]; else 0 with *d (if not NULL) the
 * CTRL_EINVAL refusal naming quantity, value and range (configuration only). */
int ctrl_diag_in_range(ctrl_diag_t *d, const char *quantity, const char *unit, double value,
                       double lo, double hi);

/*
 * Validate the machine data and compute bases and fixed-point parameters for a
 * control frequency. Returns CTRL_OK, or CTRL_EINVAL (an SI datum missing, not
 * finite, non-positive or beyond a unit-mistake limit) / CTRL_ERANGE (a
 * per-unit value outside the core's formats) with *p and *bases zeroed;
 * ctrl_params_init_diag also says why in *why (may be NULL).
 */
int ctrl_params_init(ctrl_params_t *p, ctrl_bases_t *bases, const ctrl_machine_t *m,
                     uint32_t fs_hz);
int ctrl_params_init_diag(ctrl_params_t *p, ctrl_bases_t *bases, const ctrl_machine_t *m,
                          uint32_t fs_hz, ctrl_diag_t *why);

/* The diagnosis as one line, e.g. "rated electrical speed x Ts = 1.47 rad per
 * period is outside the range the core takes, [0.001, 1] rad per period (from
 * speed_rated_rpm, pole_pairs, fs_hz)" ("ok" for CTRL_OK); a refused choice
 * (min > max: no range, the unit names its kind) as "controller bst refused:
 * <depends>" (in an image with the injection, CTRL_SL_HFI, its only user);
 * returns its length (truncated to cap - 1). */
size_t ctrl_diag_format(const ctrl_diag_t *d, char *buf, size_t cap);

/* A per-unit value -> Q24, rounded half away from zero, saturated (NaN: 0). */
q24_t ctrl_q24_from_double(double pu);
double ctrl_q24_to_double(q24_t x);

/* The one SI -> Q24 conversion of the configuration code: si / base (base =
 * the SI value of 1 pu, ctrl_bases_t) into *out when it is finite and inside
 * [lo_pu, hi_pu]: CTRL_OK; else CTRL_ERANGE and *out unchanged. */
int ctrl_q24_from_si(double si, double base, double lo_pu, double hi_pu, q24_t *out);

/* The one MTPA solver (configuration time; SI or pu alike, the current in
 * the units of psi_pm / L): the current vector of amplitude i maximising
 * Te = i_q (psi_pm + (Ld - Lq) i_d) (3.10) on |i| = i,
 *   i_d = (psi_pm - sqrt(psi_pm^2 + 8 dL^2 i^2)) / (4 dL),  dL = Lq - Ld != 0,
 * i_d = 0 for dL = 0, i_q = sqrt(i^2 - i_d^2). */
void ctrl_mtpa_split(double psi_pm, double ld, double lq, double i, double *i_d, double *i_q);

/* Change the speed-filter cut-off (Hz, 0 < fc < fs/2): sets p->speed_lpf_k.
 * Returns CTRL_OK or CTRL_EINVAL. */
int ctrl_params_set_speed_lpf(ctrl_params_t *p, double fc_hz);

#endif /* CONTROL_CTRL_PARAMS_H */
