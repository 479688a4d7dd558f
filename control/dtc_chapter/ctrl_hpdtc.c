/*
 * HP-DTC of the book chapter (S1 §5), per-sample part (integer-only):
 * vector selector S1 Table 4, reflected flux position S1(40), voltage level
 * from |T_err|, timing table (generated at init, ctrl_s1_dtc_config.c).
 */
#include <stddef.h>

#include "ctrl_s1_dtc.h"
#include "plan.h"
#include "vectors.h"

/* Section boundaries at 6 and 18 deg: tan, Q30 (round(tan(x) * 2^30)). */
#define K_TAN6_Q30 112854813
#define K_TAN18_Q30 348879867

int ctrl_hpdtc_vectors(int phi, int tau, int n, uint8_t *k1, uint8_t *k2)
{
    const int inc_phi = phi != 0;
    const int inc_tau = tau != 0;
    /* Offsets modulo 6 (n - 1 = n + 5, n - 2 = n + 4), so that the wrap of
     * Table 4 is ctrl_vec_offset's. */
    unsigned a;
    unsigned b;
    if (inc_phi && inc_tau) { /* Table 4: 1 1 -> n+1, n+2 */
        a = 1u;
        b = 2u;
    } else if (inc_phi) { /* 1 0 -> n-1, n-2 */
        a = 5u;
        b = 4u;
    } else if (inc_tau) { /* 0 1 -> n+2, n+1 */
        a = 2u;
        b = 1u;
    } else { /* 0 0 -> n-2, n-1 */
        a = 4u;
        b = 5u;
    }
    /* n reduced to 1..6 first (any int). */
    const uint8_t nr = ctrl_vec_wrap(n);
    *k1 = ctrl_vec_offset(nr, a);
    *k2 = ctrl_vec_offset(nr, b);
    return inc_phi == inc_tau ? 1 : -1;
}

int ctrl_hpdtc_section(q24_t psi_alpha, q24_t psi_beta, uint8_t n)
{
    const unsigned i = (n >= 1u && n <= 6u) ? (unsigned)n : 1u;
    /* Rotate by -(n-1) 60 deg: the sector centre onto the x axis. V_n / Vdc
     * (Q30, magnitude 2/3) serves as the rotation: the comparisons below are
     * of y against x tan(b) and do not see the common scale. */
    const int32_t c = ctrl_vec_ab_q30[i][0];
    const int32_t sn = ctrl_vec_ab_q30[i][1];
    /* Back in Q24 (rounded): |(c, sn)| = 2/3 and |psi| <= sqrt(2) 2^31, so
     * |x|, |y| <= 0.943 2^61 and the values fit an int32_t unsaturated. */
    const int32_t x24 = fx_round_nosat((int64_t)psi_alpha * c + (int64_t)psi_beta * sn, 30u);
    const int32_t y24 = fx_round_nosat((int64_t)psi_beta * c - (int64_t)psi_alpha * sn, 30u);
    /* Compare y with x tan(b) in Q24 * Q30 (one SMULL each). */
    const int64_t y54 = (int64_t)y24 * ((int64_t)1 << 30);
    const int64_t b6 = (int64_t)x24 * K_TAN6_Q30;
    const int64_t b18 = (int64_t)x24 * K_TAN18_Q30;
    if (y54 >= b18) {
        return 2;
    }
    if (y54 >= b6) {
        return 1;
    }
    if (y54 >= -b6) {
        return 0;
    }
    if (y54 >= -b18) {
        return -1;
    }
    return -2;
}

void ctrl_hpdtc_reset(void *state)
{
    ctrl_hpdtc_state_t *s = state;
    ctrl_hyst2_reset(&s->flux.h);
    ctrl_hyst2_reset(&s->torque);
    s->last_level = 0u;
    s->last_section = 2u;
}

void ctrl_hpdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_hpdtc_state_t *s = state;
    const ctrl_mstate_t *nx = &ctx->est->next; /* delay compensation */
    const q24_t psi_ref = ctx->ref->psi > 0 ? ctx->ref->psi : s->psi_ref;
    const q24_t t_err = fx_sub(ctx->ref->torque, nx->torque);
    const int phi = ctrl_s1_flux_phi(&s->flux, &s->flux_lim_ref, psi_ref, nx->psi_amp_sq) > 0;
    const int tau = ctrl_hyst2_update(&s->torque, t_err) > 0;
    const uint8_t n = nx->sector;
    uint8_t k1;
    uint8_t k2;
    const int refl = ctrl_hpdtc_vectors(phi, tau, n, &k1, &k2);
    /* Reflected position seen from V_k1 (README): s * rho, section -2..2 -> 0..4. */
    const int j = refl * ctrl_hpdtc_section(nx->psi_alpha, nx->psi_beta, n) + 2;
    /* Voltage level 0..4 from |T_err| (thresholds l e_fs / 5). */
    const q24_t ae = fx_abs(t_err);
    unsigned lvl = 0u;
    for (unsigned i = 0u; i < HPDTC_LEVELS - 1u; i++) {
        lvl += ae >= s->lvl_thr[i] ? 1u : 0u;
    }
    const unsigned sec = (unsigned)j; /* 0..4 */
    s->last_level = (uint8_t)lvl;
    s->last_section = (uint8_t)sec;
    const q24_t d1 = s->dur[lvl][sec][0];
    const q24_t d2 = s->dur[lvl][sec][1];
    const q24_t d0 = FX_ONE - d1 - d2; /* >= 0: the table keeps t_k1 + t_k2 <= 20 */
    ctrl_plan_t *p = &out->plan;
    p->n_seg = 4u;
    p->vec[0] = k1;
    p->dur[0] = d1;
    p->vec[1] = k2;
    p->dur[1] = d2;
    p->vec[2] = 0u; /* zero time split equally between V0 and V7 (S1 §5.2.3) */
    p->dur[2] = d0 / 2;
    p->vec[3] = 7u;
    p->dur[3] = d0 - d0 / 2;
    /* Its leg duties: a leg is on during the segments of the vectors that
     * have it high, V7's half of the zero time included (d1 + d2 + d0 = 1). */
    const uint32_t m1 = ctrl_vec_legs[k1];
    const uint32_t m2 = ctrl_vec_legs[k2];
    for (unsigned x = 0u; x < 3u; x++) {
        out->legs.duty[x] =
            p->dur[3] + (((m1 >> x) & 1u) != 0u ? d1 : 0) + (((m2 >> x) & 1u) != 0u ? d2 : 0);
    }
}
