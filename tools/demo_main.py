#!/usr/bin/python3
"""./tools/demo: the controller comparison, from a fresh clone to out/report.md.

1. What it needs: the Debian packages of NEEDS (tools/setup installs them; as root the
   demo runs it, otherwise it names the one command and stops).
2. The builds, each with a progress bar (build steps done of all, elapsed, time left):
   the simulator (preset host-release) and the images ./tools/bench counts.
3. ./tools/bench for the decision table's cost columns (Cortex-M4 instructions per PWM
   interrupt, flash), or out/bench.json again when the images it counted are the ones
   built now (their fingerprint in out/bench.fingerprint).
4. The studies, every run through the study engine with its progress bar (runs done of
   all, time left): tools/compare.py (out/report.md, the decision table first),
   tools/filters.py, tools/fieldweak_studies.py, the tolerance study's small version.
5. The time of every step and the total.

usage: ./tools/demo [--seed N] [--jobs N] [--out DIR] [--rebench]
       (--seed, --jobs, --out go to every study; --rebench counts again)
"""
import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from argtypes import whole_in  # noqa: E402
from study_engine import MAX_JOBS  # noqa: E402  (--jobs goes to every study; standard library only)

# Debian packages (tools/setup's names) and what shows each is there.
NEEDS = (
    ("cmake", ("cmd", "cmake")), ("ninja-build", ("cmd", "ninja")),
    ("pkg-config", ("cmd", "pkg-config")), ("gcc", ("cmd", "gcc")), ("g++", ("cmd", "g++")),
    ("libinih-dev", ("pc", "inih")), ("libeigen3-dev", ("pc", "eigen3")),
    ("python3-numpy", ("py", "numpy")), ("python3-matplotlib", ("py", "matplotlib")),
    ("python3-dask", ("py", "dask")), ("python3-distributed", ("py", "distributed")),
    ("python3-tqdm", ("py", "tqdm")),
    # ./tools/bench: the Cortex-M4 images and QEMU
    ("gcc-arm-none-eabi", ("cmd", "arm-none-eabi-gcc")),
    ("libnewlib-arm-none-eabi", ("file", "/usr/lib/arm-none-eabi/newlib")),
    ("qemu-system-arm", ("cmd", "qemu-system-arm")),
)
SEED_MAX = 2 ** 53  # ./tools/sim --seed: a whole number a double holds exactly
BENCH_ARGS = ["--no-cm0", "--no-callgrind", "--reps", "3", "--hotspots", ""]
BENCH_BUILDS = (("host-release", ("bench_rec", "bench_host")), ("cm4", ("bench_cm4_all",)))


def have(kind, what):
    if kind == "cmd":
        return shutil.which(what) is not None
    if kind == "file":
        return os.path.exists(what)
    if kind == "pc":
        return subprocess.run(["pkg-config", "--exists", what]).returncode == 0 \
            if shutil.which("pkg-config") else False
    r = subprocess.run([sys.executable, "-c", "import " + what], capture_output=True)
    return r.returncode == 0


def missing_packages():
    return [pkg for pkg, (kind, what) in NEEDS if not have(kind, what)]


def set_up():
    """True when everything is there (installing it when root); else names the command."""
    miss = missing_packages()
    if not miss:
        return True
    cmd = ["./tools/setup"] + [p for p, _ in NEEDS]
    print("demo: missing: " + ", ".join(miss))
    if os.geteuid() == 0 and shutil.which("apt-get"):
        print("demo: installing them: " + " ".join(cmd), flush=True)
        if subprocess.run(cmd, cwd=ROOT).returncode == 0 and not missing_packages():
            return True
        print("demo: tools/setup did not install everything; see its output above")
        return False
    print("demo: install them with this one command, then run ./tools/demo again:\n"
          "    sudo " + " ".join(cmd))
    return False


def build(preset, targets):
    """Configure build/<preset> once and build the targets with a progress bar."""
    import build_progress
    bdir = os.path.join(ROOT, "build", preset)
    if not os.path.isfile(os.path.join(bdir, "build.ninja")):
        print(f"demo: configuring build/{preset} (cmake --preset {preset})", flush=True)
        r = subprocess.run(["cmake", "--preset", preset], cwd=ROOT, capture_output=True,
                           text=True)
        if r.returncode != 0:
            sys.exit("demo: cmake --preset %s failed:\n%s" % (
                preset, "\n".join((r.stdout + r.stderr).splitlines()[-15:])))
    os.makedirs(bdir, exist_ok=True)
    log = os.path.join(bdir, "demo-build.log")
    with open(log, "w") as f:
        rc, tail = build_progress.run_with_bar(
            ["cmake", "--build", bdir, "--target"] + list(targets),
            "demo: building %s (%s)" % (" ".join(targets), preset), out=sys.stdout, log=f)
    if rc != 0:
        sys.exit("demo: the build failed (log %s):\n%s" % (log, "\n".join(tail)))


def bench_fingerprint():
    """A hash of what ./tools/bench counts: the recorder and every Cortex-M4 image."""
    h = hashlib.sha256()
    files = [os.path.join(ROOT, "build", "host-release", "tests", "bench", "bench_fw",
                          "bench_rec")]
    cdir = os.path.join(ROOT, "build", "cm4", "tests", "bench", "bench_fw")
    if os.path.isdir(cdir):
        files += sorted(os.path.join(cdir, f) for f in os.listdir(cdir) if f.endswith(".elf"))
    for p in files:
        if not os.path.isfile(p):
            return None
        h.update(os.path.basename(p).encode())
        with open(p, "rb") as f:
            h.update(hashlib.sha256(f.read()).digest())
    return h.hexdigest()


def clock(s):
    s = int(round(s))
    return "%d min %02d s" % (s // 60, s % 60) if s >= 60 else "%d s" % s


def main():
    ap = argparse.ArgumentParser(prog="demo", description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=whole_in(0, SEED_MAX),
                    help="ADC noise seed of every run, [0, 2^53]")
    ap.add_argument("--jobs", type=whole_in(1, MAX_JOBS, "simulations at once"),
                    help="simulations at once, [1, %d]" % MAX_JOBS)
    ap.add_argument("--out", default=os.path.join(ROOT, "out"))
    ap.add_argument("--rebench", action="store_true",
                    help="count the interrupt again even when out/bench.json matches the build")
    a = ap.parse_args()  # every value checked before anything is built (exit status 2)
    if os.path.exists(a.out) and not os.path.isdir(a.out):
        ap.error("--out %s is a file: a folder is expected (created when missing)" % a.out)
    t0 = time.time()
    os.chdir(ROOT)
    if not set_up():
        return 2
    times = []

    def step(name, fn):
        t = time.time()
        print(f"\n=== demo: {name}", flush=True)
        fn()
        times.append((name, time.time() - t))

    step("builds", lambda: [build(p, t) for p, t in
                            (("host-release", ("pmsm_sim_cli",)),) + BENCH_BUILDS])
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    bjson, bfp = os.path.join(out, "bench.json"), os.path.join(out, "bench.fingerprint")

    def bench():
        fp = bench_fingerprint()
        old = open(bfp).read().strip() if os.path.exists(bfp) else None
        if fp is not None and fp == old and os.path.exists(bjson) and not a.rebench:
            print("demo: reusing out/bench.json: the images it counted are the ones built now "
                  "(--rebench counts again)")
            return
        if os.path.exists(bfp):
            os.remove(bfp)
        r = subprocess.run(["./tools/bench"] + BENCH_ARGS + ["--out", bjson])
        if r.returncode != 0:
            print("demo: ./tools/bench failed: the decision table's cost columns stay empty")
            return
        with open(bfp, "w") as f:
            f.write((fp or "") + "\n")

    step("./tools/bench (Cortex-M4 instructions per interrupt, flash)", bench)
    common = ["--out", out] + (["--seed", str(a.seed)] if a.seed is not None else []) + (
        ["--jobs", str(a.jobs)] if a.jobs is not None else [])
    studies = (
        ("the comparison, out/report.md", ["tools/compare.py"]),
        ("the book chapter's output filters, out/filters.md", ["tools/filters.py"]),
        ("field weakening, out/fieldweak.md", ["tools/fieldweak_studies.py"]),
        ("the tolerance study (small), out/tolerance.md",
         ["tools/study", "tools/studies/tolerance.toml", "--samples", "4"]),
    )
    failed = []
    for name, cmd in studies:
        def run(cmd=cmd, name=name):
            r = subprocess.run(["/usr/bin/python3"] + cmd + common)
            if r.returncode != 0:
                failed.append(name)
        step(name, run)
    total = time.time() - t0
    print("\n=== demo: times")
    for name, dt in times:
        print(f"  {clock(dt):>12}  {name}")
    print(f"  {clock(total):>12}  total")
    rep = os.path.relpath(os.path.join(out, "report.md"))
    if failed:
        print("demo: failed: " + "; ".join(failed))
        return 1
    print(f"demo: done in {clock(total)}; open {rep}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
