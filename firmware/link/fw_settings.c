/*
 * Settings record <-> firmware configuration (fw_settings.h).
 */
#include "fw_settings.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cm.h"
#include "cmd.h"
#include "cmd_num.h"
#include "controller.h"
#include "ctrl_units.h"
#include "fw_link.h"
#if CTRL_COGGING
#include "settings_table.h"
#endif

static void fw_settings_name(char *dst, const char *src)
{
    memset(dst, 0, SETTINGS_NAME_MAX);
    if (src != NULL) {
        strncpy(dst, src, SETTINGS_NAME_MAX - 1u);
    }
}

/* A measured value, 0 where none was measured (NaN never goes into a record). */
static double fw_settings_finite(double v)
{
    return isfinite(v) ? v : 0.0;
}

void fw_settings_capture(const fw_t *fw, settings_t *s)
{
    memset(s, 0, sizeof *s);
    const ctrl_machine_t *m = &fw->machine_own;
    s->pole_pairs = m->pole_pairs;
    s->rs_ohm = m->rs_ohm;
    s->ld_h = m->ld_h;
    s->lq_h = m->lq_h;
    s->psi_pm_wb = m->psi_pm_wb;
    s->vdc_v = m->vdc_v;
    s->inertia_kgm2 = m->inertia_kgm2;
    s->torque_rated_nm = m->torque_rated_nm;
    s->speed_rated_rpm = m->speed_rated_rpm;
    s->current_rated_a = m->current_rated_a;
    s->current_max_a = m->current_max_a;
    s->psi_ref_wb = m->psi_ref_wb;
    s->speed_max_rpm = m->speed_max_rpm;
    /* the encoder as the firmware uses it now (identified offset and direction
     * included once "ident apply" adopted them) */
    s->enc_cpr = fw->enc_cpr;
    s->enc_direction = fw->enc_neg != 0u ? -1 : 1;
    s->enc_offset = fw->enc_offset;
    const fw_config_t *c = &fw->cfg;
    s->sensorless = c->sensorless ? (c->hfi ? 2u : 1u) : 0u;
    s->dead_time_s = c->dead_time_s;
    s->v_fwd_v = c->v_fwd_v;
    s->psi_adapt = c->psi_adapt ? 1u : 0u;
    if (fw->ctrl != NULL) {
        fw_settings_name(s->ctrl, fw->ctrl->name);
        const size_t n = fw->ctrl->n_tunables;
        for (size_t k = 0; k < n && k < SETTINGS_TUNABLES_MAX; k++) {
            const char *name = fw->ctrl->tunables[k].name;
            double v = 0.0;
            if (fw_tunable_get(fw, name, &v) == FW_OK) {
                fw_settings_name(s->tunable_name[s->n_tunables], name);
                s->tunable_value[s->n_tunables] = v;
                s->n_tunables++;
            }
        }
    }
#if CTRL_SL_HFI
    /* the injection's settings that differ from the machine's defaults (0) */
    for (size_t k = 0; c->hfi && k < ctrl_hfi_desc.n_tunables; k++) {
        const char *name = ctrl_hfi_desc.tunables[k].name;
        double v = 0.0;
        if (s->n_tunables < SETTINGS_TUNABLES_MAX && fw_tunable_get(fw, name, &v) == FW_OK &&
            v != 0.0) {
            fw_settings_name(s->tunable_name[s->n_tunables], name);
            s->tunable_value[s->n_tunables] = v;
            s->n_tunables++;
        }
    }
#endif
    s->speed_bw_hz = c->speed_bw_hz;
    s->speed_pm_deg = c->speed_pm_deg;
    s->speed_kp = c->speed_kp;
    s->speed_ki = c->speed_ki;
    s->speed_unit = (uint8_t)c->speed_unit;
    s->speed_out_max_nm = c->speed_out_max_nm;
    s->speed_loop_hz = c->speed_loop_hz;
    s->overspeed_rpm = c->overspeed_rpm;
#if CM_MECH
    s->coulomb_nm = c->coulomb_nm;
    s->viscous_nms = c->viscous_nms;
#endif
    fw_settings_thr_capture(s, NULL);
    cm_si_t r;
    fw_commission_results(fw, &r);
    s->id_have = r.have;
    s->id_rs_ohm = fw_settings_finite(r.rs_ohm);
    s->id_ld_h = fw_settings_finite(r.ld_h);
    s->id_lq_h = fw_settings_finite(r.lq_h);
    s->id_psi_wb = fw_settings_finite(r.psi_wb);
    s->id_inertia_kgm2 = fw_settings_finite(r.inertia_kgm2);
    s->id_enc_offset_deg = fw_settings_finite(r.enc_offset_deg);
    s->id_enc_dir = (int8_t)(r.enc_dir > 0 ? 1 : (r.enc_dir < 0 ? -1 : 0));
    s->id_enc_cpr = r.enc_cpr;
#if CM_MECH
    s->id_coulomb_nm = fw_settings_finite(r.coulomb_nm);
    s->id_viscous_nms = fw_settings_finite(r.friction_nms);
#endif
}

void fw_settings_thr_capture(settings_t *s, const thr_config_t *c)
{
    thr_config_t d;
    if (c == NULL) {
        thr_config_default(&d);
        c = &d;
    }
    s->thr_mode = c->mode;
    s->thr_low_us = c->low_us;
    s->thr_high_us = c->high_us;
    s->thr_deadband_us = c->deadband_us;
    s->thr_stored = 1u;
}

int fw_settings_thr_config(const settings_t *s, thr_config_t *c, char *why, size_t cap)
{
    thr_config_default(c);
    if (s->thr_stored == 0u) {
        return FW_OK;
    }
    c->mode = s->thr_mode;
    c->low_us = s->thr_low_us;
    c->high_us = s->thr_high_us;
    c->deadband_us = s->thr_deadband_us;
    const int bad = thr_config_check(c);
    if (bad == 0) {
        return FW_OK;
    }
    /* each field's range as thr_config_check has it; the dead band's upper
     * end is below half the span of the (then valid) end points */
    static const struct {
        char name[12];
        uint16_t lo, hi;
    } f[] = {{"mode", 0u, THR_MODE_SPEED},
             {"low_us", THR_PULSE_MIN_US, THR_LOW_MAX_US},
             {"high_us", THR_HIGH_MIN_US, THR_PULSE_MAX_US},
             {"deadband_us", 0u, 0u}};
    const unsigned v[] = {c->mode, c->low_us, c->high_us, c->deadband_us};
    const unsigned k = (unsigned)bad - 1u;
    const unsigned hi =
        bad == THR_BAD_DEADBAND ? (unsigned)(c->high_us - c->low_us - 1u) / 2u : f[k].hi;
    (void)snprintf(why, cap, "throttle.%s = %u outside [%u, %u]", f[k].name, v[k], f[k].lo, hi);
    return FW_EINVAL;
}

#if CM_MECH
/* The record's friction into c: none up to what the rated torque overcomes
 * (a drive that cannot move its own shaft is a wrong record). */
static int fw_settings_friction(const settings_t *s, fw_config_t *c, char *why, size_t cap)
{
    /* friction: none up to what the rated torque overcomes (a drive that
     * cannot move its own shaft is a wrong record) */
    const double t_r = s->torque_rated_nm;
    const double w_r = s->speed_rated_rpm * (CTRL_TWO_PI / 60.0);
    const char *bad = NULL;
    double val = 0.0, hi = 0.0;
    if (!(s->coulomb_nm >= 0.0 && s->coulomb_nm <= t_r)) {
        bad = "m.coulomb_nm";
        val = s->coulomb_nm;
        hi = t_r;
    } else if (!(s->viscous_nms >= 0.0 && s->viscous_nms * w_r <= t_r)) {
        bad = "m.viscous_nms";
        val = s->viscous_nms;
        hi = w_r > 0.0 ? t_r / w_r : 0.0;
    }
    if (bad != NULL) {
        char vt[24], ht[24]; /* no float conversion in printf (the tunables below) */
        if (cmd_num_format(vt, sizeof vt, val, 7u) == 0u ||
            cmd_num_format(ht, sizeof ht, hi, 7u) == 0u) {
            strcpy(vt, "?");
            strcpy(ht, "?");
        }
        (void)snprintf(why, cap, "%s = %s outside [0, %s]", bad, vt, ht);
        return FW_EINVAL;
    }
    c->coulomb_nm = s->coulomb_nm;
    c->viscous_nms = s->viscous_nms;
    return FW_OK;
}
#endif

int fw_settings_config(const settings_t *s, ctrl_machine_t *m, fw_config_t *c, void *cfg_buf,
                       char *why, size_t cap)
{
    const ctrl_desc_t *d = ctrl_find(s->ctrl);
    if (d == NULL) {
        (void)snprintf(why, cap, "controller %s is not in this image", s->ctrl);
        return FW_ENOENT;
    }
    memset(m, 0, sizeof *m);
    m->name = "settings";
    m->pole_pairs = (int)s->pole_pairs;
    m->rs_ohm = s->rs_ohm;
    m->ld_h = s->ld_h;
    m->lq_h = s->lq_h;
    m->psi_pm_wb = s->psi_pm_wb;
    m->vdc_v = s->vdc_v;
    m->inertia_kgm2 = s->inertia_kgm2;
    m->torque_rated_nm = s->torque_rated_nm;
    m->speed_rated_rpm = s->speed_rated_rpm;
    m->current_rated_a = s->current_rated_a;
    m->current_max_a = s->current_max_a;
    m->psi_ref_wb = s->psi_ref_wb;
    m->speed_max_rpm = s->speed_max_rpm;
    fw_config_default(c, m, d);
    c->enc_cpr = s->enc_cpr;
    c->enc_direction = s->enc_direction;
    c->enc_offset = s->enc_offset;
    c->sensorless = s->sensorless != 0u;
    c->hfi = s->sensorless == 2u;
    c->dead_time_s = s->dead_time_s;
    c->v_fwd_v = s->v_fwd_v;
    c->psi_adapt = s->psi_adapt != 0u;
    c->speed_bw_hz = s->speed_bw_hz;
    c->speed_pm_deg = s->speed_pm_deg;
    c->speed_kp = s->speed_kp;
    c->speed_ki = s->speed_ki;
    c->speed_unit = (ctrl_speed_unit_t)s->speed_unit;
    c->speed_out_max_nm = s->speed_out_max_nm;
    c->speed_loop_hz = s->speed_loop_hz;
    c->overspeed_rpm = s->overspeed_rpm;
#if CM_MECH
    /* friction (an image without the mechanics' identification keeps none:
     * the record's stay in the record) */
    if (fw_settings_friction(s, c, why, cap) != FW_OK) {
        return FW_EINVAL;
    }
#endif
    memset(cfg_buf, 0, CTRL_CFG_MAX);
    if (ctrl_cfg_default(d, cfg_buf, m) != CTRL_OK) {
        (void)snprintf(why, cap, "controller %s: no default configuration", d->name);
        return FW_EINVAL;
    }
    for (unsigned k = 0; k < s->n_tunables && k < SETTINGS_TUNABLES_MAX; k++) {
#if CTRL_SL_HFI
        if (strncmp(s->tunable_name[k], "hfi.", 4u) == 0 &&
            ctrl_tunable_set(&ctrl_hfi_desc, &c->hfi_cfg, s->tunable_name[k],
                             s->tunable_value[k]) == CTRL_OK) {
            continue; /* the injection's setting (fw_config_t.hfi_cfg) */
        }
#endif
        if (ctrl_tunable_set(d, cfg_buf, s->tunable_name[k], s->tunable_value[k]) != CTRL_OK) {
            char v[24]; /* no float conversion in printf: the target's libc may lack it */
            if (cmd_num_format(v, sizeof v, s->tunable_value[k], 7u) == 0u) {
                strcpy(v, "?");
            }
            (void)snprintf(why, cap, "%s tunable %s = %s refused", d->name, s->tunable_name[k], v);
            return FW_EINVAL;
        }
    }
    c->ctrl_cfg = cfg_buf;
    return FW_OK;
}

int fw_settings_init(fw_t *fw, hal_t *hal, const settings_t *s, void *cfg_buf, char *why,
                     size_t cap)
{
    ctrl_machine_t m;
    fw_config_t c;
    if (fw_settings_config(s, &m, &c, cfg_buf, why, cap) != FW_OK) {
        return CMD_E_FAILED;
    }
    if (fw_init(fw, hal, &c) != FW_OK) {
        (void)fw_explain(fw, why, cap);
        return CMD_E_FAILED;
    }
    return CMD_OK;
}

#if CTRL_COGGING
/* The number x as text (no float conversion in printf). */
static const char *fw_settings_num(char *buf, size_t cap, double x)
{
    return cmd_num_format(buf, cap, x, 6u) != 0u ? buf : "?";
}

/* Why the table of header h was not measured on what fw runs now; NULL: it was. */
static const char *fw_settings_tab_mismatch(const fw_t *fw, const settings_tab_hdr_t *h, char *why,
                                            size_t cap)
{
    char a[16], b[16]; /* 6 significant digits */
    const int dir = fw->enc_neg != 0u ? -1 : 1;
    /* the offset's difference, electrical: 2 degrees is the identification's
     * bound; beyond it the encoder moved on the shaft, and the table with it */
    const int32_t d = (int32_t)(fw->enc_offset - h->enc_offset);
    const uint32_t ad = d < 0 ? 0u - (uint32_t)d : (uint32_t)d;
    const double t_r = fw->machine_own.torque_rated_nm;
    if (h->n_log2 != CTRL_COG_N_LOG2) {
        (void)snprintf(why, cap, "%lu entries, this image's table %lu",
                       (unsigned long)1u << h->n_log2, (unsigned long)CTRL_COG_N);
    } else if (h->enc_cpr != fw->enc_cpr) {
        (void)snprintf(why, cap, "encoder %lu counts per revolution, the table's %lu",
                       (unsigned long)fw->enc_cpr, (unsigned long)h->enc_cpr);
    } else if (h->enc_dir != dir) {
        (void)snprintf(why, cap, "encoder direction %d, the table's %d", dir, h->enc_dir);
    } else if (h->pole_pairs != fw->machine_own.pole_pairs) {
        (void)snprintf(why, cap, "pole pairs %d, the table's %ld", fw->machine_own.pole_pairs,
                       (long)h->pole_pairs);
    } else if (!(fabs(h->torque_rated_nm - t_r) <= 1e-9 * t_r)) {
        (void)snprintf(why, cap, "rated torque %s N*m, the table's %s",
                       fw_settings_num(a, sizeof a, t_r),
                       fw_settings_num(b, sizeof b, h->torque_rated_nm));
    } else if (ad > FW_SETTINGS_TAB_OFFSET_MAX) {
        (void)snprintf(why, cap, "encoder offset %s deg electrical from the table's (> 2)",
                       fw_settings_num(a, sizeof a, (double)ad * (360.0 / 4294967296.0)));
    } else {
        return NULL;
    }
    return why;
}

/* The table saved with the record of page st->scan.page (fw_settings_boot). */
static void fw_settings_tab_boot(fw_settings_t *st)
{
    fw_t *fw = st->fw;
    st->tab_msg[0] = '\0';
    if (fw == NULL || !settings_tab_fits(&st->flash, CTRL_COG_N_LOG2)) {
        return;
    }
    const unsigned page = (unsigned)st->scan.page;
    settings_tab_hdr_t h;
    uint16_t fmt = 0;
    /* straight into the drive's table: it has none since the record's
     * configuration (fw_init), and stays without one (valid 0) unless the
     * table passes */
    const settings_status_t ts =
        settings_tab_load(&st->flash, page, st->scan.seq[page], st->buf, sizeof st->buf, &h,
                          fw->cog.table, CTRL_COG_N, &fmt);
    char why[FW_SETTINGS_MSG_MAX - 41u]; /* the message's own words: 41 */
    if (ts == SETTINGS_E_EMPTY) {
        return;
    }
    if (ts == SETTINGS_E_OLD || ts == SETTINGS_E_NEW) {
        (void)snprintf(why, sizeof why, "format %u (this firmware reads %u)", (unsigned)fmt,
                       SETTINGS_TAB_FORMAT);
    } else if (ts != SETTINGS_OK) {
        (void)snprintf(why, sizeof why, "%s", settings_status_name(ts));
    } else if (fw_settings_tab_mismatch(fw, &h, why, sizeof why) == NULL) {
        if (fw_cogging_load(fw, fw->cog.table, CTRL_COG_N) == FW_OK) {
            const bool on = h.ff_on != 0u && fw_cogging_enable(fw, true) == FW_OK;
            (void)snprintf(st->tab_msg, sizeof st->tab_msg,
                           "cogging table (%lu entries) applied, feed-forward %s",
                           (unsigned long)CTRL_COG_N,
                           on ? "on" : (h.ff_on != 0u ? "off (sensorless)" : "off"));
            return;
        }
        (void)snprintf(why, sizeof why, "%s", "gates on");
    }
    (void)snprintf(st->tab_msg, sizeof st->tab_msg, "cogging table refused: %s; feed-forward off",
                   why);
}

/* The drive's table as a record to save; false: none. */
static bool fw_settings_tab_capture(const fw_t *fw, settings_tab_t *t)
{
    t->entries = fw_cogging_table(fw, NULL);
    if (t->entries == NULL) {
        return false;
    }
    t->hdr.seq = 0u; /* the store's */
    t->hdr.enc_cpr = fw->cog.cal_cpr;
    t->hdr.enc_offset = fw->enc_offset;
    t->hdr.enc_dir = fw->enc_neg != 0u ? -1 : 1;
    t->hdr.n_log2 = (uint8_t)CTRL_COG_N_LOG2;
    t->hdr.ff_on = fw->cog_on != 0u ? 1u : 0u;
    t->hdr.pole_pairs = fw->machine_own.pole_pairs;
    t->hdr.torque_rated_nm = fw->machine_own.torque_rated_nm;
    return true;
}
#endif

bool fw_settings_boot(fw_settings_t *st)
{
#if CTRL_COGGING
    st->tab_msg[0] = '\0';
#endif
    const settings_status_t rc =
        settings_store_load(&st->flash, st->buf, sizeof st->buf, &st->rec, &st->scan);
    if (rc != SETTINGS_OK) {
        (void)settings_load_message(&st->scan, st->msg, sizeof st->msg);
        return false;
    }
    char why[FW_SETTINGS_MSG_MAX - 48u];
    why[0] = '\0';
    if (st->apply(st->ctx, &st->rec, why, sizeof why) == CMD_OK) {
        (void)settings_load_message(&st->scan, st->msg, sizeof st->msg);
#if CTRL_COGGING
        fw_settings_tab_boot(st);
#endif
        return true;
    }
    (void)st->apply_default(st->ctx);
    /* cut at the message's end when the reason is long */
    const int n =
        snprintf(st->msg, sizeof st->msg, "settings: record %lu refused: %s; compiled-in defaults",
                 (unsigned long)st->scan.seq[st->scan.page], why);
    if (n < 0) {
        st->msg[0] = '\0';
    }
    return false;
}

/* "config save|erase|default|read" (cmd.h ops.config). */
static int fw_settings_command(fw_settings_t *st, fw_t *fw, const char *what, const char **detail)
{
    *detail = st->msg;
    st->msg[0] = '\0';
    /* Gates off, and no request pending that turns them on at the next
     * period: an erase stalls the CPU (and the control interrupt) for tens
     * of ms, and a read that meets an ECC error takes the NMI, which turns
     * the gates off (g4_flash.c) */
    fw_state_id_t state;
    const char *pending = fw_gates_request_pending(fw, &state);
    if (pending != NULL || state == FW_STATE_RUNNING || state == FW_STATE_COMMISSION) {
        (void)snprintf(st->msg, sizeof st->msg,
                       "%s%s (%s): disarm first (a page erase stalls the CPU ~22 ms)",
                       pending != NULL ? pending : "gates on", pending != NULL ? " pending" : "",
                       fw_state_name(state));
        return CMD_E_STATE;
    }
    if (strcmp(what, "read") == 0) {
        if (settings_store_load(&st->flash, st->buf, sizeof st->buf, &st->rec, &st->scan) !=
            SETTINGS_OK) {
            (void)settings_load_message(&st->scan, st->msg, sizeof st->msg);
            return CMD_E_STATE;
        }
        return CMD_OK;
    }
    if (strcmp(what, "default") == 0) {
        const int rc = st->apply_default(st->ctx);
        (void)snprintf(st->msg, sizeof st->msg, "%s",
                       rc == CMD_OK ? "compiled-in defaults applied (flash unchanged)"
                                    : "compiled-in defaults refused");
        return rc;
    }
    int rc;
    if (strcmp(what, "save") == 0) {
        settings_t s;
        fw_settings_capture(fw, &s);
        if (st->capture != NULL) {
            st->capture(st->ctx, &s);
        }
        uint32_t seq = 0;
#if CTRL_COGGING
        /* the table in its own record of the same page, where the page holds it */
        settings_tab_t tab;
        const bool have = fw_settings_tab_capture(fw, &tab);
        const bool fits = settings_tab_fits(&st->flash, CTRL_COG_N_LOG2);
        rc = settings_store_save_with(&st->flash, st->buf, sizeof st->buf, &s,
                                      have && fits ? settings_tab_program : NULL, &tab, &seq);
        if (rc == SETTINGS_STORE_OK) {
            (void)snprintf(st->msg, sizeof st->msg, "saved record %lu%s", (unsigned long)seq,
                           !have  ? ""
                           : fits ? " with the cogging table"
                                  : "; the cogging table not kept: the flash page is too small");
            return CMD_OK;
        }
#else
        rc = settings_store_save(&st->flash, st->buf, sizeof st->buf, &s, &seq);
        if (rc == SETTINGS_STORE_OK) {
            (void)snprintf(st->msg, sizeof st->msg, "saved record %lu", (unsigned long)seq);
            return CMD_OK;
        }
#endif
    } else {
        rc = settings_store_erase(&st->flash, st->buf, sizeof st->buf);
        if (rc == SETTINGS_STORE_OK) {
            (void)snprintf(st->msg, sizeof st->msg, "%s",
                           "erased: compiled-in defaults from the next start");
            return CMD_OK;
        }
    }
    (void)snprintf(st->msg, sizeof st->msg, "flash: %s", settings_store_strerror(&st->flash, rc));
    return CMD_E_FAILED;
}

/* "config show": the record last read, after its sequence number and page. */
static bool fw_settings_item(const fw_settings_t *st, size_t index, cmd_config_item_t *it)
{
    if (st->scan.page < 0) {
        return false;
    }
    it->text = NULL;
    if (index < 2u) {
        it->key = index == 0u ? "record" : "page";
        it->num = index == 0u ? (double)st->scan.seq[st->scan.page] : (double)st->scan.page;
        return true;
    }
    settings_item_t si;
    if (!settings_item_at(&st->rec, index - 2u, &si)) {
        return false;
    }
    it->key = si.key;
    it->text = si.text;
    it->num = si.num;
    return true;
}

void fw_link_set_settings(fw_link_t *l, fw_settings_t *st)
{
    if (l != NULL) {
        l->settings = st;
        l->settings_cmd = st != NULL ? fw_settings_command : NULL;
        l->settings_item = st != NULL ? fw_settings_item : NULL;
    }
}
