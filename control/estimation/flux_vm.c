/*
 * Voltage-model flux, S1(31)-(38), with selectable drift handling (thesis §2.2).
 * The integral is kept in Q48 so that the per-period increments Ts*v (a Q24 x
 * Q24 product) are added without rounding: no rounding drift accumulates.
 */
#include "flux_vm.h"

/* |flux| kept below 127 pu in Q48 so the Q24 view always fits an int32_t. */
#define VM_ACC_MAX ((int64_t)127 * ((int64_t)1 << 48))

static int64_t vm_clamp(int64_t x)
{
    return x > VM_ACC_MAX ? VM_ACC_MAX : (x < -VM_ACC_MAX ? -VM_ACC_MAX : x);
}

static q24_t vm_q24(int64_t acc)
{
    return fx_sat32(fx_rshift64_round(acc, FX_QBITS));
}

void ctrl_flux_vm_init(ctrl_flux_vm_t *vm, uint8_t mode, q24_t k_corr)
{
    vm->psi_alpha_acc = 0;
    vm->psi_beta_acc = 0;
    vm->i_alpha_prev = 0;
    vm->i_beta_prev = 0;
    vm->mode = mode <= CTRL_VM_CORR_CM ? mode : CTRL_VM_CORR_NONE;
    vm->k_corr = fx_clamp(k_corr, 0, FX_ONE / 2);
    vm->primed = 0u;
}

void ctrl_flux_vm_reset(ctrl_flux_vm_t *vm, q24_t psi_alpha, q24_t psi_beta, q24_t i_alpha,
                        q24_t i_beta)
{
    vm->psi_alpha_acc = (int64_t)psi_alpha * FX_ONE;
    vm->psi_beta_acc = (int64_t)psi_beta * FX_ONE;
    vm->i_alpha_prev = i_alpha;
    vm->i_beta_prev = i_beta;
    vm->primed = 1u;
}

/* One axis: acc += Ts v - Ts Rs (i_prev + i)/2 [+ correction], all Q48. */
static int64_t vm_axis(const ctrl_flux_vm_t *vm, const ctrl_params_t *p, int64_t acc, q24_t v,
                       q24_t i_prev, q24_t i, q24_t psi_cm)
{
    const int64_t i_sum = (int64_t)i_prev + i; /* S1(37)-(38) x 2 */
    int64_t inc = (int64_t)p->ts * v - fx_rshift64_round((int64_t)p->ts_rs * i_sum, 1u);
    const q24_t psi = vm_q24(acc);
    if (vm->mode == CTRL_VM_CORR_LOWPASS) {
        inc -= (int64_t)vm->k_corr * psi; /* leak towards 0 */
    } else if (vm->mode == CTRL_VM_CORR_CM) {
        inc += (int64_t)vm->k_corr * ((int64_t)psi_cm - psi); /* pull towards (3.4) */
    }
    return vm_clamp(acc + inc);
}

void ctrl_flux_vm_update(ctrl_flux_vm_t *vm, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                         q24_t i_alpha, q24_t i_beta, q24_t psi_cm_alpha, q24_t psi_cm_beta)
{
    if (vm->primed == 0u) {
        ctrl_flux_vm_reset(vm, psi_cm_alpha, psi_cm_beta, i_alpha, i_beta);
        return;
    }
    vm->psi_alpha_acc =
        vm_axis(vm, p, vm->psi_alpha_acc, v_alpha, vm->i_alpha_prev, i_alpha, psi_cm_alpha);
    vm->psi_beta_acc =
        vm_axis(vm, p, vm->psi_beta_acc, v_beta, vm->i_beta_prev, i_beta, psi_cm_beta);
    vm->i_alpha_prev = i_alpha;
    vm->i_beta_prev = i_beta;
}

void ctrl_flux_vm_get(const ctrl_flux_vm_t *vm, q24_t *psi_alpha, q24_t *psi_beta)
{
    *psi_alpha = vm_q24(vm->psi_alpha_acc);
    *psi_beta = vm_q24(vm->psi_beta_acc);
}
