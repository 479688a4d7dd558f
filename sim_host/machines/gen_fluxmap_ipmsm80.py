#!/usr/bin/python3
"""Generate ipmsm_80kw_fluxmap_synthetic.csv: a SYNTHETIC saturation map for the
thesis 80 kW IPMSM (Table 3.1). NOT FEA data: the thesis' FEA maps (Fig. 3.4)
are not available, so a simple, separable, monotone saturation law is used:

    psi_d(id, iq) = psi_pm + Ld * id / sqrt(1 + (id / Id_s)^2),  Id_s = 1000 A
    psi_q(id, iq) = Lq * iq / sqrt(1 + (iq / Iq_s)^2),           Iq_s = 600 A

with Ld = 0.6 mH, Lq = 1.33 mH, psi_pm = 0.1875 Wb. It reduces to the linear
model (3.9) at small currents; at iq = 400 A the q-axis apparent inductance is
17 % lower. No cross-saturation and no rotor-angle dependence (theta_r = 0 in
(3.11)). Grid: id, iq in [-600, 600] A, step 40 A (the thesis' FEA used 40 A).
"""
import math
import os

LD, LQ, PSI_PM = 0.6e-3, 1.33e-3, 0.1875
ID_S, IQ_S = 1000.0, 600.0


def psi(i_d, i_q):
    return (PSI_PM + LD * i_d / math.sqrt(1.0 + (i_d / ID_S) ** 2),
            LQ * i_q / math.sqrt(1.0 + (i_q / IQ_S) ** 2))


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "ipmsm_80kw_fluxmap_synthetic.csv")
    with open(out, "w") as f:
        f.write("# SYNTHETIC flux map (not FEA): see gen_fluxmap_ipmsm80.py\n")
        f.write("id_a,iq_a,psi_d_wb,psi_q_wb\n")
        for kd in range(31):
            i_d = -600.0 + 40.0 * kd
            for kq in range(31):
                i_q = -600.0 + 40.0 * kq
                pd, pq = psi(i_d, i_q)
                f.write(f"{i_d:.1f},{i_q:.1f},{pd:.12g},{pq:.12g}\n")


if __name__ == "__main__":
    main()
