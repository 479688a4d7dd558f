/* The PC's side of processor in the loop over a link (sim_pil.h). POSIX. */
#define _DEFAULT_SOURCE /* realpath, cfmakeraw, B921600 and above */
#include "sim_pil.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "pil_frame.h"
#include "pil_shared.h"

#define SIM_PIL_TIMEOUT_MS_DEFAULT 2000u
#define SIM_PIL_BAUD_DEFAULT 921600u
/* fw_init and the emulator's start-up come before READY: a longer wait. */
#define SIM_PIL_READY_FACTOR 10u

struct sim_pil {
    sim_pil_opts_t o;
    int fd_rd, fd_wr;
    pid_t child;
    char dir[64]; /* the emulator's FIFOs / socket */
    sim_link_t link;
    pil_dec_t dec;
    pil_frame_t rx;
    uint8_t buf[256]; /* bytes read but not yet decoded */
    size_t buf_at, buf_n;
    uint16_t seq;
    int err; /* pil_err_t latched */
    char msg[512];
    uint32_t cycle_clock_hz, fs_hz;
    /* the host firmware's command state after the last period */
    fw_ref_mode_t last_mode;
    q24_t last_torque, last_speed;
    /* figures */
    uint64_t periods, run_n;
    uint64_t cyc_sum;
    uint32_t cyc_max;
    struct timespec t0;
};

static double sim_pil_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int sim_pil_fail(sim_pil_t *p, int code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int sim_pil_fail(sim_pil_t *p, int code, const char *fmt, ...)
{
    if (p->err == PIL_OK) {
        p->err = code;
        int n = snprintf(p->msg, sizeof p->msg, "%s", pil_err_name(code));
        if (fmt != NULL && n > 0 && (size_t)n < sizeof p->msg) {
            va_list ap;
            va_start(ap, fmt);
            (void)vsnprintf(p->msg + n, sizeof p->msg - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    return -1;
}

/* ---- transport ---- */

static bool sim_pil_child_gone(sim_pil_t *p)
{
    if (p->child <= 0) {
        return false;
    }
    int st = 0;
    const pid_t w = waitpid(p->child, &st, WNOHANG);
    if (w == p->child) {
        p->child = 0;
        return true;
    }
    return false;
}

static int sim_pil_write(sim_pil_t *p, const uint8_t *b, size_t n)
{
    while (n > 0u) {
        const ssize_t w = write(p->fd_wr, b, n);
        if (w < 0) {
            if (errno == EINTR) {
                continue;
            }
            return sim_pil_fail(p, PIL_E_CLOSED, ": write: %s", strerror(errno));
        }
        b += w;
        n -= (size_t)w;
    }
    return 0;
}

static int sim_pil_send(sim_pil_t *p, uint8_t type, uint16_t seq, const uint8_t *pl, size_t n)
{
    uint8_t wire[PIL_WIRE_MAX];
    const size_t w = pil_frame_encode(type, seq, pl, n, wire, sizeof wire);
    if (w == 0u) {
        return sim_pil_fail(p, PIL_E_FORMAT, ": frame of %zu bytes too long", n);
    }
    return sim_pil_write(p, wire, w);
}

/* The next frame within timeout_ms: 0, or -1 with the link fault. */
static int sim_pil_recv(sim_pil_t *p, uint32_t timeout_ms, const char *what)
{
    const double t_end = sim_pil_now_s() + 1e-3 * (double)timeout_ms;
    for (;;) {
        while (p->buf_at < p->buf_n) {
            bool got = false;
            const int rc = pil_dec_feed(&p->dec, p->buf[p->buf_at++], &p->rx, &got);
            if (rc != PIL_OK) {
                return sim_pil_fail(p, rc, " (received while waiting for %s)", what);
            }
            if (got) {
                return 0;
            }
        }
        const double left = t_end - sim_pil_now_s();
        if (left <= 0.0) {
            return sim_pil_fail(p, PIL_E_TIMEOUT, ": no %s within %u ms", what,
                                (unsigned)timeout_ms);
        }
        struct pollfd pf = {p->fd_rd, POLLIN, 0};
        const int slice = left > 0.05 ? 50 : (int)(left * 1e3) + 1;
        const int pr = poll(&pf, 1, slice);
        if (pr < 0 && errno != EINTR) {
            return sim_pil_fail(p, PIL_E_CLOSED, ": poll: %s", strerror(errno));
        }
        if (pr <= 0) {
            if (sim_pil_child_gone(p)) {
                return sim_pil_fail(p, PIL_E_CLOSED, ": the target exited while %s was awaited",
                                    what);
            }
            continue;
        }
        const ssize_t n = read(p->fd_rd, p->buf, sizeof p->buf);
        if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN)) {
            return sim_pil_fail(p, PIL_E_CLOSED, ": end of the link while %s was awaited", what);
        }
        p->buf_at = 0u;
        p->buf_n = n > 0 ? (size_t)n : 0u;
    }
}

static int sim_pil_spawn(sim_pil_t *p, char *const argv[], int in_fd, int out_fd, const char *cwd)
{
    const pid_t pid = fork();
    if (pid < 0) {
        return -1;
    }
    if (pid == 0) {
        if (cwd != NULL && chdir(cwd) != 0) {
            _exit(126);
        }
        const int nul = open("/dev/null", O_RDWR);
        (void)dup2(in_fd >= 0 ? in_fd : nul, 0);
        (void)dup2(out_fd >= 0 ? out_fd : nul, 1);
        execvp(argv[0], argv);
        fprintf(stderr, "sim: cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    p->child = pid;
    return 0;
}

static int sim_pil_open_qemu(sim_pil_t *p, char *err, size_t errlen)
{
    const bool socket_tr = p->o.transport != NULL && strcmp(p->o.transport, "socket") == 0;
    if (p->o.transport != NULL && !socket_tr && strcmp(p->o.transport, "semihosting") != 0) {
        (void)snprintf(err, errlen, "--pil-transport '%s': expected semihosting or socket",
                       p->o.transport);
        return -1;
    }
    if (p->o.qemu_image == NULL || access(p->o.qemu_image, R_OK) != 0) {
        (void)snprintf(err, errlen, "--target qemu: no firmware image '%s' (tools/sim builds it)",
                       p->o.qemu_image != NULL ? p->o.qemu_image : "");
        return -1;
    }
    char image[4096];
    if (realpath(p->o.qemu_image, image) == NULL) {
        (void)snprintf(err, errlen, "--target qemu: %s: %s", p->o.qemu_image, strerror(errno));
        return -1;
    }
    (void)snprintf(p->dir, sizeof p->dir, "/tmp/pmsm-pil-XXXXXX");
    if (mkdtemp(p->dir) == NULL) {
        (void)snprintf(err, errlen, "--target qemu: mkdtemp: %s", strerror(errno));
        p->dir[0] = '\0';
        return -1;
    }
    char a_in[128], a_out[128], a_sock[160];
    (void)snprintf(a_in, sizeof a_in, "%s/pil.in", p->dir);
    (void)snprintf(a_out, sizeof a_out, "%s/pil.out", p->dir);
    (void)snprintf(a_sock, sizeof a_sock, "socket,id=pil,path=%s/pil.sock,server=on,wait=off",
                   p->dir);
    if (!socket_tr) {
        /* Both ends opened read-write by the PC: neither open blocks, and
         * the emulator's opens find the other end present. */
        if (mkfifo(a_in, 0600) != 0 || mkfifo(a_out, 0600) != 0 ||
            (p->fd_wr = open(a_in, O_RDWR)) < 0 || (p->fd_rd = open(a_out, O_RDWR)) < 0) {
            (void)snprintf(err, errlen, "--target qemu: FIFOs in %s: %s", p->dir, strerror(errno));
            return -1;
        }
    }
    char *argv[] = {"qemu-system-arm",
                    "-machine",
                    "mps2-an386",
                    "-display",
                    "none",
                    "-monitor",
                    "none",
                    "-serial",
                    socket_tr ? "chardev:pil" : "null",
                    "-semihosting-config",
                    "enable=on,target=native",
                    "-icount",
                    "shift=3,align=off,sleep=off",
                    "-kernel",
                    image,
                    socket_tr ? "-chardev" : NULL,
                    a_sock,
                    NULL};
    if (sim_pil_spawn(p, argv, -1, -1, p->dir) != 0) {
        (void)snprintf(err, errlen, "--target qemu: fork: %s", strerror(errno));
        return -1;
    }
    if (socket_tr) {
        struct sockaddr_un sa;
        memset(&sa, 0, sizeof sa);
        sa.sun_family = AF_UNIX;
        (void)snprintf(sa.sun_path, sizeof sa.sun_path, "%s/pil.sock", p->dir);
        const double t_end = sim_pil_now_s() + 10.0;
        int fd = -1;
        while (fd < 0 && sim_pil_now_s() < t_end && !sim_pil_child_gone(p)) {
            fd = socket(AF_UNIX, SOCK_STREAM, 0);
            if (fd >= 0 && connect(fd, (const struct sockaddr *)&sa, sizeof sa) != 0) {
                close(fd);
                fd = -1;
                const struct timespec ts = {0, 10000000};
                nanosleep(&ts, NULL);
            }
        }
        if (fd < 0) {
            (void)snprintf(err, errlen, "--target qemu: no connection to %s", sa.sun_path);
            return -1;
        }
        p->fd_rd = fd;
        p->fd_wr = fd;
    }
    return 0;
}

static speed_t sim_pil_baud(uint32_t b)
{
    switch (b) {
    case 115200u:
        return B115200;
    case 230400u:
        return B230400;
    case 460800u:
        return B460800;
    case 921600u:
        return B921600;
    case 1000000u:
        return B1000000;
    case 1500000u:
        return B1500000;
    case 2000000u:
        return B2000000;
    case 3000000u:
        return B3000000;
    default:
        return (speed_t)0;
    }
}

static int sim_pil_open_board(sim_pil_t *p, const char *dev, char *err, size_t errlen)
{
    const uint32_t baud = p->o.baud != 0u ? p->o.baud : SIM_PIL_BAUD_DEFAULT;
    const speed_t sp = sim_pil_baud(baud);
    if (sp == (speed_t)0) {
        (void)snprintf(err, errlen,
                       "--baud %u: not one of 115200, 230400, 460800, 921600, 1000000, 1500000, "
                       "2000000, 3000000",
                       (unsigned)baud);
        return -1;
    }
    const int fd = open(dev, O_RDWR | O_NOCTTY);
    if (fd < 0) {
        (void)snprintf(err, errlen, "--target board:%s: %s", dev, strerror(errno));
        return -1;
    }
    struct termios t;
    if (tcgetattr(fd, &t) != 0) {
        (void)snprintf(err, errlen, "--target board:%s: not a serial port (%s)", dev,
                       strerror(errno));
        close(fd);
        return -1;
    }
    cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    (void)cfsetispeed(&t, sp);
    (void)cfsetospeed(&t, sp);
    if (tcsetattr(fd, TCSANOW, &t) != 0) {
        (void)snprintf(err, errlen, "--target board:%s: %u baud refused (%s)", dev, (unsigned)baud,
                       strerror(errno));
        close(fd);
        return -1;
    }
    (void)tcflush(fd, TCIOFLUSH);
    p->fd_rd = fd;
    p->fd_wr = fd;
    /* A board that served an earlier run, or stopped in the middle of one,
     * waits for STOP to begin again. */
    return sim_pil_send(p, PIL_T_STOP, 0u, NULL, 0u) == 0 ? 0 : -1;
}

static int sim_pil_open_exec(sim_pil_t *p, const char *prog, char *err, size_t errlen)
{
    int to_t[2], from_t[2];
    if (pipe(to_t) != 0 || pipe(from_t) != 0) {
        (void)snprintf(err, errlen, "--target exec: pipe: %s", strerror(errno));
        return -1;
    }
    char *argv[] = {(char *)prog, NULL};
    if (sim_pil_spawn(p, argv, to_t[0], from_t[1], NULL) != 0) {
        (void)snprintf(err, errlen, "--target exec: fork: %s", strerror(errno));
        return -1;
    }
    close(to_t[0]);
    close(from_t[1]);
    p->fd_wr = to_t[1];
    p->fd_rd = from_t[0];
    return 0;
}

/* ---- the engine's hooks ---- */

static int sim_pil_setup(void *ctx, sim_run_t *r, const fw_config_t *fc, char *err, size_t errlen)
{
    sim_pil_t *p = ctx;
    const sim_run_cfg_t *c = &r->cfg;
    static pil_setup_t s;
    memset(&s, 0, sizeof s);
    if (c->ctrl_cfg != NULL || c->n_sets > PIL_SETS_MAX || strlen(c->ctrl->name) >= PIL_NAME_MAX) {
        (void)snprintf(err, errlen,
                       "PIL: the target is configured by controller name and at most %u "
                       "tunables (--set)",
                       (unsigned)PIL_SETS_MAX);
        return -1;
    }
    (void)snprintf(s.ctrl, sizeof s.ctrl, "%s", c->ctrl->name);
    s.machine = *fc->machine;
    s.n_sets = (uint8_t)c->n_sets;
    for (size_t k = 0; k < c->n_sets; k++) {
        if (strlen(c->sets[k].name) >= PIL_NAME_MAX) {
            (void)snprintf(err, errlen, "PIL: tunable name '%s' longer than %u characters",
                           c->sets[k].name, (unsigned)PIL_NAME_MAX - 1u);
            return -1;
        }
        memcpy(s.sets[k].name, c->sets[k].name, strlen(c->sets[k].name) + 1u); /* fits: above */
        s.sets[k].value = c->sets[k].value;
    }
    pil_setup_from_fw_config(&s, fc);
    hal_info_get(&r->hal, &s.info);
    static uint8_t pl[PIL_BODY_MAX];
    const size_t n = pil_setup_pack(&s, pl, sizeof pl);
    if (n == 0u || sim_pil_send(p, PIL_T_SETUP, 0u, pl, n) != 0) {
        (void)snprintf(err, errlen, "PIL: %s", p->err != PIL_OK ? p->msg : "setup too long");
        return -1;
    }
    const uint32_t to = p->o.timeout_ms * SIM_PIL_READY_FACTOR;
    pil_ready_t rd;
    if (sim_pil_recv(p, to, "READY frame") != 0) {
        (void)snprintf(err, errlen, "PIL: %s", p->msg);
        return -1;
    }
    if (p->rx.type != PIL_T_READY || pil_ready_unpack(p->rx.payload, p->rx.len, &rd) != 0) {
        sim_pil_fail(p, PIL_E_FORMAT, ": type 0x%02x instead of READY", (unsigned)p->rx.type);
        (void)snprintf(err, errlen, "PIL: %s", p->msg);
        return -1;
    }
    if (rd.rc != 0) {
        sim_pil_fail(p, PIL_E_SETUP, ": code %d (%s), which the host firmware accepted", (int)rd.rc,
                     rd.why);
        (void)snprintf(err, errlen, "PIL: %s", p->msg);
        return -1;
    }
    p->cycle_clock_hz = rd.cycle_clock_hz;
    p->fs_hz = c->fs_hz;
    p->seq = 0u;
    p->last_mode = fw_ref_mode(&r->fw);
    p->last_torque = fw_torque_ref(&r->fw);
    p->last_speed = fw_speed_ref(&r->fw);
    clock_gettime(CLOCK_MONOTONIC, &p->t0);
    return 0;
}

static int sim_pil_send_period(void *ctx, sim_run_t *r)
{
    sim_pil_t *p = ctx;
    const fw_t *fw = &r->fw;
    pil_sample_t s;
    memset(&s, 0, sizeof s);
    hal_adc_read(&r->hal, &s.adc);
    hal_encoder_read(&r->hal, &s.enc);
    s.trip = hal_trip_active(&r->hal);
    /* The main loop's commands since the last period, read from the host
     * firmware's request state (pipeline.h). */
    s.cmd = (uint8_t)((fw_cmd_pending(fw, FW_REQ_ARM) ? PIL_CMD_ARM : 0u) |
                      (fw_cmd_pending(fw, FW_REQ_DISARM) ? PIL_CMD_DISARM : 0u) |
                      (fw_cmd_pending(fw, FW_REQ_CLEAR) ? PIL_CMD_CLEAR : 0u) |
                      (r->cfg.kick_watchdog ? PIL_CMD_KICK : 0u));
    if (fw_ref_mode(fw) == FW_REF_TORQUE &&
        (p->last_mode != FW_REF_TORQUE || fw_torque_ref(fw) != p->last_torque)) {
        s.cmd |= PIL_CMD_TORQUE;
        s.torque_ref = fw_torque_ref(fw);
    }
    if (fw_ref_mode(fw) == FW_REF_SPEED &&
        (p->last_mode != FW_REF_SPEED || fw_speed_ref(fw) != p->last_speed)) {
        s.cmd |= PIL_CMD_SPEED;
        s.speed_ref = fw_speed_ref(fw);
    }
    uint8_t pl[64];
    const size_t n = pil_sample_pack(&s, pl, sizeof pl);
    p->seq = pil_seq_next(p->seq);
    return sim_pil_send(p, PIL_T_SAMPLE, p->seq, pl, n);
}

static int sim_pil_diverged(sim_pil_t *p, sim_run_t *r, const pil_apply_t *a, uint16_t dg)
{
    const fw_t *fw = &r->fw;
    return sim_pil_fail(p, PIL_E_DIVERGED,
                        " at period %llu: target state %s, fault '%s', telemetry digest 0x%04x; "
                        "host state %s, fault '%s', digest 0x%04x",
                        (unsigned long long)p->periods, fw_state_name((fw_state_id_t)a->state),
                        fw_fault_name(a->fault), (unsigned)a->tm_digest,
                        fw_state_name(fw_state(fw)), fw_fault_name(fw_fault(fw)), (unsigned)dg);
}

static int sim_pil_receive(void *ctx, sim_run_t *r)
{
    sim_pil_t *p = ctx;
    pil_apply_t a;
    int rc = sim_pil_recv(p, p->o.timeout_ms, "the APPLY frame");
    if (rc == 0 && p->rx.type == PIL_T_FAULT) {
        const int code = p->rx.len >= 1u ? p->rx.payload[0] : PIL_E_FORMAT;
        rc = sim_pil_fail(p, code, " (latched by the target, frame %u)", (unsigned)p->rx.seq);
    } else if (rc == 0 && p->rx.type != PIL_T_APPLY) {
        rc = sim_pil_fail(p, PIL_E_FORMAT, ": type 0x%02x instead of APPLY", (unsigned)p->rx.type);
    } else if (rc == 0 && p->rx.seq != p->seq) {
        rc = sim_pil_fail(p, PIL_E_SEQ, ": APPLY %u for SAMPLE %u", (unsigned)p->rx.seq,
                          (unsigned)p->seq);
    } else if (rc == 0 && pil_apply_unpack(p->rx.payload, p->rx.len, &a) != PIL_OK) {
        rc = sim_pil_fail(p, PIL_E_FORMAT, ": APPLY payload of %u bytes", (unsigned)p->rx.len);
    }
    if (rc == 0) {
        const fw_t *fw = &r->fw;
        const uint16_t dg = pil_tm_digest(fw_telemetry(fw));
        if (a.state != (uint8_t)fw_state(fw) || a.fault != (uint8_t)fw_fault(fw) ||
            a.tm_digest != dg) {
            rc = sim_pil_diverged(p, r, &a, dg);
        }
    }
    if (rc != 0) {
        hal_gate_enable(&r->hal, false);
        return -1;
    }
    /* The target's decisions drive the plant. */
    if (a.flags & PIL_OUT_PWM) {
        hal_pwm_write(&r->hal, &a.pwm);
    }
    if (a.flags & PIL_OUT_TRIP_CLEAR) {
        hal_trip_clear(&r->hal);
    }
    hal_gate_enable(&r->hal, (a.flags & PIL_OUT_GATES) != 0u);
    p->last_mode = fw_ref_mode(&r->fw);
    p->last_torque = fw_torque_ref(&r->fw);
    p->last_speed = fw_speed_ref(&r->fw);
    p->periods++;
    if (a.state == (uint8_t)FW_STATE_RUNNING) {
        p->run_n++;
        p->cyc_sum += a.cycles;
        p->cyc_max = a.cycles > p->cyc_max ? a.cycles : p->cyc_max;
    }
    return 0;
}

static const char *sim_pil_error(void *ctx)
{
    const sim_pil_t *p = ctx;
    return p->err != PIL_OK ? p->msg : "no link fault";
}

/* ---- API ---- */

sim_pil_t *sim_pil_open(const sim_pil_opts_t *o, char *err, size_t errlen)
{
    sim_pil_t *p = calloc(1u, sizeof *p);
    if (p == NULL) {
        (void)snprintf(err, errlen, "out of memory");
        return NULL;
    }
    p->o = *o;
    if (p->o.timeout_ms == 0u) {
        p->o.timeout_ms = SIM_PIL_TIMEOUT_MS_DEFAULT;
    }
    p->fd_rd = p->fd_wr = -1;
    pil_dec_init(&p->dec);
    /* A target that exits is the link fault "closed" (EPIPE), not a signal. */
    (void)signal(SIGPIPE, SIG_IGN);
    int rc;
    if (strcmp(o->target, "qemu") == 0) {
        rc = sim_pil_open_qemu(p, err, errlen);
    } else if (strncmp(o->target, "board:", 6) == 0 && o->target[6] != '\0') {
        rc = sim_pil_open_board(p, o->target + 6, err, errlen);
        if (rc != 0 && p->err != PIL_OK) {
            (void)snprintf(err, errlen, "--target %s: %s", o->target, p->msg);
        }
    } else if (strncmp(o->target, "exec:", 5) == 0 && o->target[5] != '\0') {
        rc = sim_pil_open_exec(p, o->target + 5, err, errlen);
    } else {
        (void)snprintf(err, errlen, "--target '%s': expected host, qemu or board:DEVICE",
                       o->target);
        rc = -1;
    }
    if (rc != 0) {
        (void)sim_pil_close(p);
        return NULL;
    }
    p->link.ctx = p;
    p->link.setup = sim_pil_setup;
    p->link.send = sim_pil_send_period;
    p->link.receive = sim_pil_receive;
    p->link.error = sim_pil_error;
    return p;
}

const sim_link_t *sim_pil_link(sim_pil_t *p)
{
    return &p->link;
}

void sim_pil_report(const sim_pil_t *p, FILE *f)
{
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    const double wall =
        (double)(t1.tv_sec - p->t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - p->t0.tv_nsec);
    const double sim_s = p->fs_hz > 0u ? (double)p->periods / (double)p->fs_hz : 0.0;
    fprintf(f,
            "sim: target %s: %llu periods (%.4g s simulated) in %.3g s wall: %.3g s per "
            "simulated s",
            p->o.target, (unsigned long long)p->periods, sim_s, wall,
            sim_s > 0.0 ? wall / sim_s : 0.0);
    if (p->run_n > 0u && p->cycle_clock_hz > 0u && p->fs_hz > 0u) {
        /* No cycle clock: no counter either (the host program). */
        fprintf(f,
                "; fw_isr running: mean %.1f, max %u cycles of a %.0f-cycle budget (%.4g MHz "
                "cycle clock)",
                (double)p->cyc_sum / (double)p->run_n, (unsigned)p->cyc_max,
                (double)p->cycle_clock_hz / (double)p->fs_hz, 1e-6 * (double)p->cycle_clock_hz);
    }
    fprintf(f, "\n");
}

int sim_pil_close(sim_pil_t *p)
{
    if (p == NULL) {
        return 0;
    }
    int rc = 0;
    if (p->fd_wr >= 0) {
        (void)sim_pil_send(p, PIL_T_STOP, 0u, NULL, 0u);
    }
    if (p->child > 0) {
        /* The target exits after STOP; an emulator that does not is stopped. */
        int st = 0;
        pid_t w = 0;
        for (int k = 0; k < 300 && (w = waitpid(p->child, &st, WNOHANG)) == 0; k++) {
            const struct timespec ts = {0, 10000000};
            nanosleep(&ts, NULL);
        }
        if (w == 0) {
            (void)kill(p->child, SIGKILL);
            (void)waitpid(p->child, &st, 0);
            rc = -1;
        } else if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
            rc = -1;
        }
    }
    if (p->fd_rd >= 0) {
        close(p->fd_rd);
    }
    if (p->fd_wr >= 0 && p->fd_wr != p->fd_rd) {
        close(p->fd_wr);
    }
    if (p->dir[0] != '\0') {
        char path[160];
        const char *names[] = {"pil.in", "pil.out", "pil.sock"};
        for (size_t k = 0; k < 3u; k++) {
            (void)snprintf(path, sizeof path, "%s/%s", p->dir, names[k]);
            (void)unlink(path);
        }
        (void)rmdir(p->dir);
    }
    free(p);
    return rc;
}
