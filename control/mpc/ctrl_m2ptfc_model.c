/* k+2 prediction model of the chapter-6 predictive controllers (see the header). */
#include "ctrl_m2ptfc_model.h"

#include <stddef.h>

#include "mtpa.h"
#include "plan.h"
#include "vectors.h"

/* Forced inlining of the shared basis core: an out-of-line call costs each
 * step more than it saves in code (measured, tools/bench). */
#if defined(__GNUC__)
#define MPC_ALWAYS_INLINE __attribute__((always_inline))
#else
#define MPC_ALWAYS_INLINE
#endif

/* The clamps of the basis as FX_SAT (fx.h): one SSAT each on a Cortex-M4. */
_Static_assert(CTRL_MPC_PSI_CLAMP == (q24_t)1 << 27, "FX_SAT(x, 28) is the psi0 clamp");
_Static_assert(CTRL_MPC_I_CLAMP == (q24_t)1 << 30, "FX_SAT(x, 31) is the current clamp");

/* The part of the basis common to ctrl_mpc_basis and ctrl_mpc_basis3:
 * d0, q0, t0 and Ts V1 = (w[0], w[1]), Ts V2 = (w[2], w[3]) in the rotor
 * frame at k+2 (inlined into both, one set of arithmetic). */
static inline MPC_ALWAYS_INLINE void mpc_basis_core(const ctrl_mpc_model_t *m,
                                                    const ctrl_estimate_t *est, q24_t *d0,
                                                    q24_t *q0, q24_t *t0, q24_t w[4])
{
    const ctrl_mstate_t *n = &est->next;
    /* (6.10) with a zero vector in the frame at k+1: psi(k+1) - Ts Rs i(k+1).
     * The clamps only act on states far outside any machine's range; they
     * give the fast arithmetic its bounds (ctrl_mpc_basis_t): |Ts Rs i| <=
     * 64 pu and |psi| <= 8 pu, the differences fit an int32_t. */
    const q24_t id = FX_SAT(n->i_d, 31);
    const q24_t iq = FX_SAT(n->i_q, 31);
    const q24_t fd = FX_SAT(n->psi_d, 28);
    const q24_t fq = FX_SAT(n->psi_q, 28);
    const q24_t ad = FX_SAT(fd - fx_mul_nosat(m->ts_rs, id), 28);
    const q24_t aq = FX_SAT(fq - fx_mul_nosat(m->ts_rs, iq), 28);
    /* The frame at k+2 is the frame at k+1 turned by delta = omega Ts (the
     * estimator's rotation, Q30, |.| <= 1): psi e^{-j delta}; |sum| < 2^34 2^30. */
    const int32_t rc = est->rot_c;
    const int32_t rs = est->rot_s;
    const q24_t d = fx_round_nosat((int64_t)ad * rc + (int64_t)aq * rs, 30u);
    const q24_t q = fx_round_nosat((int64_t)aq * rc - (int64_t)ad * rs, 30u);
    *d0 = d;
    *q0 = q;
    *t0 = ctrl_mpc_torque(m, d, q);
    /* theta(k+2) = theta(k+1) + delta: its cosine and sine from those at k+1. */
    const q24_t c = fx_round_nosat((int64_t)n->cos_theta * rc - (int64_t)n->sin_theta * rs, 30u);
    const q24_t s = fx_round_nosat((int64_t)n->sin_theta * rc + (int64_t)n->cos_theta * rs, 30u);
    /* Ts V1 = Ts 2/3 Vdc on alpha; in the rotor frame Ts|V| e^{-j th2}:
     * (mv c, -mv s). V2 = Ts|V| e^{j(pi/3 - th2)}: cos(th2 - pi/3) =
     * c/2 + s sqrt3/2, sin(th2 - pi/3) = s/2 - c sqrt3/2. */
    const q24_t mv = fx_mul_nosat(m->ts_v, fx_clamp(est->vdc, 0, m->vdc_max));
    const q24_t c1 = fx_dot_nosat(c, s, FX_Q24_HALF, FX_Q24_SQRT3_2);
    const q24_t s1 = fx_dot_nosat(s, -c, FX_Q24_HALF, FX_Q24_SQRT3_2);
    w[0] = fx_mul_nosat(mv, c);
    w[1] = -fx_mul_nosat(mv, s);
    w[2] = fx_mul_nosat(mv, c1);
    w[3] = -fx_mul_nosat(mv, s1);
}

void ctrl_mpc_basis(const ctrl_mpc_model_t *m, const ctrl_estimate_t *est, ctrl_mpc_basis_t *b)
{
    q24_t w[4];
    mpc_basis_core(m, est, &b->d0, &b->q0, &b->t0, w);
    const q24_t w0d = w[0];
    const q24_t w0q = w[1];
    const q24_t w1d = w[2];
    const q24_t w1q = w[3];
    /* V3 = V1 e^{j 2pi/3} = V2 - V1; V_{i+3} = -V_i. */
    const q24_t w2d = w1d - w0d;
    const q24_t w2q = w1q - w0q;
    b->wd[0] = w0d;
    b->wq[0] = w0q;
    b->wd[1] = w1d;
    b->wq[1] = w1q;
    b->wd[2] = w2d;
    b->wq[2] = w2q;
    b->wd[3] = -w0d;
    b->wq[3] = -w0q;
    b->wd[4] = -w1d;
    b->wq[4] = -w1q;
    b->wd[5] = -w2d;
    b->wq[5] = -w2q;
}

void ctrl_mpc_basis3(const ctrl_mpc_model_t *m, const ctrl_estimate_t *est, ctrl_mpc_basis3_t *b)
{
    q24_t w[4];
    mpc_basis_core(m, est, &b->d0, &b->q0, &b->t0, w);
    b->wd[0] = w[0];
    b->wq[0] = w[1];
    b->wd[1] = w[2];
    b->wq[1] = w[3];
    b->wd[2] = w[2] - w[0]; /* V3 = V2 - V1 */
    b->wq[2] = w[3] - w[1];
}

void ctrl_mpc_wreset(void *state)
{
    ctrl_mpc_wstate_t *s = state;
    s->trace.n = 0u;
    s->last_vec = 0u;
    s->flux.valid = 0u;
}

int32_t ctrl_mpc_psi_ref2(const ctrl_params_t *p, const ctrl_refs_t *ref)
{
    if (ref->psi > 0) {
        return ctrl_mpc_amp2(ref->psi, 0);
    }
    if (p->psi_ref > 0) {
        return ctrl_mpc_amp2(p->psi_ref, 0);
    }
    if (p->salient == 0u) {
        /* (4.15) squared, the argument of ctrl_mtpa_psi's fx_mag. */
        return ctrl_mpc_amp2(p->psi_pm, fx_mul(fx_abs(ref->torque), p->mtpa_k));
    }
    return ctrl_mpc_amp2(ctrl_mtpa_psi(p, ref->torque), 0); /* table, no square root */
}
