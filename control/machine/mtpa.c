/*
 * MTPA: (4.15) for the SPMSM, the tabulated exact locus for the IPMSM (table
 * built in ctrl_params_config.c), one interpolation for every column.
 */
#include "mtpa.h"

/* Linear interpolation of column tab at table position pos (Q24 index units,
 * >= 0): beyond the last point the last segment is extended. */
static q24_t mtpa_interp(const q24_t *tab, int64_t pos)
{
    int64_t idx = (int64_t)((uint64_t)pos >> FX_QBITS); /* pos >= 0 */
    if (idx > CTRL_MTPA_N - 1) {
        idx = CTRL_MTPA_N - 1;
    }
    const int64_t frac = pos - idx * FX_ONE; /* < 2^33 (pos <= 4 N FX_ONE) */
    const int64_t a = tab[idx];
    const int64_t d = (int64_t)tab[idx + 1] - a;
    return fx_sat32(a + fx_rshift64_round(d * frac, FX_QBITS));
}

/* Table position of |t| (Q24 index units), at most 4 table lengths. */
static int64_t mtpa_pos(const ctrl_params_t *p, q24_t t_abs)
{
    const int64_t pos = fx_rshift64_round((int64_t)t_abs * p->mtpa_scale, 16u);
    const int64_t pos_max = (int64_t)(4 * CTRL_MTPA_N) * FX_ONE;
    return pos > pos_max ? pos_max : pos;
}

q24_t ctrl_mtpa_psi(const ctrl_params_t *p, q24_t torque)
{
    const q24_t t = fx_abs(torque);
    if (p->salient == 0u) {
        /* (4.15) in pu: psi_s = sqrt(psi_pm^2 + (Lq T / psi_pm)^2). */
        return fx_mag(p->psi_pm, fx_mul(t, p->mtpa_k));
    }
    return mtpa_interp(p->mtpa_psi, mtpa_pos(p, t));
}

void ctrl_mtpa_current(const ctrl_params_t *p, q24_t torque, q24_t *i_d, q24_t *i_q)
{
    const q24_t t = fx_min(fx_abs(torque), p->mtpa_t_max);
    q24_t q;
    if (p->salient == 0u) {
        *i_d = 0;
        q = fx_mul(t, p->inv_psi_pm); /* Te = psi_pm i_q (3.10) */
    } else {
        const int64_t pos = mtpa_pos(p, t);
        *i_d = mtpa_interp(p->mtpa_id, pos);
        q = mtpa_interp(p->mtpa_iq, pos);
    }
    *i_q = torque < 0 ? fx_neg(q) : q;
}
