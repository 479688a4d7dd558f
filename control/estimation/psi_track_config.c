/* PM-flux tracking: SI configuration -> gains and divider (configuration). */
#include <math.h>
#include <string.h>

#include "ctrl_units.h"
#include "psi_track_config.h"

int ctrl_psi_track_init(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_bases_t *b,
                        const ctrl_fobs_config_t *c, double w_max_rad_s, ctrl_diag_t *why)
{
    if (t == NULL || p == NULL || b == NULL || c == NULL || p->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    const double ts = 1.0 / (double)p->fs_hz;
    if (!ctrl_diag_in_range(why, "w_max_rad_s", "rad/s", w_max_rad_s, 1e-3, 1e9)) {
        return CTRL_EINVAL;
    }
    ctrl_fobs_config_t enc = *c;
    enc.mode = CTRL_FOBS_ENCODER;
    ctrl_psi_track_t n;
    memset(&n, 0, sizeof n);
    if (ctrl_fobs_init(&n.obs, p, b, &enc, why) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    /* At most a quarter turn between two corrections at w_max (psi_track.h);
     * every period (N = 1) where one period turns further. */
    unsigned div = 1u;
    while (div < CTRL_PSI_TRACK_DIV_MAX && (double)(div + 1u) * w_max_rad_s * ts <= 0.5 * CTRL_PI) {
        div++;
    }
    n.div = (uint8_t)div;
    const double nts = (double)n.div * ts;
    double keep = 1.0; /* (1 - w_c Ts)^N, without pow (flash on the board) */
    for (unsigned k = 0u; k < n.div; k++) {
        keep *= 1.0 - c->kenc_rad_s * ts;
    }
    n.k_n = ctrl_q24_from_double(1.0 - keep);
    n.psi_k_n = c->psi_tau_s > 0.0 ? ctrl_q24_from_double(1.0 - exp(-nts / c->psi_tau_s)) : 0;
    *t = n;
    return CTRL_OK;
}
