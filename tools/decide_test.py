#!/usr/bin/python3
"""tools/decide.py on numbers written here: the table's cells, the best and worst
columns, and the "use X for Y" sentences follow from the numbers (change a number and
the sentence changes), ties within 5 % are named, a trip counts as the worst and is
never the all-round choice, and a missing bench says so instead of a number."""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import decide  # noqa: E402

SPEEDS = (750, 2250)


def fake(ripple, thd, rise, sse, robust_worst, sens, cpu, flash, tun, trips=()):
    """results, fav, dyn, bench, tunables of one controller for decide.values;
    robust_worst: the largest shift of the mean torque (% of T_ref) of the six cases."""
    res = {}
    t_nom = decide.T_REF * (1 - sse / 100)
    for r in SPEEDS:
        res[("steady", r)] = {"m": {"fault": "none", "torque_sse_nm": sse / 100 * decide.T_REF,
                                    "torque_mean_nm": t_nom}}
    for i, (case, _) in enumerate(decide.ROBUST_CASES):
        if case in trips:
            m = {"fault": "overcurrent", "torque_mean_nm": None}
        else:
            e = robust_worst if case == "ψpm −20 %" else robust_worst / 2
            sign = 1 if i % 2 else -1
            m = {"fault": "none", "torque_mean_nm": t_nom + sign * e / 100 * decide.T_REF}
        res[("robust", case)] = {"m": m}
    res[("sensorless",)] = {"m": {"fault": "none", "est_angle_err_rms_deg": sens}}
    return {"res": res, "fav": {"torque_ripple_nm": ripple, "thd_i_pct": thd},
            "dyn": ({}, {"rise_ms": rise}), "bench": {"cm4_instr_mean": cpu,
                                                      "cm4_instr_max": cpu * 1.1,
                                                      "flash_bytes": flash},
            "tun": tun}


def inputs(ctrls, bench=True):
    results, dyn, b, tun = {}, {}, {}, {}
    for n, c in ctrls.items():
        for k, v in c["res"].items():
            results[(k[0], n) + k[1:]] = v
        dyn[n] = c["dyn"]
        b[n] = c["bench"]
        tun[n] = c["tun"]

    def fav(n, rpm, key):
        return ctrls[n]["fav"][key]
    return list(ctrls), results, SPEEDS, fav, dyn, (b if bench else None), tun


class DecideTest(unittest.TestCase):
    def ctrls(self):
        return {
            "a": fake(0.10, 5.0, 0.30, 1.0, 4.0, 0.5, 1500, 5000, 6),
            "b": fake(0.20, 3.0, 0.20, 2.0, 3.0, 2.0, 1200, 3000, 2),
            "c": fake(0.30, 9.0, 0.25, 0.5, 9.0, 9.0, 1900, 8000, 9, trips=("ψpm −20 %",)),
            "d": fake(0.104, 6.0, 0.35, 1.5, 5.0, 1.0, 1600, 5500, 5),
        }

    def section(self, ctrls, bench=True):
        lines, val = decide.section(*inputs(ctrls, bench))
        return "\n".join(lines), val

    def test_cells_and_ranks(self):
        text, val = self.section(self.ctrls())
        self.assertAlmostEqual(val["a"]["ripple"], 0.10)
        self.assertAlmostEqual(val["a"]["sse"], 1.0)
        self.assertAlmostEqual(val["a"]["robust"], 4.0)  # the largest shift of the six
        self.assertEqual(val["c"]["robust"], math.inf)  # a trip is the worst
        self.assertIn("| c | ", text)
        row_b = next(ln for ln in text.splitlines() if ln.startswith("| b |"))
        self.assertIn("current THD (1st of 4)", row_b)  # its best column
        self.assertIn("mean-torque accuracy (4th of 4)", row_b)  # its worst
        row_c = next(ln for ln in text.splitlines() if ln.startswith("| c |"))
        self.assertIn("| trips |", row_c)

    def test_sentences_follow_the_numbers(self):
        text, _ = self.section(self.ctrls())
        self.assertIn("Use **a** for the lowest torque ripple at equal switching frequency: "
                      "0.100 N·m", text)
        self.assertIn("(within 5 %: d)", text)  # 0.104 is within 5 % of 0.100
        self.assertIn("Use **b** for the fastest torque step: 0.20 ms", text)
        self.assertIn("Use **c** for the most accurate mean torque: 0.5 %", text)
        self.assertIn("Use **b** for holding the torque when the machine's parameters are "
                      "20 % off", text)  # c's 0 % trips: it cannot win
        ctrls = self.ctrls()
        ctrls["c"] = fake(0.09, 9.0, 0.25, 0.5, 9.0, 9.0, 1900, 8000, 9,
                          trips=("ψpm −20 %",))
        text, _ = self.section(ctrls)
        self.assertIn("Use **c** for the lowest torque ripple", text)  # the number moved it

    def test_all_round_choice(self):
        text, _ = self.section(self.ctrls())
        # over the six quality columns: a 1st, 3rd, 3rd, 2nd, 2nd, 1st of 4 -> mean 0.25;
        # b 2nd, 1st, 1st, 4th (its worst third), ...; c trips; d 2nd or 3rd everywhere
        line = next(ln for ln in text.splitlines() if "all-round choice" in ln)
        self.assertIn("Use **a** as the all-round choice", line)
        self.assertIn("1500 instructions per period, 5000 B of flash", line)
        ctrls = self.ctrls()
        ctrls["a"] = fake(0.10, 5.0, 0.30, 1.0, 4.0, 0.5, 1500, 5000, 6, trips=("Rs +20 %",))
        text, _ = self.section(ctrls)
        # a trips now, b, c and d each have a worst-third column: no all-round choice
        self.assertNotIn("all-round choice", text)
        ctrls["d"] = fake(0.104, 6.0, 0.28, 1.5, 5.0, 1.0, 1600, 5500, 5)
        text, _ = self.section(ctrls)  # d's step moves out of the worst third
        self.assertIn("Use **d** as the all-round choice", text)

    def test_wrong_mean_torque_is_recommended_for_nothing(self):
        ctrls = self.ctrls()
        ctrls["e"] = fake(0.05, 1.0, 0.10, 10.0, 0.1, 0.1, 900, 1000, 1)  # T_sse 10 %
        text, _ = self.section(ctrls)
        self.assertIn("| e | ", text)  # in the table, with its numbers
        self.assertIn("; not e.", text)
        self.assertNotIn("**e**", text)
        self.assertIn("Use **a** for the lowest torque ripple", text)

    def test_missing_bench_is_said(self):
        text, val = self.section(self.ctrls(), bench=False)
        self.assertIn("not measured: run ./tools/bench", text)
        self.assertIsNone(val["a"]["cpu_mean"])
        self.assertNotIn("Use **b** for the least flash", text)


if __name__ == "__main__":
    unittest.main(verbosity=2)
