/* Configuration of the voltage replacement (4.19) from sigma in radians. */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "vectors.h"
#include "vreplace.h"
#include "vreplace_config.h"

int ctrl_vreplace_config(ctrl_vreplace_t *c, double sigma_rad)
{
    /* (4.19) takes sigma in [0, pi/12]; the subsectors I and II stay apart up
     * to pi/6, where they split the sector in halves (the sigma study of
     * docs/algorithms.md goes that far); 1e-9 rad of slack so that e.g.
     * 30 * pi / 180 is accepted. */
    const double sigma_max = CTRL_VR_SIGMA_MAX;
    if (c == NULL) {
        return CTRL_EINVAL;
    }
    memset(c, 0, sizeof *c);
    if (!isfinite(sigma_rad) || sigma_rad < 0.0 || sigma_rad > sigma_max + 1e-9) {
        return CTRL_EINVAL;
    }
    if (sigma_rad > sigma_max) {
        sigma_rad = sigma_max;
    }
    const double b = CTRL_PI / 6.0 - sigma_rad;
    c->cos_b = ctrl_q24_from_double(ctrl_cfg_cos(b));
    c->sin_b = ctrl_q24_from_double(ctrl_cfg_sin(b));
    c->enabled = ctrl_q24_from_double(ctrl_cfg_sin(sigma_rad)) > 0 ? 1u : 0u;
    /* u = d e^{-+j(pi/6 - sigma)}: (dx cb +- dy sb, dy cb -+ dx sb), one
     * rounding each (vreplace.h) */
    for (unsigned x = 1u; x <= 6u; x++) {
        const q24_t dx = ctrl_vec_dir_q24[x][0];
        const q24_t dy = ctrl_vec_dir_q24[x][1];
        c->u_lo[x - 1u][0] = fx_dot(dx, dy, c->cos_b, c->sin_b);
        c->u_lo[x - 1u][1] = fx_cross(dy, dx, c->sin_b, c->cos_b);
        c->u_hi[x - 1u][0] = fx_cross(dx, dy, c->sin_b, c->cos_b);
        c->u_hi[x - 1u][1] = fx_dot(dy, dx, c->cos_b, c->sin_b);
    }
    return CTRL_OK;
}
