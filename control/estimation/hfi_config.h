/*
 * Configuration side of the high-frequency injection (hfi.h): SI values
 * (double) converted to its fixed-point settings. Included only by
 * *_config.c files, tests and the firmware's configuration code.
 */
#ifndef CONTROL_HFI_CONFIG_H
#define CONTROL_HFI_CONFIG_H

#include "controller.h"
#include "ctrl_params.h"
#include "hfi.h"

typedef struct {
    double ripple_frac; /* current step of one injection period along d, share of the
                         * rated current: sets the amplitude V = ripple Ld fs */
    double v_inj_v;     /* the amplitude instead, V (0: from ripple_frac) */
    double track_hz;    /* tracking observer's bandwidth: its triple pole, Hz (0: from
                         * the inertia) */
    double j_kgm2;      /* rotor and load inertia of the observer's mechanics (0: none,
                         * no torque feed-forward) */
    double h_tau_s;     /* time constant of the ripple model (its removal), s */
    double sal_min;     /* smallest max(Lq/Ld, Ld/Lq) the injection takes */
    double w_hi_frac;   /* hand-over to the flux observer above this share of rated speed */
    double w_lo_frac;   /* ... back to the injection below this share */
    double pol_i_frac;  /* polarity pulses: peak current, share of the rated current */
    double pol_rounds;  /* pulse pairs per direction */
    double pol_min;     /* smallest |asymmetry| of the pulses that tells the polarity */
} ctrl_hfi_config_t;

/*
 * Defaults for a machine (docs/algorithms.md, "High-frequency injection"):
 * a ripple step of 3 % of the rated current per period (the amplitude within
 * a quarter of the DC link); the tracking observer with the machine's inertia,
 * fast enough that a load step of the rated torque it does not know of
 * (p T / J) moves the angle by 5 deg at most (0.271 a / w_o^2), within
 * 10 Hz .. fs / 100; the ripple model
 * over 2 ms; saliency at least 1.1; hand-over to the observer at twice
 * and back at once the speed where its angle error from a 10 % resistance
 * error at rated current is 2 deg, at least 2 % of rated speed (its
 * fallback's level), at most 10 %; polarity pulses to the rated current,
 * 2 rounds, 2 % asymmetry at least.
 */
void ctrl_hfi_config_default(ctrl_hfi_config_t *c, const ctrl_machine_t *m);

/* Validate and set everything; the state is stopped. Returns CTRL_OK or
 * CTRL_EINVAL with *why naming the field (why may be NULL) and *h untouched:
 * a machine with too little saliency is refused with its ratio and the
 * minimum. */
int ctrl_hfi_init(ctrl_hfi_t *h, const ctrl_params_t *p, const ctrl_bases_t *b,
                  const ctrl_hfi_config_t *c, ctrl_diag_t *why);

/* The fields by name, "hfi.<field>" (0: the machine's default), for
 * ctrl_tunable_set / ctrl_tunable_get and listings: a descriptor with the
 * tunables only (no controller functions). */
extern const ctrl_desc_t ctrl_hfi_desc;

/* The saliency the injection reads: max(Lq/Ld, Ld/Lq) of the machine. */
double ctrl_hfi_saliency(const ctrl_params_t *p);

#endif /* CONTROL_HFI_CONFIG_H */
