#!/usr/bin/python3
"""Generate ipmsm_80kw_fluxmap_magsat_synthetic.csv: a SYNTHETIC saturation map
of the thesis 80 kW IPMSM (Table 3.1) whose d axis saturates with the magnet's
flux. NOT FEA data (as gen_fluxmap_ipmsm80.py's map), a simple law with the
mechanism that map leaves out: the d-axis iron carries the magnet's flux and
the armature's together, so it saturates with their sum,

    psi_d(id, iq) = Psi_s tanh((Psi_m0 + Ld0 id) / Psi_s),   Psi_s = 0.6 Wb
    psi_q(id, iq) = Lq iq / sqrt(1 + (iq / Iq_s)^2),            Iq_s = 600 A

with Psi_m0 and Ld0 chosen so that the map keeps the machine's data at id = 0:
psi_d(0) = psi_pm = 0.1875 Wb and d psi_d / d id (0) = Ld = 0.6 mH (Lq = 1.33 mH
as in gen_fluxmap_ipmsm80.py). A current towards north (id > 0) meets more
saturated iron than one towards south: the same volt-seconds (0.24 V*s, the rated
current through Ld) drive +513 A along +d and -371 A along -d, the asymmetry
the polarity pulses read (docs/algorithms.md, "High-frequency injection").
gen_fluxmap_ipmsm80.py's psi_d - psi_pm is odd in id (saturation about id = 0,
not about the magnet's working point): the same current either way, no polarity
to read. No cross-saturation, no rotor-angle dependence. Grid as that map's:
id, iq in [-600, 600] A, step 40 A.
"""
import math
import os

LD, LQ, PSI_PM = 0.6e-3, 1.33e-3, 0.1875
PSI_S, IQ_S = 0.6, 600.0
# psi_d(0) = PSI_PM and the slope Ld there: tanh(x0) = PSI_PM / PSI_S,
# Ld0 (1 - tanh(x0)^2) = LD
PSI_M0 = PSI_S * math.atanh(PSI_PM / PSI_S)
LD0 = LD / (1.0 - (PSI_PM / PSI_S) ** 2)


def psi(i_d, i_q):
    return (PSI_S * math.tanh((PSI_M0 + LD0 * i_d) / PSI_S),
            LQ * i_q / math.sqrt(1.0 + (i_q / IQ_S) ** 2))


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "ipmsm_80kw_fluxmap_magsat_synthetic.csv")
    with open(out, "w") as f:
        f.write("# SYNTHETIC flux map (not FEA), d axis saturating with the magnet's flux: "
                "see gen_fluxmap_ipmsm80_magsat.py\n")
        f.write("id_a,iq_a,psi_d_wb,psi_q_wb\n")
        for kd in range(31):
            i_d = -600.0 + 40.0 * kd
            for kq in range(31):
                i_q = -600.0 + 40.0 * kq
                pd, pq = psi(i_d, i_q)
                f.write(f"{i_d:.1f},{i_q:.1f},{pd:.12g},{pq:.12g}\n")


if __name__ == "__main__":
    main()
