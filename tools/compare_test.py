#!/usr/bin/python3
"""The report of tools/compare.py in its reduced configuration (--fast).

usage: compare_test.py SIM_BINARY
Runs compare.py --fast with the given simulator into a temporary folder and
checks the report: it opens with Findings (the sources' claims beside the
measurements, with verdicts; trips; steady-state errors), has the comparison
at equal switching frequency with a Pareto plot (a PNG whose name contains
"pareto") and a conclusion, marks the reversal n/a where it was never
commanded, and every image it links exists. HdtcPredCause checks the mechanism
the report gives for hdtc_pred's steady-state torque error (compare.py,
hdtc_pred_text) on two short runs.
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import decide  # noqa: E402  (the decision table's columns)
SIM = None


class ReportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        r = subprocess.run([sys.executable, os.path.join(HERE, "compare.py"), "--fast", "--sim",
                            SIM, "--out", cls.tmp.name], capture_output=True, text=True,
                           timeout=600)
        cls.rc, cls.out, cls.err = r.returncode, r.stdout, r.stderr
        path = os.path.join(cls.tmp.name, "report.md")
        cls.md = open(path).read() if os.path.exists(path) else ""

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_ran(self):
        self.assertEqual(self.rc, 0, self.err)
        self.assertTrue(self.md)

    def test_decision_table_first(self):
        """The report opens with the decision table: a row per controller with its best
        and worst column and a number (or n/a, trips) in every column, then the "use X
        for Y" sentences (tools/decide.py)."""
        h2 = re.findall(r"^## (.+)$", self.md, re.M)
        self.assertEqual(h2[0], "Which controller for which job")
        sec = self.md.split("## Which controller for which job", 1)[1].split("\n## ", 1)[0]
        for name in ("bst", "m2ptfc"):
            row = re.search(r"^\| %s \| (.+) \|$" % name, sec, re.M)
            self.assertIsNotNone(row, name)
            cells = [c.strip() for c in row.group(1).split(" | ")]
            self.assertEqual(len(cells), 2 + len(decide.COLUMNS), cells)
            self.assertRegex(cells[0], r"\((1st|2nd) of 2\)")
            for c in cells[2:]:
                self.assertRegex(c, r"^([0-9.]+|n/a|trips)$", row.group(0))
            # measured, not n/a: ripple, THD, step, |T_sse|, robustness, sensorless
            self.assertTrue(all(re.match(r"^[0-9.]+$", c) for c in cells[2:8]), cells)
        self.assertGreaterEqual(len(re.findall(r"^- Use \*\*(bst|m2ptfc)\*\* for ", sec, re.M)),
                                5)

    def test_findings_first(self):
        h2 = re.findall(r"^## (.+)$", self.md, re.M)
        self.assertGreater(len(h2), 3)
        self.assertEqual(h2[1], "Findings")
        rows = re.findall(r"^\| (.+?) \| (.+?) \| .+? \| .+? \| \*\*(reproduced|direction only|"
                          r"not reproduced)\*\* \| .+ \|$", self.md, re.M)
        self.assertGreaterEqual(len(rows), 10)
        self.assertIn("### Trips", self.md)
        self.assertIn("### Steady-state torque errors above 5 % of T_ref", self.md)

    def test_pareto(self):
        self.assertIn("## Comparison at equal switching frequency", self.md)
        links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", self.md)
        pareto = [p for p in links if "pareto" in p]
        self.assertTrue(pareto, links)
        for p in pareto:
            with open(os.path.join(self.tmp.name, p), "rb") as fh:
                self.assertEqual(fh.read(8), b"\x89PNG\r\n\x1a\n")
        self.assertRegex(self.md, r"\*\*Conclusion\.\*\* At 750 r/min and f_av = \d+ kHz the "
                                  r"lowest torque ripple is \w+'s")

    def test_images_exist(self):
        for p in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", self.md):
            self.assertTrue(os.path.isfile(os.path.join(self.tmp.name, p)), p)

    def test_lowspeed_sensorless(self):
        # the injection holds foc, m2ptfc and drr at 0 r/min: the angle error within
        # the work's bounds (5 deg rms, 15 deg at most), the torque within 5 % of the
        # reference and of the same controller with its encoder
        sec = self.md[self.md.find("## Low-speed sensorless"):]
        sec = sec[:sec.find("\n## ", 5)]
        rows = re.findall(r"^\| (foc|m2ptfc|drr) \| ([\d.]+) of ([\d.]+) \| ([\d.]+) \| .+? \| "
                          r"([\d.]+)° / ([\d.]+)° \| motion \|$", sec, re.M)
        self.assertEqual([r[0] for r in rows], ["foc", "m2ptfc", "drr"], sec)
        for c, t, ref, enc, rms, mx in rows:
            self.assertLessEqual(float(rms), 5.0, c)
            self.assertLessEqual(float(mx), 15.0, c)
            self.assertLessEqual(abs(float(t) - float(ref)), 0.05 * float(ref), c)
            self.assertLessEqual(abs(float(t) - float(enc)), 0.05 * float(ref), c)

    def test_reversal_not_commanded_is_na(self):
        # --fast runs the dynamic test for 40 ms: most controllers never reach
        # 1500 r/min, so their reversal indices must read n/a, not "no".
        sec = self.md[self.md.find("## Dynamic test"):]
        sec = sec[:sec.find("\n## ", 5)]
        rows = [[c.strip() for c in ln.strip("|").split("|")]
                for ln in sec.splitlines() if ln.startswith("| ") and not ln.startswith("| contr")]
        self.assertTrue(rows)
        na = [r for r in rows if r[3] == "n/a"]
        self.assertTrue(na, sec)
        for r in na:
            self.assertEqual((r[2], r[4], r[6], r[7]), ("n/a",) * 4, r)
        for r in rows:
            if r[3] != "n/a":
                self.assertIn(r[7], ("yes", "**no**"), r)


class PlotStyles(unittest.TestCase):
    """Every controller is told apart in every plot: no two share colour, line style and
    marker (the plots drew 21 series in four family colours; foc and hdtc_pred both
    solid red), and within a family no two share a colour, a line style or a marker."""

    def test_unique(self):
        sys.path.insert(0, HERE)
        import compare
        names = [n for _f, members in compare.FAMILIES for n in members]
        looks = {n: compare.style_of(n) for n in names}
        triples = {(s["color"], str(s["ls"]), s["marker"]) for s in looks.values()}
        self.assertEqual(len(triples), len(names))
        for _f, members in compare.FAMILIES:
            for key in ("color", "ls", "marker"):
                vals = [str(looks[n][key]) for n in members]
                self.assertEqual(len(set(vals)), len(vals), (key, members))


    def test_bars(self):
        """fieldweak_robust.png drew 20 bars in matplotlib's ten default colours (fst and
        m2ptfc alike): a bar takes its controller's colour and its family place's hatch."""
        sys.path.insert(0, HERE)
        import compare
        names = [n for _f, members in compare.FAMILIES for n in members]
        looks = {n: compare.bar_style(n) for n in names}
        self.assertEqual(len({(s["color"], s["hatch"]) for s in looks.values()}), len(names))
        for _f, members in compare.FAMILIES:
            self.assertEqual(len({looks[n]["hatch"] for n in members}), len(members))
        # the robustness plot draws with them
        import fieldweak_studies as fws
        ctrls = [n for n in names if n not in ("foc", "foc_hyst", "hdtc", "svm_dtc", "hpdtc",
                                               "hdtc_pred")]
        res = {(case, c, rpm): {"torque_ripple_nm": 0.1, "rc": 0, "fault": "none",
                                "torque_sse_nm": 0.0}
               for case, _ in fws.ROBUST_CASES for c in ctrls for rpm in fws.SPEEDS}
        self.assertTrue(all(fws.ok(m) for m in res.values()))
        figs = []
        subplots = fws.plt.subplots

        def keep(*a, **kw):
            fig, ax = subplots(*a, **kw)
            figs.append(fig)
            return fig, ax
        fws.plt.subplots = keep
        try:
            with tempfile.TemporaryDirectory() as tmp:
                fws.plot_robust(res, ctrls, tmp)
        finally:
            fws.plt.subplots = subplots
        for ax in figs[0].axes:
            bars = [c.get_label() for c in ax.containers]
            for c in ax.containers:
                p0 = c.patches[0]
                self.assertEqual((matplotlib_hex(p0.get_facecolor()), p0.get_hatch() or ""),
                                 (looks[c.get_label()]["color"], looks[c.get_label()]["hatch"]))
            self.assertEqual(sorted(bars), sorted(ctrls))
        fws.plt.close(figs[0])

    def test_time_series_draw_the_whole_look(self):
        """dynamic.png and dynamic_zoom.png: every controller's line has its colour, line
        style and a marker (foc and hdtc_pred were both solid red; six thin dashes of one
        colour in a panel were hard to tell apart), no two alike in a panel."""
        sys.path.insert(0, HERE)
        import numpy as np
        import compare
        names = [n for _f, members in compare.FAMILIES for n in members]
        t = np.linspace(0.0, compare.DYN_DURATION, 4000)
        dyn = {n: ({"t": t, "torque": np.sin(t * (k + 1)), "speed_rpm": t * 1e4,
                    "torque_ref": t}, {"t_rev": 0.05 if k % 2 else None})
               for k, n in enumerate(names)}
        figs = []
        subplots = compare.plt.subplots

        def keep(*a, **kw):
            fig, ax = subplots(*a, **kw)
            figs.append(fig)
            return fig, ax
        compare.plt.subplots = keep
        try:
            with tempfile.TemporaryDirectory() as tmp:
                compare.plot_dynamic(dyn, tmp)
                self.assertTrue(os.path.exists(os.path.join(tmp, "dynamic_zoom.png")))
        finally:
            compare.plt.subplots = subplots
        self.assertEqual(len(figs), 2)
        for fig in figs:
            for ax in fig.axes:
                looks = []
                for ln in ax.get_lines():
                    name = ln.get_label().split(" ")[0]
                    if name not in names:
                        continue
                    st = compare.style_of(name)
                    self.assertEqual(matplotlib_hex(ln.get_color()), st["color"], name)
                    self.assertEqual(ln.get_marker(), st["marker"], name)
                    self.assertIsNotNone(ln.get_markevery(), name)
                    looks.append((ln.get_color(), str(ln.get_dashes() if hasattr(ln, "get_dashes")
                                                      else ln.get_linestyle()), ln.get_marker()))
                self.assertEqual(len(set(looks)), len(looks), ax.get_title())
            compare.plt.close(fig)


def matplotlib_hex(c):
    import matplotlib.colors
    return matplotlib.colors.to_hex(c)


class BadInput(unittest.TestCase):
    """Each exits 2 naming option, value and range before a run starts (--jobs 0 ran the
    whole comparison on the CPU count, an unknown controller exited 1)."""

    def test_each(self):
        with tempfile.TemporaryDirectory() as tmp:
            for args, want in (
                    (["--jobs", "0"], "--jobs: '0' is out of range: allowed a whole number in "
                     "[1, 1024] workers"),
                    (["--seed", "-1"], "--seed -1 is out of range: allowed [0, 2^53]"),
                    (["--settle", "0.5"], "--settle 0.5, --duration 0.3 s: allowed 0 <= settle "
                     "< duration <= 10 s"),
                    (["--controllers", "nosuch,bst"], "--controllers: unknown nosuch (allowed: "
                     "bst, ")):
                r = subprocess.run([sys.executable, os.path.join(HERE, "compare.py"), "--sim",
                                    SIM, "--out", tmp] + args, capture_output=True, text=True,
                                   timeout=60)
                self.assertEqual(r.returncode, 2, (args, r.stderr))
                self.assertIn(want, r.stderr, args)
                # nothing run: no runs, no report (the engine's store may be opened first)
                self.assertEqual(set(os.listdir(tmp)) - {"runs.sqlite"}, set(), args)


class HdtcPredCause(unittest.TestCase):
    """hdtc_pred (thesis SPMSM, 1.8 N*m, 10 kHz): one period's torque steps
    dwarf S1's band, so the three-level regulator goes from +1 straight to -1 and
    the mean torque stays below T_ref. Were the regulator to hold 0 between +1
    and -1 as it does in continuous time, the zero vector would fill the share
    dTa / (dTa + |dT0|) of the periods of its +1/0 limit cycle; the report's
    cause holds while it fills less than a tenth of that and T_sse exceeds the
    report's 5 % threshold."""

    def test_mechanism(self):
        sys.path.insert(0, HERE)
        import compare
        for rpm in (750, 2250):
            d_ta, d_t0, _, _, _ = compare.table_steps(rpm, 10000.0)
            self.assertGreater(min(d_ta, d_t0), 10 * 0.02)  # S1 sec. 3.3: 2 h_T = 0.02 N*m
            with tempfile.TemporaryDirectory() as tmp:
                tr, mj = os.path.join(tmp, "t.csv"), os.path.join(tmp, "m.json")
                r = subprocess.run([SIM, "--machine", compare.MACHINE, "--controller",
                                    "hdtc_pred", "--speed-rpm", str(rpm), "--torque-ref",
                                    str(compare.LOAD_NM), "--duration", "0.3", "--window",
                                    "0.15:0.3", "--trace", tr, "--trace-window", "0.15:0.3",
                                    "--trace-decimation", "10", "--metrics", mj],
                                   capture_output=True, text=True, timeout=300)
                self.assertEqual(r.returncode, 0, r.stderr)
                with open(tr) as fh:
                    vec = [row["vec"] for row in csv.DictReader(fh)]  # one row per period
                with open(mj) as fh:
                    sse = json.load(fh)["torque_sse_nm"]
            zero = sum(v in ("0", "7") for v in vec) / len(vec)
            self.assertGreater(len(vec), 1000)
            self.assertLess(zero, 0.1 * d_ta / (d_ta + d_t0), rpm)
            self.assertGreater(sse, 0.05 * compare.LOAD_NM, rpm)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: compare_test.py SIM_BINARY")
    SIM = sys.argv.pop(1)
    unittest.main(verbosity=2)
