/* Configuration of the voltage replacement (4.19) from sigma in radians. */
#include <math.h>
#include <stddef.h>

#include "ctrl_params.h"
#include "vreplace.h"
#include "vreplace_config.h"

int ctrl_vreplace_config(ctrl_vreplace_t *c, double sigma_rad)
{
    /* pi/12, the largest subsector of (4.19); 1e-12 rad of slack so that
     * e.g. 15 * pi / 180 is accepted. */
    const double sigma_max = 0.26179938779914943653855361527329;
    if (c == NULL) {
        return CTRL_EINVAL;
    }
    c->sin_sigma = 0;
    c->cos_sigma = FX_ONE;
    c->enabled = 0u;
    if (!isfinite(sigma_rad) || sigma_rad < 0.0 || sigma_rad > sigma_max + 1e-12) {
        return CTRL_EINVAL;
    }
    if (sigma_rad > sigma_max) {
        sigma_rad = sigma_max;
    }
    c->sin_sigma = ctrl_q24_from_double(sin(sigma_rad));
    c->cos_sigma = ctrl_q24_from_double(cos(sigma_rad));
    c->enabled = c->sin_sigma > 0 ? 1u : 0u;
    return CTRL_OK;
}
