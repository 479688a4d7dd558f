/* The target's side of the PIL link (pil_target.h). */
#include "pil_target.h"

#include <string.h>

#include "controller.h"
#include "pil_shared.h"

static void pil_send(pil_target_t *t, uint8_t type, uint16_t seq, const uint8_t *p, size_t n)
{
    uint8_t wire[PIL_WIRE_MAX];
    const size_t w = pil_frame_encode(type, seq, p, n, wire, sizeof wire);
    if (w > 0u) {
        t->port->write(t->port->ctx, wire, w);
    }
}

static void pil_send_fault(pil_target_t *t)
{
    const uint8_t p[1] = {(uint8_t)t->fault};
    pil_send(t, PIL_T_FAULT, t->seq_next, p, sizeof p);
}

static void pil_latch(pil_target_t *t, int err)
{
    if (t->fault == PIL_OK) {
        t->fault = err;
        hal_pil_link_fault(&t->hal);
    }
    pil_send_fault(t);
}

/* SETUP -> fw_init -> READY. */
static void pil_on_setup(pil_target_t *t, const pil_frame_t *f)
{
    pil_ready_t rd;
    memset(&rd, 0, sizeof rd);
    rd.cycle_clock_hz = t->port->cycle_clock_hz;
    pil_setup_t *s = &t->setup;
    const ctrl_desc_t *d = NULL;
    if (pil_setup_unpack(f->payload, f->len, s) != PIL_OK) {
        rd.rc = -100;
        (void)strncpy(rd.why, "setup frame malformed", sizeof rd.why - 1u);
    } else if ((d = ctrl_find(s->ctrl)) == NULL) {
        rd.rc = -101;
        (void)strncpy(rd.why, "controller not in this image", sizeof rd.why - 1u);
    } else if (d->cfg_size > CTRL_CFG_MAX) {
        rd.rc = -102;
        (void)strncpy(rd.why, "controller configuration too large", sizeof rd.why - 1u);
    } else {
        memset(t->ctrl_cfg, 0, sizeof t->ctrl_cfg);
        if (d->cfg_default != NULL) {
            d->cfg_default(t->ctrl_cfg, &s->machine);
        }
        for (size_t k = 0; k < s->n_sets && rd.rc == 0; k++) {
            if (strncmp(s->sets[k].name, "hfi.", 4u) == 0) {
                continue; /* the injection's, into fw_config_t below */
            }
            if (ctrl_tunable_set(d, t->ctrl_cfg, s->sets[k].name, s->sets[k].value) != CTRL_OK) {
                rd.rc = -103;
                (void)strncpy(rd.why, s->sets[k].name, sizeof rd.why - 1u);
            }
        }
    }
    if (rd.rc == 0) {
        fw_config_t fc;
        fw_config_default(&fc, &s->machine, d);
        fc.ctrl_cfg = t->ctrl_cfg;
        pil_setup_to_fw_config(s, &fc);
        for (size_t k = 0; k < s->n_sets && rd.rc == 0; k++) {
            if (strncmp(s->sets[k].name, "hfi.", 4u) != 0) {
                continue;
            }
#if CTRL_SL_HFI
            if (ctrl_tunable_set(&ctrl_hfi_desc, &fc.hfi_cfg, s->sets[k].name, s->sets[k].value) ==
                CTRL_OK) {
                continue;
            }
#endif
            rd.rc = -103;
            (void)strncpy(rd.why, s->sets[k].name, sizeof rd.why - 1u);
        }
        if (rd.rc == 0) {
            hal_pil_init(&t->hal, &s->info, t->port->cycles, t->port->cycle_clock_hz);
            rd.rc = fw_init(&t->fw, &t->hal, &fc);
            if (rd.rc != FW_OK) {
                (void)fw_explain(&t->fw, rd.why, sizeof rd.why);
            }
        }
    }
    t->ready = rd.rc == 0;
    t->seq_next = 1u;
    uint8_t p[PIL_WHY_MAX + 16u];
    const size_t n = pil_ready_pack(&rd, p, sizeof p);
    pil_send(t, PIL_T_READY, 0u, p, n);
}

static void pil_on_sample(pil_target_t *t, const pil_frame_t *f)
{
    pil_sample_t s;
    if (!t->ready || pil_sample_unpack(f->payload, f->len, &s) != PIL_OK) {
        pil_latch(t, PIL_E_FORMAT);
        return;
    }
    if (f->seq != t->seq_next) {
        pil_latch(t, PIL_E_SEQ);
        return;
    }
    if (t->fault != PIL_OK) {
        pil_send_fault(t);
        return;
    }
    fw_t *fw = &t->fw;
    /* The main loop's commands since the last period, in the engine's order. */
    if (s.cmd & PIL_CMD_TORQUE) {
        fw_set_torque_ref(fw, s.torque_ref);
    }
    if (s.cmd & PIL_CMD_SPEED) {
        fw_set_speed_ref(fw, s.speed_ref);
    }
    if (s.cmd & PIL_CMD_CLEAR) {
        fw_cmd_clear(fw);
    }
    if (s.cmd & PIL_CMD_DISARM) {
        fw_cmd_disarm(fw);
    }
    if (s.cmd & PIL_CMD_ARM) {
        fw_cmd_arm(fw);
    }
    hal_pil_sample(&t->hal, &s.adc, &s.enc, s.trip);
    fw_isr(fw);
    if (s.cmd & PIL_CMD_KICK) {
        fw_watchdog_kick(fw);
    }
    pil_apply_t a;
    bool written, gates, cleared;
    hal_pil_outputs(&t->hal, &a.pwm, &written, &gates, &cleared);
    const fw_telemetry_t *tm = fw_telemetry(fw);
    a.flags = (uint8_t)((written ? PIL_OUT_PWM : 0u) | (gates ? PIL_OUT_GATES : 0u) |
                        (cleared ? PIL_OUT_TRIP_CLEAR : 0u));
    a.state = (uint8_t)fw_state(fw);
    a.fault = (uint8_t)fw_fault(fw);
    a.cycles = tm->cycles;
    a.tm_digest = pil_tm_digest(tm);
    uint8_t p[32];
    const size_t n = pil_apply_pack(&a, p, sizeof p);
    pil_send(t, PIL_T_APPLY, f->seq, p, n);
    t->seq_next = pil_seq_next(t->seq_next);
    t->periods++;
}

int pil_target_byte(pil_target_t *t, uint8_t byte)
{
    bool got = false;
    const int rc = pil_dec_feed(&t->dec, byte, &t->rx, &got);
    if (rc != PIL_OK) {
        pil_latch(t, rc);
        return 0;
    }
    if (!got) {
        return 0;
    }
    if (t->port->now != NULL) {
        t->t_last = t->port->now(t->port->ctx);
    }
    switch (t->rx.type) {
    case PIL_T_SETUP:
        if (t->rx.seq != 0u || t->ready) {
            pil_latch(t, PIL_E_SEQ);
        } else {
            pil_on_setup(t, &t->rx);
        }
        return 0;
    case PIL_T_SAMPLE:
        pil_on_sample(t, &t->rx);
        return 0;
    case PIL_T_STOP:
        return 1;
    default:
        pil_latch(t, PIL_E_FORMAT);
        return 0;
    }
}

void pil_target_poll_timeout(pil_target_t *t)
{
    const pil_port_t *p = t->port;
    if (p->now == NULL || !t->ready || t->fault != PIL_OK || p->timeout_ms == 0u) {
        return;
    }
    const uint32_t gap = p->now(p->ctx) - t->t_last;
    if ((uint64_t)gap * 1000u > (uint64_t)p->timeout_ms * p->now_hz) {
        pil_dec_init(&t->dec); /* a partial frame is lost with it */
        pil_latch(t, PIL_E_TIMEOUT);
    }
}

int pil_target_run(pil_target_t *t, const pil_port_t *port)
{
    uint8_t buf[sizeof t->carry];
    /* what the last run read after its STOP (a new SETUP, typically) */
    const size_t carried = t->port == port && t->carry_n <= sizeof buf ? t->carry_n : 0u;
    memcpy(buf, t->carry, carried);
    memset(t, 0, sizeof *t);
    t->port = port;
    pil_dec_init(&t->dec);
    t->fault = PIL_OK;
    if (port->now != NULL) {
        t->t_last = port->now(port->ctx);
    }
    int n = (int)carried;
    for (;;) {
        if (n == 0) {
            n = port->read(port->ctx, buf, sizeof buf);
            if (n < 0) {
                return t->fault != PIL_OK ? t->fault : PIL_E_CLOSED;
            }
            if (n == 0) {
                pil_target_poll_timeout(t);
                continue;
            }
        }
        for (int i = 0; i < n; i++) {
            if (pil_target_byte(t, buf[i]) != 0) {
                t->carry_n = (uint8_t)(n - i - 1);
                memcpy(t->carry, &buf[i + 1], t->carry_n);
                return t->fault;
            }
        }
        n = 0;
    }
}
