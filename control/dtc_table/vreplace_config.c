/* Configuration of the voltage replacement (4.19) from sigma in radians. */
#include <math.h>
#include <stddef.h>

#include "ctrl_params.h"
#include "ctrl_units.h"
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
    c->cos_b = 0;
    c->sin_b = 0;
    c->enabled = 0u;
    if (!isfinite(sigma_rad) || sigma_rad < 0.0 || sigma_rad > sigma_max + 1e-9) {
        return CTRL_EINVAL;
    }
    if (sigma_rad > sigma_max) {
        sigma_rad = sigma_max;
    }
    const double b = CTRL_PI / 6.0 - sigma_rad;
    c->cos_b = ctrl_q24_from_double(cos(b));
    c->sin_b = ctrl_q24_from_double(sin(b));
    c->enabled = ctrl_q24_from_double(sin(sigma_rad)) > 0 ? 1u : 0u;
    return CTRL_OK;
}
