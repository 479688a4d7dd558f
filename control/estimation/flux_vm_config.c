/* Voltage-model flux: corner frequency -> per-period gain (configuration). */
#include <math.h>
#include <stddef.h>

#include "ctrl_units.h"
#include "flux_vm.h"
#include "flux_vm_config.h"

int ctrl_flux_vm_gain(const ctrl_params_t *p, double fc_hz, q24_t *k_corr)
{
    if (p == NULL || k_corr == NULL || p->fs_hz == 0u || !isfinite(fc_hz) || fc_hz <= 0.0) {
        return CTRL_EINVAL;
    }
    /* Discrete first-order section: k = w_c Ts (forward Euler). */
    const double k = CTRL_TWO_PI * fc_hz / (double)p->fs_hz;
    if (k >= 0.5) {
        return CTRL_EINVAL;
    }
    *k_corr = ctrl_q24_from_double(k);
    return *k_corr > 0 ? CTRL_OK : CTRL_EINVAL;
}
