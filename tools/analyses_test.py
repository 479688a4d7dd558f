#!/usr/bin/python3
"""The mechanisms tools/analyses.py reports, checked on its reduced set (--short).

usage: analyses_test.py SIM_BINARY
  drr    DRR's flux step per period is a fixed part of the arc ω_e|ψs|Ts: halving
         Ts halves DRR's flux ripple (0.35..0.75 allowed around 0.5), the step/arc
         ratio is the same at 10 and 20 kHz and at 1.5 × Vdc (within 25 %); BST's
         ripple, bounded by its band plus a step of Vdc·Ts, grows with Vdc (> 1.1 ×).
  zeta   M1's D_f (5.18) cancels every unsaturated candidate's torque error, so at
         750 r/min and 220 V (no duty saturates) ζ cannot change a decision: the
         indices for ζ = 2, 25.5 and 149 are identical; at 70 V, where duties
         saturate, the flux-heavy ζ has the lower flux ripple and THD_I.
  hpdtc  HP-DTC's own ripple, on the dynamometer, is inside the book chapter's
         bound < 0.15 N*m p-p; the chapter's case (speed loop, 2500-line encoder)
         ripples more, and less with a fine encoder.
And tools/compare.py's report section and finding reasons built from them.
"""
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import analyses  # noqa: E402

SIM = None


class Mechanisms(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.r = analyses.run_analyses(SIM, 2, 1, short=True)

    def test_drr_flux_step_is_a_part_of_the_arc(self):
        d = self.r["drr"]["data"]
        psi, sa = d["psi_mwb"], d["step_over_arc"]
        for rpm in (750, 2250):
            half = psi[("drr Ts/2", rpm)] / psi[("drr", rpm)]
            self.assertTrue(0.35 <= half <= 0.75, (rpm, half))
            base = sa[("drr", rpm)]
            for v in ("drr Ts/2", "drr Vdc×1.5"):
                self.assertAlmostEqual(sa[(v, rpm)] / base, 1.0, delta=0.25, msg=(v, rpm))
            self.assertGreater(psi[("bst Vdc×1.5", rpm)] / psi[("bst", rpm)], 1.1, rpm)
        # the ripple grows with the arc (speed) for DRR
        self.assertGreater(psi[("drr", 2250)], 2.0 * psi[("drr", 750)])

    def test_m1_zeta_only_acts_on_saturated_duties(self):
        d = self.r["zeta"]["data"]
        z = analyses.ZETA_THD
        keys = ("thd_i_pct", "torque_ripple_nm", "flux_ripple_wb", "f_av_hz")
        first = d[("z", 750, z[0])]
        self.assertEqual(first["fault"], "none")
        self.assertEqual(first["saturated"], 0.0)
        for zz in z[1:]:
            for k in keys:
                self.assertEqual(d[("z", 750, zz)][k], first[k], (zz, k))
        lo, hi = d[("lowv", 750, z[0])], d[("lowv", 750, z[-1])]
        self.assertGreater(lo["saturated"], 0.0)
        self.assertLess(hi["flux_ripple_wb"], lo["flux_ripple_wb"])
        self.assertLess(hi["thd_i_pct"], lo["thd_i_pct"])

    def test_hpdtc_own_ripple_inside_the_bound(self):
        pp = self.r["hpdtc"]["data"]
        chapter = next(v for k, v in pp.items() if k.startswith("HP-DTC, the chapter's"))[0]
        dyn = next(v for k, v in pp.items() if k.startswith("HP-DTC on the dynamometer"))[0]
        enc = next(v for k, v in pp.items() if k.startswith("HP-DTC, encoder"))[0]
        self.assertLess(dyn, analyses.HPDTC_BOUND)
        self.assertLess(dyn, chapter)
        self.assertLess(enc, chapter)

    def test_report_embeds_them(self):
        import compare
        lines = compare.apply_analyses(self.r)
        text = "\n".join(lines)
        for h in ("## Analyses of three findings", "### DRR's flux ripple", "### M1's weight ζ",
                  "### HP-DTC's torque ripple"):
            self.assertIn(h, text)
        for k in (("drr", "flux"), ("m2ptfc", "thd_i_pct"), ("m2ptfc", "flux_ripple_wb"),
                  ("hpdtc", "pp")):
            self.assertIn("see Analyses of three findings", compare.REASON[k], k)
            self.assertNotIn("not analysed", compare.REASON[k], k)
        self.assertEqual(compare.apply_analyses(None)[0], "## Analyses of three findings\n")

    def test_texts_carry_numbers(self):
        for k, key in (("drr", "short"), ("zeta", "short_thd"), ("hpdtc", "short")):
            txt = self.r[k][key]
            self.assertRegex(txt, r"\d\.\d\d")
            self.assertNotIn("n/a", txt)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    SIM = sys.argv.pop(1)
    unittest.main(verbosity=2)
