/*
 * FOC (S1 §2, Algorithm 1) and its hysteresis-current variant: descriptors,
 * tunables, defaults, SI -> fixed-point initialisation and the current
 * reference table (MTPA locus). Configuration only (may use double).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_foc.h"
#include "ctrl_foc_config.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "estimator.h"
#include "field_weak_config.h"

#define FOC_FS_HZ 10000u      /* S1 §2: Ts = 100 us */
#define FOC_WC_PER_FS 20.0    /* default wc = 2 pi fs / 20 */
#define FOC_HI_REL 0.05       /* default foc_hyst band: 5 % of the rated current */
#define FOC_KI_TS_MAX 16383.0 /* Ki Ts < 2^31 / 2^17 in Q17 */

static const ctrl_tunable_t foc_tunables[] = {
    {"wc", "rad/s", HELP_TEXT("current-loop bandwidth for Kp = L wc, Ki = R wc; 0 = 2 pi fs/20"),
     offsetof(ctrl_foc_cfg_t, wc), 0.0, 1.0e6},
    {"Kp_d", "V/A", HELP_TEXT("d-current PI proportional gain; 0 = Ld wc"),
     offsetof(ctrl_foc_cfg_t, kp_d), 0.0, 1.0e5},
    {"Ki_d", "V/(A*s)", HELP_TEXT("d-current PI integral gain; 0 = Rs wc"),
     offsetof(ctrl_foc_cfg_t, ki_d), 0.0, 1.0e8},
    {"Kp_q", "V/A", HELP_TEXT("q-current PI proportional gain; 0 = Lq wc"),
     offsetof(ctrl_foc_cfg_t, kp_q), 0.0, 1.0e5},
    {"Ki_q", "V/(A*s)", HELP_TEXT("q-current PI integral gain; 0 = Rs wc"),
     offsetof(ctrl_foc_cfg_t, ki_q), 0.0, 1.0e8},
    {"mtpa", "-", HELP_TEXT("1: i_d from the MTPA locus (IPMSM); 0: i_d = 0 (S1 Algorithm 1)"),
     offsetof(ctrl_foc_cfg_t, mtpa), 0.0, 1.0},
};

static const ctrl_tunable_t foc_hyst_tunables[] = {
    {"h_i", "A",
     HELP_TEXT("phase-current hysteresis half band (S1 sec. 2 current-controlled inverter)"),
     offsetof(ctrl_foc_cfg_t, h_i), 0.0, 1.0e4},
    {"mtpa", "-", HELP_TEXT("1: i_d from the MTPA locus (IPMSM); 0: i_d = 0 (S1 Algorithm 1)"),
     offsetof(ctrl_foc_cfg_t, mtpa), 0.0, 1.0},
};

static void foc_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    ctrl_foc_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->mtpa = 1.0;
    if (m != NULL) {
        c->h_i = FOC_HI_REL * m->current_rated_a;
    }
}

/* Torque -> current references: the MTPA table of the params for a salient
 * machine with Lq > Ld and mtpa on, else i_d = 0 up to T(current_max). */
static int foc_iref_init(ctrl_foc_iref_t *r, const ctrl_params_t *p, int mtpa)
{
    r->mtpa = (uint8_t)(mtpa && p->salient && p->lq > p->ld);
    const double t_max =
        ctrl_q24_to_double(p->psi_pm) * ctrl_q24_to_double(p->current_max); /* (3.10) */
    return ctrl_q24_from_si(t_max, 1.0, 0.0, 127.0, &r->t_max); /* < 16 pu: params' range */
}

static int foc_pi_config(ctrl_foc_pi_t *pi, double kp_si, double ki_si, double l_pu, double wc,
                         const ctrl_setup_t *su)
{
    const ctrl_params_t *p = su->params;
    const double fs = (double)p->fs_hz;
    const double ts_pu = ctrl_q24_to_double(p->ts);
    const double r_pu = ctrl_q24_to_double(p->rs);
    const double r_base = su->bases->r_ohm;
    /* Kp = L wc (pu: L_pu * wc / w_base, w_base = ts_pu * fs); Ki Ts = R wc Ts. */
    const double kp = kp_si > 0.0 ? kp_si / r_base : l_pu * (wc / fs) / ts_pu;
    const double ki_ts = ki_si > 0.0 ? ki_si / r_base / fs : r_pu * wc / fs;
    if (!isfinite(kp) || !(kp >= 0.0) || kp >= 2047.0) {
        return ctrl_setup_refuse(su, CTRL_ERANGE, "current PI Kp / (r_base)", "pu", kp, 0.0,
                                 2047.0);
    }
    /* Ki Ts in Q(ki_shift): Q30 below 2 pu (every thesis machine), fewer bits
     * above (Ki Ts = Rs wc Ts grows with Rs / r_base: a gimbal motor's Rs is
     * ~16 r_base at its low rated speed); at least 17. */
    if (!isfinite(ki_ts) || !(ki_ts >= 0.0) || ki_ts >= FOC_KI_TS_MAX) {
        return ctrl_setup_refuse(su, CTRL_ERANGE, "current PI Ki Ts / (r_base)", "pu", ki_ts, 0.0,
                                 FOC_KI_TS_MAX);
    }
    unsigned ki_shift = 30u;
    while (ki_shift > 17u && ki_ts * ctrl_cfg_ldexp(1.0, (int)ki_shift) >= 2147483000.0) {
        ki_shift--;
    }
    pi->kp = (int32_t)ctrl_cfg_llround(kp * 1048576.0); /* Q20: FOC_KP_QBITS */
    /* Q(24 + ki_shift): vdc_nom <= 32 pu (2^29), so lim <= 2^59 */
    pi->lim = (int64_t)p->vdc_nom * ((int64_t)1 << ki_shift);
    pi->ki_ts = (int32_t)ctrl_cfg_llround(ctrl_cfg_ldexp(ki_ts, (int)ki_shift));
    pi->ki_shift = (uint8_t)ki_shift;
    pi->integ = 0;
    return CTRL_OK;
}

static int foc_init_common(void *state, const void *cfg, const ctrl_setup_t *su, int hyst)
{
    const ctrl_params_t *p = su->params;
    const ctrl_foc_cfg_t *c = cfg;
    ctrl_foc_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(foc_tunables, sizeof foc_tunables / sizeof foc_tunables[0], c) !=
            CTRL_OK ||
        ctrl_tunables_check(foc_hyst_tunables,
                            sizeof foc_hyst_tunables / sizeof foc_hyst_tunables[0], c) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    const double wc = c->wc > 0.0 ? c->wc : CTRL_TWO_PI * fs / FOC_WC_PER_FS;
    if (wc / fs > 1.5) {
        return CTRL_EINVAL; /* discrete loop gain wc Ts beyond the stable range */
    }
    int rc = foc_iref_init(&s->iref, p, c->mtpa >= 0.5);
    if (rc == CTRL_OK) {
        rc = foc_pi_config(&s->pi_d, c->kp_d, c->ki_d, ctrl_q24_to_double(p->ld), wc, su);
    }
    if (rc == CTRL_OK) {
        rc = foc_pi_config(&s->pi_q, c->kp_q, c->ki_q, ctrl_q24_to_double(p->lq), wc, su);
    }
    if (rc == CTRL_OK) {
        /* The flux-circle constants of the machine (current and voltage
         * limits unused here: the pipeline limits the torque). */
        ctrl_fieldweak_cfg_t fieldweak_cfg;
        ctrl_fieldweak_cfg_default(&fieldweak_cfg);
        rc =
            ctrl_fieldweak_init(&s->fieldweak, &fieldweak_cfg, su->machine, su->bases, p, NULL, 0u);
        if (rc != CTRL_OK && !(su->machine->lq_h >= su->machine->ld_h)) {
            rc = ctrl_setup_refuse(su, rc, "lq_h (reverse saliency Lq < Ld, field weakening)", "H",
                                   su->machine->lq_h, su->machine->ld_h, INFINITY);
        } else if (rc != CTRL_OK) {
            rc = ctrl_setup_refuse(su, rc, "a field-weakening constant (field_weak_config.c)", "pu",
                                   0.0, -100.0, 100.0);
        }
    }
    if (rc == CTRL_OK) {
        rc = ctrl_setup_q24(su, "h_i / current base", c->h_i, su->bases->i_a, 0.0, 127.0, &s->h_i);
    }
    if (rc != CTRL_OK) {
        memset(s, 0, sizeof *s);
        return rc;
    }
    s->hyst = (uint8_t)(hyst != 0);
    ctrl_foc_reset(s);
    return CTRL_OK;
}

static int foc_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return foc_init_common(state, cfg, su, 0);
}

static int foc_hyst_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return foc_init_common(state, cfg, su, 1);
}

#if PMSM_LIVE_PARAMS
/* One axis' PI takes new gains while running (integer-only: the interrupt
 * calls it): the integrator holds the output for the last step's error e
 * under the old gains less the new proportional part, Kp_new e + I_new =
 * Kp_old e + I_old (within +-lim), in the new Q(24 + ki_shift). */
static void foc_pi_retune(ctrl_foc_pi_t *pi, const ctrl_foc_pi_t *to, q24_t e)
{
    /* Q24: the integrator (ki_shift >= 17), (Kp_old - Kp_new) e from Q44
     * (|e| < 2^31, |kp| < 2^31); |sum| < 2^43 */
    int64_t v = fx_rshift64_round_call(pi->integ, pi->ki_shift) +
                fx_rshift64_round_call((int64_t)e * ((int64_t)pi->kp - to->kp), FOC_KP_QBITS);
    const int64_t lim = to->lim >> to->ki_shift; /* lim >= 0 */
    v = v > lim ? lim : (v < -lim ? -lim : v);
    *pi = *to;
    pi->integ = v * ((int64_t)1 << to->ki_shift); /* |v| 2^ki_shift <= lim <= 2^59 */
}

/* The tunables changed while running: foc the current PIs' gains (wc and the
 * four gains, bumpless by foc_pi_retune), foc_hyst its band; mtpa changes the
 * current references: with the controller stopped only. */
static void foc_retune(void *state, const void *fresh)
{
    ctrl_foc_state_t *s = state;
    const ctrl_foc_state_t *f = fresh;
    if (s->hyst != 0u) {
        s->h_i = f->h_i;
        return;
    }
    foc_pi_retune(&s->pi_d, &f->pi_d, s->e_d);
    foc_pi_retune(&s->pi_q, &f->pi_q, s->e_q);
}
#endif

/* FOC reads no optional estimator output: rotor-frame currents and fluxes
 * only. Its currents come from the torque (ctrl_foc_iref, or the flux circle
 * of field weakening): no fixed flux reference (flux_free). */
CTRL_DESC_DEFINE_LIVE(
    foc, "FOC, rotor-field oriented, dq current PI + SVPWM, MTPA/i_d=0 (S1 sec. 2, Algorithm 1)",
    FOC_FS_HZ, ctrl_foc_state_t, ctrl_foc_cfg_t, foc_tunables, foc_cfg_default, foc_init,
    ctrl_foc_reset, ctrl_foc_step, 0u, 1u, CTRL_RETUNE(foc_retune), 0x1Fu);

/* The hysteresis variant reads the angle at k+1. */
CTRL_DESC_DEFINE_LIVE(
    foc_hyst, "FOC with per-phase hysteresis current control, one vector per period (S1 sec. 2)",
    FOC_FS_HZ, ctrl_foc_state_t, ctrl_foc_cfg_t, foc_hyst_tunables, foc_cfg_default, foc_hyst_init,
    ctrl_foc_reset, ctrl_foc_step, CTRL_EST_SC_NEXT, 1u, CTRL_RETUNE(foc_retune), 0x1u);
