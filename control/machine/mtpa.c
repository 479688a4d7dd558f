/*
 * MTPA stator-flux reference: (4.15) for the SPMSM, tabulated exact locus for
 * the IPMSM (table built in ctrl_params_config.c).
 */
#include "mtpa.h"

q24_t ctrl_mtpa_psi(const ctrl_params_t *p, q24_t torque)
{
    const q24_t t = fx_abs(torque);
    if (p->salient == 0u) {
        /* (4.15) in pu: psi_s = sqrt(psi_pm^2 + (Lq T / psi_pm)^2). */
        return fx_mag(p->psi_pm, fx_mul(t, p->mtpa_k));
    }
    /* Position on the table in Q24 index units; beyond the last point the
     * last segment is extended, at most to 4 table lengths (bounded product). */
    int64_t pos = fx_rshift64_round((int64_t)t * p->mtpa_scale, 16u);
    const int64_t pos_max = (int64_t)(4 * CTRL_MTPA_N) * FX_ONE;
    if (pos > pos_max) {
        pos = pos_max;
    }
    int64_t idx = (int64_t)((uint64_t)pos >> FX_QBITS); /* pos >= 0 */
    if (idx > CTRL_MTPA_N - 1) {
        idx = CTRL_MTPA_N - 1;
    }
    const int64_t frac = pos - idx * FX_ONE; /* < 2^33 */
    const int64_t a = p->mtpa_psi[idx];
    const int64_t d = (int64_t)p->mtpa_psi[idx + 1] - a;
    return fx_sat32(a + fx_rshift64_round(d * frac, FX_QBITS));
}
