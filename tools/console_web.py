"""Live console in the browser: `tools/console --web` (see docs/console.md).

A local web server (python3-aiohttp) between one target (board, QEMU, any
program speaking firmware/PROTOCOL.md) and any number of pages. The page
(tools/web/) is served from the repository; nothing is fetched from elsewhere.

Threads: the link worker owns the transport: it writes one command line at a
time, collects its response (ok / err / `ok N` + N lines, PROTOCOL.md section
2), decodes telemetry frames and polls `status` (and the commissioning status
while a step runs) when the line is idle. The asyncio loop serves HTTP and
WebSockets and pushes to every page, at most 30 times a second, the samples
decoded since the last push (SI units, scales from the META frame).

Safety:
- it listens on 127.0.0.1 unless --bind says otherwise; every request carries
  the token printed at start (a random 128-bit value), or it is refused (403);
  a WebSocket must also come from a page of this server (Origin);
- one page controls, the others watch: a watcher may send the commands that
  only read (READ_ONLY: status, param list, ...), its others are refused, but
  STOP is obeyed from every page;
- a command that energises the motor (arm, ident run/resume/step, bringup) is
  refused unless the page says the user confirmed it;
- when the controlling page has been silent for --page-timeout seconds (tab
  closed, network gone, page frozen: its heartbeat stops), the drive gets
  `stop` (gates off) and control is free again;
- the firmware page flashes a board through tools/flash (the controlling page
  only, confirmed, one run at a time, the drive stopped first); its output
  reaches every page line by line with the phase it shows.
"""
import asyncio
import json
import os
import queue
import re
import secrets
import subprocess
import sys
import threading
import time

import console_proto as cp

TOOLS = os.path.dirname(os.path.abspath(__file__))
WEB_DIR = os.path.join(TOOLS, "web")
FLASH = os.path.join(TOOLS, "flash")
STATIC_TYPES = {".js": "application/javascript", ".css": "text/css"}
PUSH_PERIOD_S = 1.0 / 30.0   # samples and status reach the pages 30 times a second
POLL_PERIOD_S = 0.25         # `status` when the line is idle
CM_STATES = ("commission",)  # state names in which the commissioning status is polled

# First words (and second, for ident) of commands that put voltage on the motor.
ENERGISING = {("arm",), ("ident", "run"), ("ident", "resume"), ("ident", "step"),
              ("ident", "cogging"), ("bringup",)}
NOT_ENERGISING_BRINGUP = {"status"}


# Commands that only read (firmware/PROTOCOL.md): a watching page may send them.
# One word alone, or the first two words (any arguments after: `param get NAME`).
READ_ONLY = {("status",), ("help",), ("fault",), ("param", "list"), ("param", "get"),
             ("tel", "list"), ("ctrl", "list"), ("ident", "status"), ("ident", "result"),
             ("ident", "ini"), ("bringup", "status"), ("cogging", "status")}

# Phases of a flash run: a text in a line of tools/flash --progress (its own,
# openocd's `program ... verify reset`, st-flash's `write`) and the share of
# the run done when it appears.
FLASH_PHASES = [
    ("tools/flash: programming", "connecting to the probe", 5),
    ("Programming Started", "writing", 20), ("Attempting to write", "writing", 20),
    ("Programming Finished", "written", 60),
    ("Verify Started", "verifying", 70), ("Starting verification", "verifying", 70),
    ("Verified OK", "verified", 90),
    ("Resetting Target", "resetting the board", 95),
    ("written and verified", "done", 100),
]
PAGES_WRITTEN = re.compile(r"(\d+)/(\d+) pages written")  # st-flash: 20 % .. 60 %


def flash_progress(line, pct):
    """(phase or None, percent) after a line of tools/flash --progress."""
    for text, phase, p in FLASH_PHASES:
        if text in line:
            return phase, max(pct, p)
    m = PAGES_WRITTEN.search(line)
    if m and int(m.group(2)) > 0:
        return "writing", max(pct, 20 + 40 * int(m.group(1)) // int(m.group(2)))
    return None, pct


def reads_only(line):
    w = line.split()
    return (len(w) == 1 and (w[0],) in READ_ONLY) or (len(w) >= 2 and tuple(w[:2]) in READ_ONLY)


def energises(line):
    w = line.split()
    if not w:
        return False
    if w[0] == "bringup":
        return len(w) >= 2 and w[1] not in NOT_ENERGISING_BRINGUP
    return (w[0],) in ENERGISING or tuple(w[:2]) in ENERGISING


def parse_status(lines):
    """`status` list lines ('  key=value') into a dict."""
    st = {}
    for ln in lines:
        ln = ln.strip()
        if "=" in ln:
            k, v = ln.split("=", 1)
            st[k.strip()] = v.strip()
    return st


class LinkWorker(threading.Thread):
    """Owns the transport; see the module's description."""

    def __init__(self, tr, timeout, emit):
        super().__init__(daemon=True, name="link")
        self.tr = tr
        self.timeout = timeout
        self.emit = emit                  # emit(event dict), thread-safe
        self.q = queue.Queue()
        self.dec = cp.StreamDecoder()
        self.rec = cp.Recorder()
        self.lock = threading.Lock()
        self.samples = []                 # [t_s, v...] since the last push
        self.stop_evt = threading.Event()
        self.gone = None                  # reason, once the target went away
        self.inflight = None              # (line, origin, lines, expected, deadline)
        self.last_poll = 0.0
        self.state = None
        # A commissioning step was started: its status is polled until a
        # `status` shows the drive out of the commissioning state, then once
        # more (a step may start and end between two polls of `status`, or
        # end between the last one in the state and the next).
        self.cm_watch = False

    # ---- called from the asyncio side
    def submit(self, line, origin):
        self.q.put((line, origin))

    def take_samples(self):
        with self.lock:
            s, self.samples = self.samples, []
        return s

    def counters(self):
        return {"frames": self.dec.frames, "bad": self.dec.bad, "lost": self.rec.lost}

    # ---- the thread
    def run(self):
        try:
            while not self.stop_evt.is_set():
                self._step()
        except EOFError as e:
            self._went_away(str(e) or "connection closed")
        except OSError as e:
            self._went_away("link error: %s" % e)

    def _went_away(self, why):
        rc = None
        for _ in range(10):  # the pipe closes just before the process is reaped
            rc = self.tr.exit_status()
            if rc is not None:
                break
            time.sleep(0.05)
        if rc is not None:
            why = "the target exited with status %d" % rc
        self.gone = why
        print("console: target gone: %s" % why, file=sys.stderr, flush=True)
        if self.inflight is not None:
            self.emit({"type": "reply", "origin": self.inflight[1], "line": self.inflight[0],
                       "ok": False, "lines": ["(target gone)"]})
            self.inflight = None
        self.emit({"type": "gone", "reason": why})

    def _step(self):
        now = time.monotonic()
        if self.inflight is None:
            try:
                line, origin = self.q.get_nowait()
            except queue.Empty:
                line = None
                if now - self.last_poll >= POLL_PERIOD_S:
                    self.last_poll = now
                    line, origin = "status", "poll"
            if line is not None:
                self.tr.write(line.encode("ascii", "replace") + b"\n")
                self.inflight = [line, origin, [], None, now + self.timeout]
        data = self.tr.read(0.01)
        if self.tr.exit_status() is not None and not data:
            raise EOFError("target exited")
        for kind, val in self.dec.feed(data):
            if kind == "frame":
                self._frame(val)
            elif kind == "text":
                self._text(val)
        if self.inflight is not None and time.monotonic() > self.inflight[4]:
            line, origin, lines = self.inflight[:3]
            self.inflight = None
            self.emit({"type": "reply", "origin": origin, "line": line, "ok": False,
                       "lines": lines + ["(no response within %g s)" % self.timeout]})

    def _frame(self, f):
        self.rec.add(f)
        if f.type == cp.TYPE_META:
            names = cp.signal_names(f.mask)
            units = dict(cp.SIGNALS)
            self.emit({"type": "meta", "signals": names, "units": [units.get(n, "") for n in names],
                       "scales": [s if s != 0.0 else 1.0 for s in f.scales],
                       "fs_hz": f.fs_hz, "every": f.every})
            return
        meta = self.rec.meta
        if meta is None or meta.mask != f.mask or not meta.fs_hz:
            return
        t = f.tick / meta.fs_hz
        row = [t] + [v * (s if s != 0.0 else 1.0) for v, s in zip(f.values, meta.scales)]
        with self.lock:
            self.samples.append(row)

    def _text(self, ln):
        inf = self.inflight
        if inf is None:
            self.emit({"type": "text", "line": ln})
            return
        line, origin, lines, expected = inf[:4]
        if expected is None:
            if not (ln.startswith("ok") or ln.startswith("err ")):
                self.emit({"type": "text", "line": ln})  # a banner, a boot message
                return
            lines.append(ln)
            w = ln.split()
            if ln.startswith("ok") and len(w) == 2 and w[1].isdigit() and int(w[1]) > 0:
                inf[3] = int(w[1])
                return
        else:
            lines.append(ln)
            if len(lines) - 1 < expected:
                return
        self.inflight = None
        ok = lines[0].startswith("ok")
        if ok and origin != "poll" and energises(line) and line.split()[0] in ("ident", "bringup"):
            self.cm_watch = True
        if origin == "poll" and line == "status" and ok:
            st = parse_status(lines[1:])
            self.state = st.get("state", self.state)
            if self.state in CM_STATES or self.cm_watch:
                self.cm_watch = self.state in CM_STATES
                self.q.put(("ident status", "poll"))
                self.q.put(("bringup status", "poll"))
            self.emit({"type": "status", "status": st, "counters": self.counters()})
            return
        self.emit({"type": "reply", "origin": origin, "line": line, "ok": ok, "lines": lines})


class WebConsole:
    def __init__(self, tr, args, target_label):
        self.tr = tr
        self.args = args
        self.token = secrets.token_hex(16)
        self.label = target_label
        self.pages = {}           # ws -> {"id", "last_seen"}
        self.controller = None    # the controlling ws
        self.next_id = 1
        self.loop = None
        self.link = LinkWorker(tr, args.timeout, self._emit_threadsafe)
        self.last_status = {}
        self.meta = None
        self.flashing = False     # a tools/flash run is under way
        self._flash_boards = None  # tools/flash --boards
        self.flash_board = args.flash_board  # None: tools/flash's default (the first it lists)

    # ---- events from the link thread
    def _emit_threadsafe(self, ev):
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._on_link_event, ev)

    def _on_link_event(self, ev):
        # Every event, replies included, goes to every page: watchers see what
        # the controlling page does.
        if ev["type"] == "status":
            self.last_status = ev["status"]
        elif ev["type"] == "meta":
            self.meta = ev
        asyncio.ensure_future(self._broadcast(ev))

    async def _broadcast(self, ev):
        msg = json.dumps(ev)
        for ws in list(self.pages):
            try:
                await ws.send_str(msg)
            except (ConnectionError, RuntimeError):
                pass

    async def _send(self, ws, ev):
        try:
            await ws.send_str(json.dumps(ev))
        except (ConnectionError, RuntimeError):
            pass

    def _roles(self):
        return {ws: ("control" if ws is self.controller else "watch") for ws in self.pages}

    async def _announce_roles(self):
        for ws, role in self._roles().items():
            await self._send(ws, {"type": "role", "role": role, "page": self.pages[ws]["id"],
                                  "pages": len(self.pages)})

    # ---- periodic tasks
    async def _pusher(self):
        while True:
            await asyncio.sleep(PUSH_PERIOD_S)
            rows = self.link.take_samples()
            if rows:
                await self._broadcast({"type": "samples", "rows": rows,
                                       "counters": self.link.counters()})

    async def _watchdog(self):
        while True:
            await asyncio.sleep(0.1)
            ws = self.controller
            if ws is None:
                continue
            silent = time.monotonic() - self.pages.get(ws, {"last_seen": 0})["last_seen"]
            if silent > self.args.page_timeout:
                await self._page_lost(ws, "no heartbeat for %.1f s" % silent)

    async def _page_lost(self, ws, why):
        if ws is not self.controller:
            return
        self.controller = None
        if self.link.gone is None:
            self.link.submit("stop", "page-loss")
        text = "console: the controlling page was lost (%s): drive stopped (gates off)" % why
        print(text, file=sys.stderr, flush=True)
        await self._broadcast({"type": "text", "line": text})
        await self._announce_roles()

    # ---- HTTP
    def _authorised(self, request):
        return secrets.compare_digest(request.query.get("token", ""), self.token)

    def _host_ok(self, request):
        # A page of another site that a DNS name points here must not reach us.
        host = request.host.rsplit(":", 1)[0].strip("[]")
        return host in self.allowed_hosts

    async def h_index(self, request):
        from aiohttp import web
        if not (self._authorised(request) and self._host_ok(request)):
            return web.Response(status=403, text="console: token missing or wrong\n")
        with open(os.path.join(WEB_DIR, "console.html"), encoding="utf-8") as fh:
            html = fh.read().replace("{{TOKEN}}", self.token)  # hex digits only
        return web.Response(text=html, content_type="text/html",
                            headers={"Cache-Control": "no-store",
                                     "Content-Security-Policy":
                                         "default-src 'self'; img-src 'self' data: blob:; "
                                         "connect-src 'self'; style-src 'self'; script-src 'self'"})

    async def h_static(self, request):
        from aiohttp import web
        if not (self._authorised(request) and self._host_ok(request)):
            return web.Response(status=403, text="console: token missing or wrong\n")
        name = request.match_info["name"]
        ext = os.path.splitext(name)[1]
        # The page's own files only: a plain name in tools/web/, no path.
        if not re.fullmatch(r"[a-z0-9_]+\.(js|css)", name) or \
                not os.path.isfile(os.path.join(WEB_DIR, name)):
            return web.Response(status=404)
        with open(os.path.join(WEB_DIR, name), encoding="utf-8") as fh:
            return web.Response(text=fh.read(), content_type=STATIC_TYPES[ext],
                                headers={"Cache-Control": "no-store"})

    # ---- the firmware page
    def flash_boards(self):
        """The boards tools/flash flashes (tools/flash --boards), once."""
        if self._flash_boards is None:
            r = subprocess.run([FLASH, "--boards"], stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True)
            self._flash_boards = r.stdout.split() if r.returncode == 0 else []
            if self.flash_board is None and self._flash_boards:
                self.flash_board = self._flash_boards[0]
        return self._flash_boards

    def _hello_flash_info(self):
        self.flash_boards()  # settles the default board
        return self.flash_info(self.flash_board)

    def _flash_argv(self, board, *opts):
        argv = [FLASH, "--board", board] + list(opts)
        if self.args.flash_tool:
            argv += ["--tool", self.args.flash_tool]
        if self.args.flash_image:
            argv.append(self.args.flash_image)
        return argv

    def flash_info(self, board):
        """What a flash of the board would write and with what: the image
        (tools/flash --which; st-flash writes an F405 board's image in two
        parts), its size and time, and the programmer's command or why there
        is none (tools/flash --dry-run)."""
        info = {"board": board, "boards": self.flash_boards(), "image": None, "bytes": None,
                "mtime": None, "command": None, "problem": None}
        r = subprocess.run(self._flash_argv(board, "--which"), stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
        if r.returncode == 0:
            parts = r.stdout.split()
            info["image"] = " + ".join(parts)
            try:
                sts = [os.stat(f) for f in parts]
                info["bytes"] = sum(st.st_size for st in sts)
                info["mtime"] = max(st.st_mtime for st in sts)
            except OSError:
                pass
        r = subprocess.run(self._flash_argv(board, "--dry-run"), stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
        if r.returncode == 0:
            info["command"] = r.stdout.strip()
        else:
            info["problem"] = (r.stderr.strip().splitlines() or ["tools/flash exited %d" %
                                                                r.returncode])[-1]
        return info

    async def _flash(self, page, board):
        """One tools/flash --progress run; every line to every page with its phase."""
        self.flashing = True
        pct = 0
        last = ""
        try:
            if self.link.gone is None:
                self.link.submit("stop", "page%d" % page)  # flashing resets the board
            await self._broadcast({"type": "flash", "start": True, "page": page,
                                   "info": self.flash_info(board)})
            proc = await asyncio.create_subprocess_exec(
                *self._flash_argv(board, "--progress"), stdout=asyncio.subprocess.PIPE,
                stderr=asyncio.subprocess.STDOUT)
            while True:
                raw = await proc.stdout.readline()
                if not raw:
                    break
                line = raw.decode("utf-8", "replace").rstrip()
                if not line:
                    continue
                last = line
                phase, pct = flash_progress(line, pct)
                await self._broadcast({"type": "flash", "line": line, "phase": phase, "pct": pct})
            rc = await proc.wait()
        except OSError as e:
            rc, last = 1, "tools/flash: cannot run: %s" % e
        finally:
            self.flashing = False
        # tools/flash: 0 written and verified, 1 set-up or image, 2 no probe, 3 programmer failed
        await self._broadcast({"type": "flash", "done": True, "rc": rc, "ok": rc == 0,
                               "pct": 100 if rc == 0 else pct,
                               "verdict": last if rc != 0 else "written and verified"})

    async def h_ws(self, request):
        from aiohttp import web, WSMsgType
        if not (self._authorised(request) and self._host_ok(request)):
            return web.Response(status=403, text="console: token missing or wrong\n")
        origin = request.headers.get("Origin")
        if origin is not None and origin != "http://%s" % request.host:
            return web.Response(status=403, text="console: foreign origin\n")
        ws = web.WebSocketResponse(heartbeat=None, max_msg_size=1 << 16)
        await ws.prepare(request)
        self.pages[ws] = {"id": self.next_id, "last_seen": time.monotonic()}
        self.next_id += 1
        if self.controller is None:
            self.controller = ws
        await self._send(ws, {"type": "hello", "target": self.label, "token_ok": True,
                              "page_timeout_s": self.args.page_timeout,
                              "target_pid": self.tr.proc.pid if self.tr.proc else None,
                              "status": self.last_status, "meta": self.meta,
                              "gone": self.link.gone, "flash": self._hello_flash_info(),
                              "read_only": sorted(" ".join(k) for k in READ_ONLY)})
        await self._announce_roles()
        try:
            async for msg in ws:
                if msg.type != WSMsgType.TEXT:
                    continue
                self.pages[ws]["last_seen"] = time.monotonic()
                try:
                    m = json.loads(msg.data)
                except ValueError:
                    continue
                await self._on_page_msg(ws, m)
        finally:
            was_controller = ws is self.controller
            del self.pages[ws]
            if was_controller:
                await self._page_lost(ws, "page closed")
            else:
                await self._announce_roles()
        return ws

    async def _on_page_msg(self, ws, m):
        kind = m.get("type")
        page = self.pages[ws]["id"]
        if kind == "heartbeat":
            return
        if kind == "stop":      # from every page, always
            if self.link.gone is None:
                self.link.submit("stop", "page%d" % page)
            await self._broadcast({"type": "text", "line": "console: STOP from page %d" % page})
            return
        if kind == "take_control":
            if self.controller is None:
                self.controller = ws
                await self._announce_roles()
            else:
                await self._send(ws, {"type": "refused", "line": "",
                                      "why": "another page controls the drive"})
            return
        board = m.get("board") or self.flash_board
        if kind in ("flash", "flash_info") and board not in self.flash_boards():
            await self._send(ws, {"type": "refused", "line": "flash",
                                  "why": "board %r: tools/flash flashes %s" % (
                                      board, ", ".join(self.flash_boards()) or "none")})
            return
        if kind == "flash":
            if ws is not self.controller:
                await self._send(ws, {"type": "refused", "line": "flash",
                                      "why": "this page watches; another page controls the drive"})
            elif m.get("confirm") is not True:
                await self._send(ws, {"type": "refused", "line": "flash",
                                      "why": "flashing replaces the board's firmware: confirm it first"})
            elif self.flashing:
                await self._send(ws, {"type": "refused", "line": "flash",
                                      "why": "a flash run is already under way"})
            else:
                self.flash_board = board
                asyncio.ensure_future(self._flash(page, board))
            return
        if kind == "flash_info":
            if ws is self.controller:
                self.flash_board = board  # the board the pages show from now on
            await self._send(ws, {"type": "flash_info", "info": self.flash_info(board)})
            return
        if kind != "cmd":
            return
        line = str(m.get("line", "")).strip()
        if not line:
            return
        if ws is not self.controller and not reads_only(line):
            await self._send(ws, {"type": "refused", "line": line,
                                  "why": "this page watches (it may read: status, param list, "
                                         "...); another page controls the drive"})
            return
        if energises(line) and m.get("confirm") is not True:
            await self._send(ws, {"type": "refused", "line": line,
                                  "why": "'%s' energises the motor: confirm it first" % line})
            return
        if self.link.gone is not None:
            await self._send(ws, {"type": "refused", "line": line, "why": "target gone"})
            return
        if len(line) > 96 or any(not (0x20 <= ord(c) <= 0x7E) for c in line):
            await self._send(ws, {"type": "refused", "line": line[:100],
                                  "why": "a command line is at most 96 printable ASCII characters"})
            return
        self.link.submit(line, "page%d" % page)

    async def serve(self):
        from aiohttp import web
        self.loop = asyncio.get_running_loop()
        self.allowed_hosts = {"127.0.0.1", "localhost", "::1", self.args.bind}
        app = web.Application()
        app.router.add_get("/", self.h_index)
        app.router.add_get("/static/{name}", self.h_static)
        app.router.add_get("/ws", self.h_ws)
        runner = web.AppRunner(app, access_log=None)
        await runner.setup()
        site = web.TCPSite(runner, self.args.bind, self.args.port)
        await site.start()
        port = site._server.sockets[0].getsockname()[1]
        host = self.args.bind if ":" not in self.args.bind else "[%s]" % self.args.bind
        url = "http://%s:%d/?token=%s" % (host, port, self.token)
        print("console: web page at %s" % url, flush=True)
        if self.args.url_file:
            with open(self.args.url_file, "w") as fh:
                fh.write(url + "\n")
        self.link.start()
        tasks = [asyncio.ensure_future(self._pusher()), asyncio.ensure_future(self._watchdog())]
        try:
            while True:
                await asyncio.sleep(3600)
        finally:
            for t in tasks:
                t.cancel()
            await runner.cleanup()


def serve(tr, args, target_label):
    """Runs until interrupted (Ctrl-C / SIGTERM). Returns the console's exit status."""
    try:
        import aiohttp  # noqa: F401  (python3-aiohttp, tools/setup)
    except ImportError:
        print("console: --web needs python3-aiohttp (tools/setup installs it)", file=sys.stderr)
        return 2
    wc = WebConsole(tr, args, target_label)
    boards = wc.flash_boards()
    if args.flash_board is not None and args.flash_board not in boards:
        print("console: --flash-board %s: tools/flash flashes %s" % (
            args.flash_board, ", ".join(boards) or "no board (tools/flash --boards failed)"),
            file=sys.stderr)
        return 2
    import signal
    loop = asyncio.new_event_loop()
    main = loop.create_task(wc.serve())
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, main.cancel)
    try:
        loop.run_until_complete(main)
    except asyncio.CancelledError:
        pass
    except OSError as e:
        print("console: cannot listen on %s:%d: %s" % (args.bind, args.port, e), file=sys.stderr)
        return 2
    finally:
        wc.link.stop_evt.set()
        wc.link.join(1.0)
        loop.close()
    if wc.link.gone is None:
        try:  # leave the drive with its gates off
            tr.write(b"stop\n")
        except (EOFError, OSError):
            pass
    print("console: web console stopped", file=sys.stderr)
    return 0
