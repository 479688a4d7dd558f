"""The study engine: runs of the host simulator on dask.distributed, each result
stored as it arrives, keyed by the run's full description.

Every tool that runs many simulations (tools/compare.py, analyses.py, filters.py,
fieldweak_studies.py, torque_sweep.py, the declarative studies of tools/study) goes
through it:

    with study_engine.Engine.from_args(args, out_dir, "compare") as eng:
        res = eng.run({key: study_engine.Run(build, sim_args, outputs=("metrics",))})
        res[key].metrics        # the simulator's --metrics JSON, or None

A run is a simulator command line. Input files (--machine, --control-machine,
--scenario, --replay, and a machine file's [fluxmap] file) travel by content;
outputs (--metrics, --trace) are added by the engine and come back as text. Its
key is the sha256 of the canonical description: the simulator build (sha256 of
the binary), the arguments, every input's name and content, the outputs asked
for. So:
  * the store (SQLite, one row per run, committed as each result arrives) is
    asked first: a rerun computes only what is missing, a killed client loses
    nothing stored, a rebuilt simulator (another build) recomputes everything;
  * the runs execute on a dask.distributed cluster: a local one in this process
    by default (--jobs workers, no set-up), or an existing one (--scheduler
    tcp://HOST:PORT, docs/studies.md); a worker that dies mid-run has its runs
    re-executed by the scheduler on another;
  * a result is the simulator's exit status, stderr and output files, which
    depend on the description only: the same study gives the same table bit for
    bit whatever the number of workers and the order they finish in.
A run the simulator refuses, that faults (trips) or fails is a result with its
reason (Result.status, Result.reason), stored like any other. What is not the
run's own doing - a lost worker, no simulator of that build on a worker, a
time-out - is reported and not stored, so the next invocation tries again.
"""
import argparse
import hashlib
import json
import logging
import os
import re
import sqlite3
import sys
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import study_worker  # noqa: E402
from argtypes import whole_in  # noqa: E402

ROOT = os.path.dirname(HERE)
DESCRIPTION_VERSION = 1  # part of every key: bump when the meaning of a description changes
# Options whose value is an input file (shipped by content) and the name it has on
# the worker; outputs the engine adds and brings back.
INPUT_OPTS = {"--machine": "machine", "--control-machine": "control", "--scenario": "scenario",
              "--replay": "replay"}
OUTPUT_OPTS = {"metrics": ("--metrics", "out/metrics.json"),
               "trace": ("--trace", "out/trace.csv")}
PROGRESS_ENV = "PMSM_STUDY_PROGRESS"  # auto | bar | text | none: the default of --progress
SCHEDULER_RE = re.compile(r"^(tcp|tls)://([^:/\s]+|\[[0-9a-fA-F:]+\]):(\d{1,5})$")


class StudyInputError(Exception):
    """Bad input to a study (file, value, address): the tools exit with status 2."""


# ---------------------------------------------------------------- the simulator build

class Build:
    """A simulator binary and its identity (sha256 of the file)."""

    def __init__(self, path):
        self.path = os.path.abspath(path)
        if not os.access(self.path, os.X_OK):
            raise StudyInputError(f"simulator {self.path}: not an executable file")
        self.sha = study_worker.file_sha256(self.path)

    def __repr__(self):
        return f"Build({self.path}, {self.sha[:12]})"


def tools_sim(tool):
    """./tools/sim --list-controllers, which builds the host-release simulator when it
    is stale: (the simulator it built, its controller list: a line each, name TAB
    default rate TAB ...). Exits naming tool when tools/sim fails."""
    import subprocess
    r = subprocess.run([os.path.join(ROOT, "tools", "sim"), "--list-controllers"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{tool}: tools/sim failed:\n{r.stderr}")
    # where tools/sim builds it
    bdir = os.environ.get("PMSM_SIM_BUILD_DIR", os.path.join(ROOT, "build", "host-release"))
    return os.path.join(bdir, "firmware", "sim"), r.stdout


def default_build():
    """The simulator: $PMSM_SIM_EXE, else ./tools/sim's (host-release, built if needed)."""
    exe = os.environ.get("PMSM_SIM_EXE")
    if not exe:
        exe, _listing = tools_sim("study")
    return Build(exe)


# ---------------------------------------------------------------- run descriptions

class Text:
    """An input file given by its content (a generated machine file): name is its
    file name on the worker; a relative [fluxmap] file is looked up in base_dir."""

    def __init__(self, name, content, base_dir=None):
        if os.sep in name or name in ("", ".", ".."):
            raise ValueError(f"input name {name!r}: a plain file name")
        self.name = name
        self.data = content.encode() if isinstance(content, str) else bytes(content)
        self.base_dir = base_dir


def _ini_deps(data, base_dir):
    """Files a machine file names ([fluxmap] file): (path as written, content or None
    when it cannot be read: the simulator then says so)."""
    deps, sec = [], None
    for ln in data.decode("utf-8", "replace").splitlines():
        s = ln.split(";")[0].split("#")[0].strip()
        if s.startswith("["):
            sec = s.strip("[]").strip()
        elif sec == "fluxmap" and "=" in s and s.split("=")[0].strip() == "file":
            rel = s.split("=", 1)[1].strip()
            try:
                with open(os.path.join(base_dir or "", rel), "rb") as f:
                    deps.append((rel, f.read()))
            except OSError:
                deps.append((rel, None))
    return deps


class Run:
    """One simulator run: build, arguments (strings, numbers; the value of an option
    of INPUT_OPTS is a path or a Text), the outputs to bring back (names of
    OUTPUT_OPTS). tag names the run in messages (not part of its key)."""

    def __init__(self, build, args, outputs=("metrics",), tag=None, timeout_s=900.0):
        self.build, self.tag, self.timeout_s = build, tag, float(timeout_s)
        self.inputs = {}  # relative path on the worker -> bytes
        desc_args, argv = [], []
        args = list(args)
        i = 0
        while i < len(args):
            a = args[i]
            if isinstance(a, Text) or (i > 0 and str(args[i - 1]) in INPUT_OPTS):
                if isinstance(a, Text):
                    name, data, base = a.name, a.data, a.base_dir
                else:
                    path = os.path.abspath(str(a))
                    try:
                        with open(path, "rb") as f:
                            data = f.read()
                    except OSError as e:
                        raise StudyInputError(f"{args[i - 1]} {a}: {e.strerror}") from None
                    name, base = os.path.basename(path), os.path.dirname(path)
                slot = f"in{len(desc_args)}"
                deps = _ini_deps(data, base) if str(args[i - 1]) in ("--machine",
                                                                      "--control-machine") else []
                # A dependency reached through "..": the file one folder deeper per "..",
                # so that the path as written resolves inside the run's folder.
                up = max([os.path.normpath(d).split(os.sep).count("..") for d, _ in deps
                          if not os.path.isabs(d)] + [0])
                rel = "/".join([slot] + ["d"] * up + [name])
                self.inputs[rel] = data
                entry = {"file": rel, "sha256": hashlib.sha256(data).hexdigest()}
                if deps:
                    entry["deps"] = []
                    for d, ddata in deps:
                        h = hashlib.sha256(ddata).hexdigest() if ddata is not None else None
                        if os.path.isabs(d):  # not shipped: the worker's own file at that path
                            entry["deps"].append({"path": d, "sha256": h})
                            continue
                        drel = os.path.normpath(os.path.join(os.path.dirname(rel), d))
                        if ddata is not None:
                            self.inputs[drel] = ddata
                        entry["deps"].append({"file": drel, "sha256": h})
                desc_args.append(entry)
                argv.append(rel)
            else:
                s = str(a)
                if s in ("--metrics", "--trace"):
                    raise ValueError(f"{s}: outputs are the engine's (Run(outputs=...))")
                desc_args.append(s)
                argv.append(s)
            i += 1
        bad = [o for o in outputs if o not in OUTPUT_OPTS]
        if bad:
            raise ValueError(f"unknown output(s) {bad}: known {list(OUTPUT_OPTS)}")
        self.outputs = {o: OUTPUT_OPTS[o][1] for o in sorted(set(outputs))}
        for o, rel in self.outputs.items():
            argv += [OUTPUT_OPTS[o][0], rel]
        self.argv = argv
        self.description = json.dumps({"v": DESCRIPTION_VERSION, "sim": build.sha,
                                       "args": desc_args, "outputs": self.outputs},
                                      sort_keys=True, separators=(",", ":"))
        self.key = hashlib.sha256(self.description.encode()).hexdigest()

    def task(self):
        """What study_worker.execute gets."""
        return {"key": self.key, "sim": self.build.path, "build": self.build.sha,
                "args": self.argv, "inputs": self.inputs, "outputs": self.outputs,
                "timeout_s": self.timeout_s}

    def label(self):
        return self.tag if self.tag is not None else " ".join(self.argv)[:160]


def run_of_command(build, args, tag=None):
    """A Run from arguments written for the simulator itself: the paths of its
    --metrics and --trace become the engine's outputs. Returns (run, {output: path});
    Result.save_all(paths) writes them there."""
    rest, paths = [], {}
    args = [str(a) for a in args]
    i = 0
    while i < len(args):
        name = next((o for o, (opt, _) in OUTPUT_OPTS.items() if opt == args[i]), None)
        if name is not None and i + 1 < len(args):
            paths[name] = args[i + 1]
            i += 2
            continue
        rest.append(args[i])
        i += 1
    return Run(build, rest, outputs=tuple(paths), tag=tag), paths


# ---------------------------------------------------------------- results

def _last_error(stderr):
    lines = [ln.strip() for ln in stderr.splitlines() if ln.strip()]
    errs = [ln for ln in lines if "error" in ln]
    txt = (errs or lines or ["(no message)"])[-1]
    return txt[len("sim: error: "):] if txt.startswith("sim: error: ") else txt


class Result:
    """A run's result. status: ok (exit 0), fault (the drive tripped, exit 3: the
    metrics up to the trip), refused (invalid input, exit 2), error (the run could
    not complete, exit 1), crash (killed by a signal); and, never stored: lost (its
    workers died), no-build, timeout, engine-error. reason: why, in words."""

    def __init__(self, key, rc, stderr, outputs, wall_s=None, cpu_s=None, worker=None,
                 cached=False, status=None, reason=None):
        self.key, self.rc, self.stderr, self.outputs = key, rc, stderr, outputs or {}
        self.wall_s, self.cpu_s, self.worker, self.cached = wall_s, cpu_s, worker, cached
        self._metrics = False
        if status is not None:
            self.status, self.reason = status, reason
        elif rc == 0:
            self.status, self.reason = "ok", ""
        elif rc == 3:
            m = self.metrics or {}
            self.status = "fault"
            t = m.get("fault_time_s")
            self.reason = (f"the drive faulted: {m['fault']}" + (f" at t = {t:.4f} s" if t else "")
                           if m.get("fault") else _last_error(stderr))
        elif rc == 2:
            self.status, self.reason = "refused", _last_error(stderr)
        elif rc is not None and rc < 0:
            self.status, self.reason = "crash", f"simulator killed by signal {-rc}"
        else:
            self.status, self.reason = "error", _last_error(stderr)

    @property
    def stored(self):
        return self.status in ("ok", "fault", "refused", "error", "crash")

    @property
    def ok(self):
        return self.status == "ok"

    @property
    def metrics(self):
        """The --metrics JSON (also of a faulted run), None without one."""
        if self._metrics is False:
            txt = self.outputs.get("metrics")
            try:
                self._metrics = json.loads(txt) if txt else None
            except ValueError:
                self._metrics = None
        return self._metrics

    def text(self, name):
        return self.outputs.get(name)

    def save(self, name, path):
        """Write output name to path; False when the run has none."""
        txt = self.outputs.get(name)
        if txt is None:
            if os.path.exists(path):
                os.unlink(path)
            return False
        with open(path, "w") as f:
            f.write(txt)
        return True

    def save_all(self, paths):
        """Each output to its path ({output: path}, run_of_command's)."""
        for name, path in paths.items():
            self.save(name, path)

    def table_row(self):
        """What the store keeps of the run itself (no timing): the comparable part."""
        return (self.key, self.rc, self.stderr, json.dumps(self.outputs, sort_keys=True))


def _unpack(raw):
    return json.loads(zlib.decompress(raw["outputs"]))


class Store:
    """SQLite, one row per run keyed by its description's sha256; every result is
    committed as it arrives (WAL journal: a killed process leaves whole rows)."""

    SCHEMA = """CREATE TABLE IF NOT EXISTS runs (
        key TEXT PRIMARY KEY, description TEXT NOT NULL, rc INTEGER NOT NULL,
        stderr TEXT NOT NULL, outputs BLOB NOT NULL,
        wall_s REAL, cpu_s REAL, worker TEXT, stored_at REAL)"""

    def __init__(self, path):
        self.path = path
        if path != ":memory:":
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        try:
            self.db = sqlite3.connect(path, timeout=60.0)
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=NORMAL")
            self.db.execute(self.SCHEMA)
            self.db.commit()
        except sqlite3.DatabaseError as e:
            raise StudyInputError(f"store {path}: {e}") from None

    def get(self, keys):
        out = {}
        keys = list(keys)
        for k in range(0, len(keys), 500):
            chunk = keys[k:k + 500]
            q = ("SELECT key, rc, stderr, outputs, wall_s, cpu_s, worker FROM runs WHERE key IN "
                 f"({','.join('?' * len(chunk))})")
            for key, rc, err, outs, w, c, wk in self.db.execute(q, chunk):
                out[key] = Result(key, rc, err, json.loads(zlib.decompress(outs)), w, c, wk,
                                  cached=True)
        return out

    def put(self, run, raw, commit=True):
        self.db.execute("INSERT OR IGNORE INTO runs VALUES (?,?,?,?,?,?,?,?,?)",
                        (run.key, run.description, raw["rc"], raw["stderr"], raw["outputs"],
                         raw["wall_s"], raw["cpu_s"], raw["worker"], time.time()))
        if commit:
            self.db.commit()

    def commit(self):
        self.db.commit()

    def count(self):
        return self.db.execute("SELECT COUNT(*) FROM runs").fetchone()[0]

    def close(self):
        self.db.close()


# ---------------------------------------------------------------- progress

def _hms(s):
    s = int(round(s))
    return f"{s // 3600} h {s // 60 % 60:02d} min" if s >= 3600 else (
        f"{s // 60} min {s % 60:02d} s" if s >= 60 else f"{s} s")


class Progress:
    """Runs done and the time left, on stderr: a tqdm bar on a terminal (bar), or a
    line every few seconds (text), or nothing (none); auto: bar on a terminal,
    else text. callback(done, total, failed, eta_s), if given, gets every update
    (the demo's own display)."""

    def __init__(self, mode, label, total, stream=sys.stderr, callback=None, every_s=5.0):
        mode = mode or os.environ.get(PROGRESS_ENV) or "auto"
        if mode not in ("auto", "bar", "text", "none"):
            raise StudyInputError(f"progress display '{mode}': expected auto, bar, text or none")
        if mode == "auto":
            mode = "bar" if stream.isatty() else "text"
        self.mode, self.label, self.total, self.stream = mode, label, total, stream
        self.callback, self.every_s = callback, every_s
        self.t0 = self.t_last = time.monotonic()
        self.done = self.failed = 0
        self.bar = None
        if mode == "bar" and total:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, desc=label, unit="run", file=stream,
                                dynamic_ncols=True, smoothing=0.1)
            except ImportError:
                self.mode = "text"

    def eta_s(self):
        el = time.monotonic() - self.t0
        return el / self.done * (self.total - self.done) if self.done else None

    def step(self, failed=False):
        self.done += 1
        self.failed += bool(failed)
        eta = self.eta_s()
        if self.callback:
            self.callback(self.done, self.total, self.failed, eta)
        if self.bar is not None:
            self.bar.update(1)
            if failed:
                self.bar.set_postfix(failed=self.failed)
        elif self.mode == "text":
            now = time.monotonic()
            if now - self.t_last >= self.every_s or self.done == self.total:
                self.t_last = now
                el = now - self.t0
                self.stream.write(f"{self.label}: {self.done}/{self.total} runs"
                                  + (f", {self.failed} failed" if self.failed else "")
                                  + f", {self.done / el:.2f} runs/s"
                                  + (f", about {_hms(eta)} left" if eta and self.done < self.total
                                     else "") + "\n")
                self.stream.flush()

    def close(self):
        if self.bar is not None:
            self.bar.close()


# ---------------------------------------------------------------- the engine

def check_scheduler_address(addr):
    if not SCHEDULER_RE.match(addr or ""):
        raise StudyInputError(f"--scheduler {addr!r}: expected tcp://HOST:PORT (the address "
                              "`dask scheduler` prints)")
    port = int(SCHEDULER_RE.match(addr).group(3))
    if not 0 < port < 65536:
        raise StudyInputError(f"--scheduler {addr}: port {port} is outside 1..65535")
    return addr


NUMBER_RE = re.compile(r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
SUMMARY_GROUPS = 10  # kinds of failure the summary lists


class Engine:
    """Runs batches of Run on a dask.distributed cluster (or, serial=True, one by one
    in this process: the reference the cluster's results are compared with), through
    the store. Use as a context manager; close() prints the summary."""

    def __init__(self, jobs=None, scheduler=None, store=":memory:", progress=None, serial=False,
                 connect_timeout_s=10.0, name="study", stream=sys.stderr, callback=None,
                 chunk_s=1.0):
        self.jobs = int(jobs) if jobs else (os.cpu_count() or 1)
        if self.jobs < 1:
            raise StudyInputError(f"--jobs {jobs}: at least 1 worker")
        self.scheduler = check_scheduler_address(scheduler) if scheduler else None
        self.serial, self.name, self.stream = serial, name, stream
        self.progress_mode, self.callback = progress, callback
        if progress is not None:
            Progress(progress, name, 0)  # refuse a bad mode now
        self.connect_timeout_s = connect_timeout_s
        self.chunk_s = chunk_s  # seconds of simulation per dask task (0: one run per task)
        self.store = Store(store or ":memory:")
        self.client = self.cluster = None
        self.stats = {"runs": 0, "cached": 0, "computed": 0, "sim_wall": 0.0, "sim_cpu": 0.0,
                      "compute_wall": 0.0, "slots": 0}
        self.failures = []  # (status, reason, label)
        self._slots, self._slots_at = 0, -1e9
        self.t0, self.cpu0 = time.monotonic(), time.process_time()
        if self.scheduler:
            self._connect()  # an unreachable scheduler is refused before any work

    @classmethod
    def from_args(cls, a, out_dir, name, **kw):
        """An engine from the options of add_arguments (store default OUT/runs.sqlite)."""
        store = a.store or os.path.join(out_dir, "runs.sqlite")
        return cls(jobs=a.jobs, scheduler=a.scheduler, store=store, progress=a.progress,
                   connect_timeout_s=a.connect_timeout, name=name, **kw)

    # -- cluster
    def _connect(self):
        logging.getLogger("distributed").setLevel(logging.ERROR)
        import dask
        from distributed import Client
        # The client reads the submitting code's source for the dashboard's record on
        # every submit (inspect.getsource): none of it here.
        dask.config.set({"distributed.diagnostics.computations.ignore-modules": [".*"]})
        if self.scheduler:
            import cloudpickle
            # The workers need the simulator, not this repository's code: the run's
            # function travels by value.
            cloudpickle.register_pickle_by_value(study_worker)
            try:
                self.client = Client(self.scheduler, timeout=self.connect_timeout_s,
                                     set_as_default=False)
            except (OSError, TimeoutError) as e:
                raise StudyInputError(f"--scheduler {self.scheduler}: no dask scheduler "
                                      f"reachable within {self.connect_timeout_s:g} s ({e})"
                                      ) from None
        else:
            from distributed import LocalCluster
            # Threads in this process: each run is a simulator process, a worker
            # thread only waits for it. No statistical profiler (it samples every
            # thread's stack every 10 ms) and slower housekeeping: the engine's own
            # CPU time per run is then a fraction of a simulator run's.
            dask.config.set({"distributed.worker.profile.enabled": False,
                             "distributed.worker.memory.monitor-interval": "5s",
                             "distributed.admin.system-monitor.interval": "5s",
                             "distributed.admin.tick.interval": "1s",
                             "distributed.client.scheduler-info-interval": "10s",
                             # every worker is in this process: nothing to steal or move
                             "distributed.scheduler.work-stealing": False,
                             "distributed.scheduler.active-memory-manager.start": False})
            # No dashboard (no bokeh here); the scheduler's HTTP server on a free
            # loopback port, not on 8787 (where another cluster may be).
            self.cluster = LocalCluster(n_workers=self.jobs, threads_per_worker=1,
                                        processes=False, dashboard_address=None,
                                        silence_logs=logging.ERROR,
                                        scheduler_kwargs={"dashboard": False,
                                                          "dashboard_address": "127.0.0.1:0"})
            self.client = Client(self.cluster, set_as_default=False)

    def workers(self):
        if self.serial:
            return 1
        if self.client is None:
            self._connect()
        if self.scheduler:
            self.client.wait_for_workers(1, timeout=None)
        return sum(self.client.nthreads().values())

    # -- batches
    def run(self, runs, label=None):
        """Results of runs (a list, or a dict of Run), in the same shape."""
        items = list(runs.items()) if isinstance(runs, dict) else list(enumerate(runs))
        label = label or self.name
        by_key = {}
        for _, r in items:
            by_key.setdefault(r.key, r)
        have = self.store.get(by_key)
        todo = [r for k, r in by_key.items() if k not in have]
        self.stats["runs"] += len(by_key)
        self.stats["cached"] += len(have)
        if todo:
            have.update(self._compute(todo, label))
        self.stats["computed"] += len(todo)
        out = [(k, have[r.key]) for k, r in items]
        for k, r in by_key.items():
            if have[k].status != "ok":
                self.failures.append((have[k].status, have[k].reason, r.label()))
        return dict(out) if isinstance(runs, dict) else [v for _, v in out]

    def _compute(self, todo, label):
        slots = self.workers()  # the cluster is started (or reached) outside the timing
        prog = Progress(self.progress_mode, label, len(todo), self.stream, self.callback)
        got = {}
        self._t_slot = t0 = time.monotonic()
        try:
            if self.serial:
                for r in todo:
                    got[r.key] = self._arrived(r, study_worker.execute(r.task()), prog)
            else:
                self._compute_dask(todo, got, prog, slots)
        finally:
            prog.close()
        self.stats["compute_wall"] += time.monotonic() - t0
        return got

    def _slots_now(self):
        """Worker threads the cluster has now, asked of the scheduler at most every
        2 s (each question is a round trip through the scheduler)."""
        if self.serial:
            return 1
        now = time.monotonic()
        if now - self._slots_at >= 2.0:
            info = self.client.scheduler_info().get("workers", {})
            self._slots = sum(w.get("nthreads", 1) for w in info.values())
            self._slots_at = now
        return self._slots

    def _tick(self):
        """Slot-seconds (worker threads x time) since the last result: the time the
        runs could have used, against which the overhead is measured."""
        now = time.monotonic()
        n = self._slots_now()
        self.stats["slots"] = max(self.stats["slots"], n)
        self.stats["slot_s"] = self.stats.get("slot_s", 0.0) + n * (now - self._t_slot)
        self._t_slot = now

    def _chunk_size(self, left, slots):
        """Runs per dask task: about chunk_s seconds of simulation (the mean run's
        time so far), so that the scheduler's own work per task is a small part of
        it; one run per task until a few have been timed; never so many that the
        workers would wait for each other at the end (left / (3 slots))."""
        n, t = self._timed
        if self.chunk_s <= 0 or n < 2 * slots:
            return 1
        per_run = max(t / n, 1e-3)
        return max(1, min(int(self.chunk_s / per_run), left // (3 * slots), 256))

    def _compute_dask(self, todo, got, prog, slots):
        from collections import deque

        from distributed import as_completed
        pending = deque(todo)
        runs_of = {}
        ac = as_completed(loop=self.client.loop)
        self._timed = (0, 0.0)

        def submit_next():
            if not pending:
                return
            k = self._chunk_size(len(pending), slots)
            chunk = [pending.popleft() for _ in range(min(k, len(pending)))]
            # The key names the chunk's first run (tests find a run by it).
            f = self.client.submit(study_worker.execute_many, [r.task() for r in chunk],
                                   key=f"pmsm-runs-{chunk[0].key}-{len(chunk)}", pure=False)
            runs_of[f.key] = chunk
            ac.add(f)

        for _ in range(2 * slots):  # tasks in flight: each worker has the next one at hand
            submit_next()
        for f in ac:
            chunk = runs_of.pop(f.key)
            if f.status == "finished":
                raws = f.result()
                for r, raw in zip(chunk, raws):  # one transaction for the task's runs
                    got[r.key] = self._arrived(r, raw, None, commit=False)
                    n, t = self._timed
                    self._timed = (n + 1, t + raw["wall_s"])
                self.store.commit()
                for r in chunk:
                    prog.step(failed=got[r.key].status != "ok")
            else:
                exc = f.exception()
                name = type(exc).__name__
                for r in chunk:
                    if name == "KilledWorker":
                        res = Result(r.key, None, "", {}, status="lost",
                                     reason=f"the workers running it died ({exc})")
                    elif name == "MissingBuild":
                        res = Result(r.key, None, "", {}, status="no-build", reason=str(exc))
                    else:
                        res = Result(r.key, None, "", {}, status="engine-error",
                                     reason=f"{name}: {exc}")
                    got[r.key] = res
                    self._tick()
                    prog.step(failed=True)
            f.release()
            submit_next()

    def _arrived(self, run, raw, prog, commit=True):
        """The result of a raw one, stored (committed unless commit is False: the
        caller commits the task's runs together); prog steps unless None."""
        if raw["timeout"]:
            res = Result(run.key, raw["rc"], raw["stderr"], _unpack(raw), raw["wall_s"],
                         raw["cpu_s"], raw["worker"], status="timeout",
                         reason=f"no result within {run.timeout_s:g} s")
        else:
            self.store.put(run, raw, commit)
            res = Result(run.key, raw["rc"], raw["stderr"], _unpack(raw), raw["wall_s"],
                         raw["cpu_s"], raw["worker"])
            self.stats["sim_wall"] += raw["wall_s"]
            self.stats["sim_cpu"] += raw["cpu_s"]
        self._tick()
        if prog is not None:
            prog.step(failed=res.status != "ok")
        return res

    # -- summary
    def describe(self):
        """Where the runs execute, in words."""
        return ("serial, in this process" if self.serial else
                f"dask scheduler {self.scheduler}" if self.scheduler else
                f"local dask cluster, {self.jobs} worker{'s' * (self.jobs > 1)}")

    def summary(self):
        s = self.stats
        wall = time.monotonic() - self.t0
        where = ("this process" if self.store.path == ":memory:" else
                 os.path.relpath(self.store.path))
        how = self.describe()
        L = [f"{self.name}: {s['runs']} runs: {s['computed']} computed ({how}), {s['cached']} "
             f"from the store ({where})"]
        if self.failures:
            # Grouped by status and reason with its numbers left out (a fault's time, a
            # value), so that a large study's summary stays a few lines; each group
            # shows its first reason in full, the table every run's.
            groups = {}
            for st, why, lab in self.failures:
                g = groups.setdefault((st, NUMBER_RE.sub("#", why)), [why, set(), []])
                g[1].add(why)
                g[2].append(lab)
            L.append(f"{self.name}: {len(self.failures)} not ok:")
            ranked = sorted(groups.items(), key=lambda g: (-len(g[1][2]), g[0]))
            for (st, _), (why, whys, labs) in ranked[:SUMMARY_GROUPS]:
                alike = (f" (and {len(whys) - 1} alike with other numbers)"
                         if len(whys) > 1 else "")
                more = f" and {len(labs) - 3} more" if len(labs) > 3 else ""
                L.append(f"  {len(labs)} {st}: {why}{alike} [{'; '.join(labs[:3])}{more}]")
            if len(ranked) > SUMMARY_GROUPS:
                rest = sum(len(g[2]) for _, g in ranked[SUMMARY_GROUPS:])
                L.append(f"  {rest} more in {len(ranked) - SUMMARY_GROUPS} other kinds "
                         "(every run's reason is in the results)")
        line = (f"{self.name}: wall {wall:.1f} s; simulator {s['sim_wall']:.1f} s wall, "
                f"{s['sim_cpu']:.1f} s CPU; this process (engine and tool) "
                f"{time.process_time() - self.cpu0:.1f} s "
                "CPU")
        n = s["computed"]
        if n and s["sim_wall"] > 0:
            over = (s.get("slot_s", 0.0) - s["sim_wall"]) / n
            line += (f"; per-run overhead {1e3 * over:.1f} ms "
                     f"({100 * over / (s['sim_wall'] / n):.1f} % of a run: worker time not in "
                     "the simulator)")
        L.append(line)
        return "\n".join(L)

    def close(self):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        self.client = self.cluster = None
        self.store.close()

    def __enter__(self):
        return self

    def __exit__(self, et, ev, tb):
        try:
            if et is None or et is KeyboardInterrupt:
                print(self.summary(), file=self.stream)
        finally:
            self.close()
        return False


MAX_JOBS = 1024


def add_arguments(ap, jobs_default=None):
    """The engine's options on a tool's command line."""
    g = ap.add_argument_group("execution (tools/study_engine.py, docs/studies.md)")
    g.add_argument("--jobs", type=whole_in(1, MAX_JOBS, "workers"), default=jobs_default,
                   help="workers of the local dask cluster, [1, %d] (default: the CPU count)"
                   % MAX_JOBS)
    g.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help="run on an existing dask cluster instead of a local one")
    g.add_argument("--store", default=None, metavar="FILE.sqlite",
                   help="results store (default OUT/runs.sqlite); ':memory:' keeps none")
    g.add_argument("--progress", default=None, choices=("auto", "bar", "text", "none"),
                   help=f"progress display (default ${PROGRESS_ENV}, else auto)")
    g.add_argument("--connect-timeout", type=float, default=10.0, metavar="S",
                   help="seconds to reach --scheduler (default 10)")
    return g


def engine_or_exit(a, out_dir, name, **kw):
    """Engine.from_args, a bad option refused with exit status 2."""
    try:
        return Engine.from_args(a, out_dir, name, **kw)
    except StudyInputError as e:
        print(f"{name}: error: {e}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__).parse_args()
