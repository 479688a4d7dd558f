#!/usr/bin/python3
"""The study engine on a real dask cluster (ctest study_cluster).

usage: study_cluster_test.py SIM

On loopback, with free ports: a `dask scheduler` and two `dask worker` processes
(one thread each, no nanny, each in its own session). The 40-run study
cluster40.toml runs first serially in this process (--serial: the reference),
then through the scheduler; once some results are stored, the worker that is
running a simulation is killed (SIGKILL to its whole process group, the
simulator with it). Checks:
  * the study completes (exit 0) on the surviving worker;
  * every run's result is present exactly once and equal, byte for byte, to the
    serial run's (exit status, stderr, metrics), and so is the study's table;
  * a run that was on the killed worker was re-executed by the other one;
  * a second invocation computes nothing (every result from the store) and
    changes no row.
Every wait is on progress, not on a wall-clock budget: a study is given up only
when no new result (nor output) has come for STALL_S - a stuck study, whatever
the machine's speed or load; a slow one keeps its time. Every process started here
is stopped in a finally clause; the scheduler and the workers also end by
themselves if this script dies (the kernel's parent-death signal, the workers'
--death-timeout, the scheduler's --idle-timeout).
"""
import ctypes
import os
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
import zlib

from study_testutil import STALL_S, free_port, stored, watch

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
STUDY = os.path.join(ROOT, "tools", "study")
SPEC = os.path.join(HERE, "cluster40.toml")
N_RUNS = 40
KILL_AFTER = 6  # stored results before the kill: the study is under way
PY = "/usr/bin/python3"


def die_with_parent():
    """In the child before exec: SIGKILL when this test process dies (Linux)."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


class Procs:
    """The processes of this test, each a session of its own; stop() ends them all."""

    def __init__(self, tmp):
        self.tmp, self.procs = tmp, {}

    def start(self, name, argv, env=None):
        log = open(os.path.join(self.tmp, f"{name}.log"), "w")
        p = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                             start_new_session=True, preexec_fn=die_with_parent,
                             env=env, cwd=self.tmp)
        self.procs[name] = (p, log)
        return p

    def kill(self, name):
        p, log = self.procs[name]
        if p.poll() is None:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        p.wait()
        log.close()

    def path(self, name):
        return os.path.join(self.tmp, f"{name}.log")

    def log(self, name):
        with open(self.path(name)) as f:
            return f.read()

    def stop(self):
        for name in list(self.procs):
            self.kill(name)


def rows(store):
    db = sqlite3.connect(store)
    try:
        return {k: (rc, err, zlib.decompress(outs), worker) for k, rc, err, outs, worker in
                db.execute("SELECT key, rc, stderr, outputs, worker FROM runs")}
    finally:
        db.close()


def verdict(rc, took):
    return (f"exit {rc}, {took:.0f} s" if rc is not None else
            f"stuck: no new result nor output for {STALL_S} s, killed after {took:.0f} s")


def main():
    sim = os.path.abspath(sys.argv[1])
    dask = shutil.which("dask") or "/usr/bin/dask"
    t_start = time.monotonic()
    fails = []

    def check(cond, what):
        print(("ok   " if cond else "FAIL ") + what, flush=True)
        if not cond:
            fails.append(what)

    tmp = tempfile.mkdtemp(prefix="study-cluster-")
    procs = Procs(tmp)
    client = None

    def study(name, out, *extra, on_progress=None):
        """tools/study on SPEC into out (its store out/runs.sqlite), watched."""
        store = os.path.join(out, "runs.sqlite")
        os.makedirs(out, exist_ok=True)
        p = procs.start(name, [PY, STUDY, SPEC, "--sim", sim, "--out", out, "--progress", "text",
                               "--store", store] + list(extra))
        rc, took = watch(p, store, [procs.path(name)], on_progress)
        procs.kill(name)  # if it was stuck
        return rc, took, procs.log(name)

    try:
        # -- the serial reference
        rc, took, log = study("serial", os.path.join(tmp, "serial"), "--serial")
        check(rc == 0, f"serial run: {verdict(rc, took)}" + (f" {log[-400:]}" if rc else ""))
        ref_rows = rows(os.path.join(tmp, "serial", "runs.sqlite"))
        check(len(ref_rows) == N_RUNS, f"serial run stores {N_RUNS} results ({len(ref_rows)})")

        # -- the cluster: scheduler, two workers
        for attempt in range(3):
            port = free_port()
            addr = f"tcp://127.0.0.1:{port}"
            sch = procs.start("scheduler", [dask, "scheduler", "--host", "127.0.0.1", "--port",
                                            str(port), "--no-dashboard", "--idle-timeout",
                                            f"{2 * STALL_S}s"])
            up, t0 = False, time.monotonic()
            while sch.poll() is None and time.monotonic() - t0 < STALL_S:
                try:
                    socket.create_connection(("127.0.0.1", port), timeout=1).close()
                    up = True
                    break
                except OSError:
                    time.sleep(0.1)
            if up:
                break
            procs.kill("scheduler")  # the port was taken meanwhile: another one
        check(up, f"dask scheduler listening at {addr}")
        if not up:
            raise RuntimeError(procs.log("scheduler"))
        for w in ("w1", "w2"):
            procs.start(w, [dask, "worker", addr, "--nthreads", "1", "--no-nanny", "--name", w,
                            "--no-dashboard", "--death-timeout", str(STALL_S),
                            "--local-directory", os.path.join(tmp, w)])
        from distributed import Client
        client = Client(addr, timeout=STALL_S, set_as_default=False)
        client.wait_for_workers(2, timeout=STALL_S)
        names = {v["name"]: k for k, v in client.scheduler_info()["workers"].items()}
        check(set(names) == {"w1", "w2"}, f"two workers registered ({sorted(names)})")

        # -- the study on the cluster, one worker killed mid-run
        out = os.path.join(tmp, "cluster")
        store = os.path.join(out, "runs.sqlite")
        kill = {"victim": None, "in_flight": set(), "at": N_RUNS}

        def kill_one(n):
            """Once KILL_AFTER results are stored: SIGKILL the worker running a task."""
            if kill["victim"] is not None or n < KILL_AFTER:
                return
            proc = client.processing()
            busy = [w for w in ("w1", "w2") if proc.get(names[w])]
            if busy:
                victim = busy[0]
                # its tasks, each a chunk of runs named by its first run's key
                kill["in_flight"] = {k[len("pmsm-runs-"):].rsplit("-", 1)[0]
                                     for k in proc[names[victim]]}
                kill["at"] = stored(store)
                procs.kill(victim)
                kill["victim"] = victim
                print(f"     killed {victim} ({names[victim]}) after {kill['at']} results, "
                      f"running {len(kill['in_flight'])} run(s)", flush=True)

        rc, took, log = study("study", out, "--scheduler", addr, on_progress=kill_one)
        victim, in_flight = kill["victim"], kill["in_flight"]
        check(victim is not None and kill["at"] < N_RUNS, "a worker was killed while the study ran")
        check(rc == 0, f"the study completes on the other worker ({verdict(rc, took)})"
                       + (f" {log[-600:]}" if rc else ""))
        got = rows(store)
        check(len(got) == N_RUNS and set(got) == set(ref_rows),
              f"every run stored once ({len(got)} rows, {len(set(got) & set(ref_rows))} of the "
              f"serial run's keys)")
        same = [k for k in ref_rows if k in got and got[k][:3] == ref_rows[k][:3]]
        check(len(same) == N_RUNS, f"every result equals the serial run's byte for byte "
                                   f"({len(same)} of {N_RUNS})")
        tables = [os.path.join(d, "cluster40.csv") for d in (os.path.join(tmp, "serial"), out)]
        if all(os.path.exists(t) for t in tables):
            t_ref, t_got = (open(t, "rb").read() for t in tables)
            check(t_ref == t_got, f"the study's table equals the serial run's ({len(t_got)} bytes)")
        else:
            check(False, "the study's table equals the serial run's (a table is missing)")
        survivor = names["w2" if victim == "w1" else "w1"]
        redone = [k for k in in_flight if k in got and got[k][3] == survivor]
        check(bool(redone), f"a run that was on the killed worker was re-executed on the "
                            f"other ({len(redone)} of {len(in_flight)})")
        by = {w: sum(1 for r in got.values() if r[3] == names[w]) for w in ("w1", "w2")}
        check(all(by.values()) and sum(by.values()) == N_RUNS,
              f"both workers computed runs, nothing else did ({by})")

        # -- a second invocation computes nothing
        rc, took, log = study("again", out, "--scheduler", addr)
        check(rc == 0, f"second invocation: {verdict(rc, took)}" + (f" {log[-400:]}" if rc else ""))
        check(f"{N_RUNS} runs: 0 computed" in log and f"{N_RUNS} from the store" in log,
              "second invocation computes nothing: " +
              next((ln for ln in log.splitlines() if "computed" in ln), "?"))
        check(rows(store) == got, "and changes no row")
    finally:
        if client is not None:
            client.close()
        procs.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"study_cluster_test: {len(fails)} failure(s) in {time.monotonic() - t_start:.0f} s")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
