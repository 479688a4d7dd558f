/*
 * Parameters changed over the link on the host closed loop: the firmware's
 * parameter tree (fw_params.h) and changes while the drive runs.
 *
 * Bumpless, against a twin: two runs from the same configuration and seed
 * are identical period by period; one of them gets a live change, and its
 * first output under the new gains is compared with the twin's, which kept
 * the old ones. The difference the transfer leaves is derived from the PI's
 * equations (speed_pi.h, ctrl_foc.h), not measured:
 *  - speed loop (ctrl_speed_pi_retune), run n the first after the change:
 *      u_B - u_A = (Kp_new - Kp_old)(e_n - e*) + (Ki_new - Ki_old) Ts e_n
 *    e* the error the interrupt took the change with, e_n the run's; plus 2
 *    LSB of rounding. A swap of the gains without the integrator's share
 *    steps by (Kp_new - Kp_old) e_n instead; the scenario makes that at
 *    least 5 times the bound, so the check can tell the two apart;
 *  - FOC current PI (foc_retune), the first step after the change: the
 *    integrator is read before it integrates, so
 *      v_B - v_A = (Kp_new - Kp_old)(e_k+1 - e_k)
 *    per axis (e_k the last step's error), plus 2 LSB.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_foc.h"
#include "ctrl_units.h"
#include "fw_link.h"
#include "fw_params.h"
#include "fw_settings.h"
#include "hfi_config.h"
#include "link_text.h"
#include "loop_util.h"
#include "unity.h"

static sim_run_t run_a, run_b;
static fw_link_t link;
static link_text_t lt;
static fw_settings_t st;

void setUp(void)
{
}

void tearDown(void)
{
    sim_run_free(&run_a);
    sim_run_free(&run_b);
}

#define LSB (1.0 / 16777216.0)

static void send(const char *line)
{
    link_text_send(&lt, &link, line);
}

/* Both runs one period, in lockstep; the link (on run B) polled. */
static void both_period(void)
{
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run_a));
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run_b));
    fw_link_poll(&link);
}

/* The application's side (as pil_interactive.c): fw_init with a record's data. */
static int app_apply(void *ctx, const settings_t *s, char *why, size_t cap)
{
    sim_run_t *r = ctx;
    ctrl_machine_t m;
    fw_config_t c;
    if (fw_settings_config(s, &m, &c, r->ctrl_cfg_buf, why, cap) != FW_OK) {
        return CMD_E_FAILED;
    }
    if (fw_init(&r->fw, &r->hal, &c) != FW_OK) {
        (void)fw_explain(&r->fw, why, cap);
        return CMD_E_FAILED;
    }
    return CMD_OK;
}

/* The link on run r with the parameter tree (both tables) written through
 * app_apply. */
static void attach_tree(sim_run_t *r)
{
    fw_link_init(&link, &r->fw, link_text_capture, &lt);
    memset(&st, 0, sizeof st);
    st.apply = app_apply;
    st.ctx = r;
    fw_link_set_settings(&link, &st);
    fw_params_attach(&link, &fw_params_machine);
    fw_params_attach(&link, &fw_params_drive);
}

static double pi_kp(const ctrl_speed_pi_t *pi)
{
    return ldexp((double)pi->kp, -(int)pi->kp_shift);
}

static double pi_ki(const ctrl_speed_pi_t *pi)
{
    return ldexp((double)pi->ki_ts, -(int)pi->ki_shift);
}

static void test_speed_loop_live_is_bumpless(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "m2ptfc", 0.0, 0.0, 1.0, 0.99);
    c.free_mech = true;
    c.speed_mode = true;
    c.speed_ref_rpm = 500.0;
    c.speed_kp = c.speed_ki = 0.0; /* the design's gains (the file gives its own) */
    loop_start(&run_a, &c);
    loop_start(&run_b, &c);
    attach_tree(&run_b);
    while (sim_run_time(&run_b) < 0.3) {
        both_period();
    }
    /* A speed step that the loop follows linearly (P part about 0.5 N*m of
     * the 2.4 N*m limit), then the change 5 ms into it, in the period before
     * a run of the medium task (the interrupt takes it there, e* one period
     * old). */
    fw_set_speed_ref_rpm(&run_a.fw, 700.0);
    fw_set_speed_ref_rpm(&run_b.fw, 700.0);
    const double t_change = sim_run_time(&run_b) + 0.005;
    while (sim_run_time(&run_b) < t_change || run_b.fw.mid_count != 1u) {
        both_period();
    }
    const ctrl_speed_pi_t old = run_b.fw.speed_pi;
    const double bw_old = run_b.fw.speed_info.bandwidth_hz;
    send("param set speed.bw_hz 15");
    TEST_ASSERT_EQUAL_STRING("ok speed.bw_hz 15\r\n", lt.out);
    const double e_star =
        ctrl_q24_to_double(fx_sat32((int64_t)fw_speed_ref(&run_b.fw) - run_b.fw.estimate.omega_e));
    const uint32_t done = run_b.fw.mid_done;
    both_period(); /* takes the change, triggers the run */
    TEST_ASSERT_FALSE(fw_cmd_pending(&run_b.fw, FW_REQ_SPEED_TUNE));
    TEST_ASSERT_EQUAL_UINT32(done + 1u, run_b.fw.mid_done);
    TEST_ASSERT_EQUAL_UINT32(run_a.fw.mid_done, run_b.fw.mid_done);
    const fw_mid_in_t *in = &run_b.fw.mid_in[run_b.fw.mid_done & 1u];
    const double e_n = ctrl_q24_to_double(fx_sat32((int64_t)in->speed_ref - in->omega_e));
    const q24_t ua = run_a.fw.mid_out[run_a.fw.mid_done & 1u].speed_tref;
    const q24_t ub = run_b.fw.mid_out[run_b.fw.mid_done & 1u].speed_tref;
    const ctrl_speed_pi_t *nw = &run_b.fw.speed_pi;
    const double dkp = pi_kp(nw) - pi_kp(&old);
    const double dki = pi_ki(nw) - pi_ki(&old);
    const double bound = fabs(dkp * (e_n - e_star)) + fabs(dki * e_n) + 2.0 * LSB;
    const double step = fabs(ctrl_q24_to_double(ub) - ctrl_q24_to_double(ua));
    const double tb = run_b.fw.bases.torque_nm;
    printf("  speed.bw_hz %.1f -> %.1f Hz live, 5 ms into a 500 -> 700 r/min step: Kp %.4g -> "
           "%.4g pu, e %.4g pu; torque reference %.4f N*m (twin %.4f): step %.2e N*m, bound "
           "%.2e N*m, a swap without the integrator's share %.2e N*m\n",
           bw_old, run_b.fw.speed_info.bandwidth_hz, pi_kp(&old), pi_kp(nw), e_n,
           ctrl_q24_to_double(ub) * tb, ctrl_q24_to_double(ua) * tb, step * tb, bound * tb,
           fabs(dkp * e_n) * tb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 15.0, run_b.fw.speed_info.bandwidth_hz);
    TEST_ASSERT_TRUE(ua < run_a.fw.speed_pi.out_max && ua > -run_a.fw.speed_pi.out_max);
    TEST_ASSERT_TRUE_MESSAGE(fabs(dkp * e_n) > 5.0 * bound, "the scenario cannot tell a bump");
    TEST_ASSERT_TRUE_MESSAGE(step <= bound, "the live change stepped the torque reference");
    /* and the loop still settles at the new reference with the new gains */
    while (sim_run_time(&run_b) < 0.8) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run_b));
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run_b.fw));
    TEST_ASSERT_DOUBLE_WITHIN(14.0, 700.0, sim_run_speed_rpm(&run_b));
}

/* The interrupt may preempt the medium task half-way through a step of the
 * speed PI (PendSV on the boards): so a live change of its gains is taken by
 * the interrupt and applied by the medium task, between two of its steps.
 * The interrupt alone (fw_isr_fast) leaves speed_pi as it was, byte for
 * byte; the run it triggers (fw_medium) has the new gains. */
static void test_speed_retune_applied_by_the_medium_task(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "m2ptfc", 0.0, 0.0, 1.0, 0.99);
    c.free_mech = true;
    c.speed_mode = true;
    c.speed_ref_rpm = 500.0;
    c.speed_kp = c.speed_ki = 0.0;
    loop_start(&run_b, &c);
    attach_tree(&run_b);
    while (sim_run_time(&run_b) < 0.1 || run_b.fw.mid_count != 1u) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run_b));
    }
    const ctrl_speed_pi_t old = run_b.fw.speed_pi;
    send("param set speed.bw_hz 15");
    TEST_ASSERT_EQUAL_STRING("ok speed.bw_hz 15\r\n", lt.out);
    TEST_ASSERT_TRUE(fw_isr_fast(&run_b.fw)); /* takes the change, a run due */
    TEST_ASSERT_FALSE(fw_cmd_pending(&run_b.fw, FW_REQ_SPEED_TUNE));
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&old, &run_b.fw.speed_pi, sizeof old,
                                     "the interrupt wrote the speed PI");
    fw_medium(&run_b.fw);
    TEST_ASSERT_EQUAL_INT32(run_b.fw.speed_pi_next.kp, run_b.fw.speed_pi.kp);
    TEST_ASSERT_EQUAL_INT32(run_b.fw.speed_pi_next.ki_ts, run_b.fw.speed_pi.ki_ts);
    TEST_ASSERT_TRUE(run_b.fw.speed_pi.kp != old.kp);
}

static void test_foc_gain_live_is_bumpless(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "foc", 750.0, 1.2, 1.0, 0.99);
    loop_start(&run_a, &c);
    loop_start(&run_b, &c);
    fw_link_init(&link, &run_b.fw, link_text_capture, &lt);
    while (sim_run_time(&run_b) < 0.05) {
        both_period();
    }
    /* A torque step, the change 0.5 ms into it: the currents still move, the
     * error of the step after the change is many times its change (in other
     * periods of this run the ripple makes them alike: a swap of the gains
     * without the integrator's share could not be told from the transfer). */
    fw_set_torque_ref_nm(&run_a.fw, 2.0);
    fw_set_torque_ref_nm(&run_b.fw, 2.0);
    for (int k = 0; k < 10; k++) {
        both_period();
    }
    const ctrl_foc_state_t *sa = fw_ctrl_state(&run_a.fw);
    const ctrl_foc_state_t *sb = fw_ctrl_state(&run_b.fw);
    const ctrl_foc_state_t old = *sb;
    const double wc = 2.0 * CTRL_PI * (double)run_b.fw.info.pwm_freq_hz / 20.0; /* the default */
    char line[64];
    (void)snprintf(line, sizeof line, "param set wc %.6g", 0.5 * wc);
    send(line);
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok wc", 5));
    both_period();
    TEST_ASSERT_FALSE(fw_cmd_pending(&run_b.fw, FW_REQ_CTRL_TUNE));
    double worst = 0.0;
    double naive = 0.0;
    const ctrl_foc_pi_t *pold[2] = {&old.pi_d, &old.pi_q};
    const ctrl_foc_pi_t *pnew[2] = {&sb->pi_d, &sb->pi_q};
    const q24_t e_old[2] = {old.e_d, old.e_q};
    const q24_t e_new[2] = {sb->e_d, sb->e_q};
    const q24_t va[2] = {sa->v_d, sa->v_q};
    const q24_t vb[2] = {sb->v_d, sb->v_q};
    for (int x = 0; x < 2; x++) {
        TEST_ASSERT_EQUAL_INT32(e_new[x], x == 0 ? sa->e_d : sa->e_q); /* the same step */
        const double dkp = ldexp((double)pnew[x]->kp - pold[x]->kp, -(int)FOC_KP_QBITS);
        const double bound =
            fabs(dkp * (ctrl_q24_to_double(e_new[x]) - ctrl_q24_to_double(e_old[x]))) + 2.0 * LSB;
        const double step = fabs(ctrl_q24_to_double(vb[x]) - ctrl_q24_to_double(va[x]));
        TEST_ASSERT_TRUE_MESSAGE(step <= bound, "the live change stepped the voltage");
        worst = fmax(worst, step / bound);
        naive = fmax(naive, fabs(dkp * ctrl_q24_to_double(e_new[x])) / bound);
    }
    printf("  foc wc %.0f -> %.0f rad/s live, 0.5 ms into a 1.2 -> 2 N*m step: Kp_q %.4g -> "
           "%.4g pu; voltage step at most %.2f of its bound (a swap without the integrator's "
           "share: %.1f times the bound)\n",
           wc, 0.5 * wc, ldexp((double)old.pi_q.kp, -20), ldexp((double)sb->pi_q.kp, -20), worst,
           naive);
    TEST_ASSERT_TRUE_MESSAGE(naive > 5.0, "the scenario cannot tell a bump");
    /* the torque still follows with half the bandwidth */
    while (sim_run_time(&run_b) < 0.1) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run_b));
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run_b.fw));
}

static void periods_b(int n)
{
    link_text_periods(&run_b, &link, n);
}

static void test_parameter_tree(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 1.2, 1.0, 0.99);
    c.speed_kp = c.speed_ki = 0.0; /* the design's gains (the file gives its own) */
    loop_start(&run_b, &c);
    attach_tree(&run_b);
    periods_b(5);

    /* Every entry is a key of the record, readable, listed after the
     * tunables with its unit and range; the speed loop's and fst's tunables
     * are live. */
    send("param list");
    const char *tabs[] = {"fw_params_machine", "fw_params_drive"};
    const fw_params_table_t *t[] = {&fw_params_machine, &fw_params_drive};
    size_t n = 0;
    for (size_t k = 0; k < 2; k++) {
        for (size_t i = 0; i < t[k]->n; i++, n++) {
            char want[48];
            (void)snprintf(want, sizeof want, "\n  %s ", t[k]->p[i].key);
            const char *at = strstr(lt.out, want);
            TEST_ASSERT_NOT_NULL_MESSAGE(at, t[k]->p[i].key);
            TEST_ASSERT_TRUE_MESSAGE(strncmp(at + strlen(want), "? ", 2) != 0, tabs[k]);
            const char *eol = strchr(at + 1, '\n');
            const char *live = strstr(at, "] live ");
            const bool listed_live = live != NULL && live < eol;
            TEST_ASSERT_EQUAL_MESSAGE((t[k]->p[i].flags & FW_PARAM_LIVE) != 0u, listed_live,
                                      t[k]->p[i].key);
        }
    }
#if CTRL_SL_HFI
    /* the injection's settings follow the controller's tunables, read-write
     * (taken at the next start), and the estimator's field takes 2 */
    n += ctrl_hfi_desc.n_tunables;
    for (size_t i = 0; i < ctrl_hfi_desc.n_tunables; i++) {
        char want[48];
        (void)snprintf(want, sizeof want, "\n  %s ", ctrl_hfi_desc.tunables[i].name);
        const char *at = strstr(lt.out, want);
        TEST_ASSERT_NOT_NULL_MESSAGE(at, ctrl_hfi_desc.tunables[i].name);
        const char *eol = strchr(at + 1, '\n');
        const char *live = strstr(at, "] live ");
        TEST_ASSERT_TRUE_MESSAGE(live == NULL || live > eol, ctrl_hfi_desc.tunables[i].name);
        TEST_ASSERT_TRUE(at < strstr(lt.out, "  m.p "));
    }
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  est.sensorless 0 - [0, 2] "));
#else
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  est.sensorless 0 - [0, 1] "));
#endif
    char head[16];
    (void)snprintf(head, sizeof head, "ok %u\r\n", (unsigned)(run_b.fw.ctrl->n_tunables + n));
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, head, strlen(head)));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "] live corner of the mean-torque-error integrator"));
    TEST_ASSERT_TRUE(strstr(lt.out, "  f_i ") < strstr(lt.out, "  m.p "));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  speed.bw_hz 0 Hz [0, 10000] live speed-loop crossover"));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  speed.kp 0 N*m*s/rad [0, 1000000] live speed PI Kp"));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  m.rs_ohm 0.901 ohm [0, 100] stator"));

    /* Running: live ones change, the others are refused naming why. */
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run_b.fw));
    send("param set m.rs_ohm 1");
    TEST_ASSERT_EQUAL_STRING("err 8 state in running: m.rs_ohm changes with the gates off only\r\n",
                             lt.out);
    send("param set speed.unit 1");
    TEST_ASSERT_EQUAL_STRING(
        "err 8 state in running: speed.unit changes with the gates off only\r\n", lt.out);
    send("param set f_i 20");
    TEST_ASSERT_EQUAL_STRING("ok f_i 20\r\n", lt.out);
    send("param set sigma 0.1"); /* the previous change not yet taken */
    TEST_ASSERT_EQUAL_STRING("err 8 state in running: the last live change is not taken yet\r\n",
                             lt.out);
    periods_b(1);
    send("param set sigma 0.1");
    TEST_ASSERT_EQUAL_STRING("ok sigma 0.1\r\n", lt.out);
    periods_b(1);
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run_b.fw, "f_i", &v));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 20.0, v);
    send("param set speed.pm_deg 10"); /* the design's range: refused, in force unchanged */
    TEST_ASSERT_EQUAL_STRING("err 10 failed speed loop: bandwidth above what the phase margin "
                             "allows, or margin outside [20, 80] deg\r\n",
                             lt.out);
    send("param get speed.pm_deg");
    TEST_ASSERT_EQUAL_STRING("ok speed.pm_deg 0 deg\r\n", lt.out);
    send("param set speed.pm_deg 45");
    TEST_ASSERT_EQUAL_STRING("ok speed.pm_deg 45\r\n", lt.out);
    periods_b(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 45.0, run_b.fw.speed_info.phase_margin_deg);
    /* A gain makes both explicit, the other as in force; the bandwidth
     * designs them again. */
    const double ki_design = run_b.fw.speed_info.ki_nm_rad;
    send("param set speed.kp 0.05");
    TEST_ASSERT_EQUAL_STRING("ok speed.kp 0.05\r\n", lt.out);
    periods_b(1);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.05, run_b.fw.cfg.speed_kp);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12 * ki_design, ki_design, run_b.fw.cfg.speed_ki);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.05, run_b.fw.speed_info.kp_nm_s_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, run_b.fw.speed_info.bandwidth_hz); /* explicit */
    send("param set speed.bw_hz 20");
    TEST_ASSERT_EQUAL_STRING("ok speed.bw_hz 20\r\n", lt.out);
    periods_b(1);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, run_b.fw.cfg.speed_kp);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 20.0, run_b.fw.speed_info.bandwidth_hz);

    /* Gates off: the record path (the drive calibrates again), tunables and
     * the rest of the configuration kept; telemetry goes on. */
    send("tel start torque every 10");
    send("disarm");
    periods_b(2);
    send("param set inv.v_fwd_v 0.7");
    TEST_ASSERT_EQUAL_STRING("ok inv.v_fwd_v 0.7\r\n", lt.out);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.7, run_b.fw.cfg.v_fwd_v);
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run_b.fw, "f_i", &v));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 20.0, v);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 45.0, run_b.fw.cfg.speed_pm_deg);
    lt.zeros = 0;
    periods_b(300); /* the calibration again */
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run_b.fw));
    TEST_ASSERT_TRUE_MESSAGE(lt.zeros >= 2u * 20u, "telemetry stopped by the reconfiguration");
    send("tel stop");
    send("param set enc.offset 90");
    TEST_ASSERT_EQUAL_STRING("ok enc.offset 90\r\n", lt.out);
    send("param get enc.offset");
    TEST_ASSERT_EQUAL_STRING("ok enc.offset 90 deg\r\n", lt.out);
    TEST_ASSERT_EQUAL_UINT32(0x40000000u, run_b.fw.enc_offset);
    send("param set enc.offset 0");
    send("param set enc.dir 0");
    TEST_ASSERT_EQUAL_STRING("err 4 range [-1, 1]\r\n", lt.out);
    send("param set m.p 2.5");
    TEST_ASSERT_EQUAL_STRING("err 4 range [1, 50], whole numbers\r\n", lt.out);
    /* The core refuses a machine it cannot represent: its reason, and the
     * configuration before it in force again. */
    const ctrl_machine_t m_before = run_b.fw.machine_own;
    send("param set m.ld_h 10");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 10 failed ", 14));
    TEST_MESSAGE(lt.out);
    TEST_ASSERT_TRUE(strstr(lt.out, "outside") != NULL || strstr(lt.out, "missing") != NULL);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, m_before.ld_h, run_b.fw.machine_own.ld_h);
    TEST_ASSERT_EQUAL_STRING("fst", run_b.fw.ctrl->name);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.7, run_b.fw.cfg.v_fwd_v);
    periods_b(300);
    send("arm");
    periods_b(2000);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run_b.fw));
}

/* Every line of every controller's listing whole: the interpreter cuts a
 * response line at CMD_OUT_MAX bytes with its "\r\n" (cmd.c), and a help text
 * that reaches the cut reaches the page cut. A line of CMD_OUT_MAX - 2
 * characters may have been cut: none may be that long. */
static void test_listing_lines_whole(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 1.2, 1.0, 0.99);
    loop_start(&run_b, &c);
    attach_tree(&run_b);
    periods_b(5);
    send("disarm");
    periods_b(5);
    for (size_t k = 0; ctrl_at(k) != NULL; k++) {
        const char *name = ctrl_at(k)->name;
        char line[48];
        (void)snprintf(line, sizeof line, "ctrl select %s", name);
        send(line);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(lt.out, "ok", 2), lt.out);
        periods_b(2);
        send("param list");
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(lt.out, "ok ", 3), lt.out);
        for (const char *at = lt.out; *at != '\0';) {
            const char *eol = strstr(at, "\r\n");
            TEST_ASSERT_NOT_NULL(eol);
            char msg[CMD_OUT_MAX + 48];
            (void)snprintf(msg, sizeof msg, "%s: %.*s", name, (int)(eol - at), at);
            TEST_ASSERT_TRUE_MESSAGE((size_t)(eol - at) < CMD_OUT_MAX - 2u, msg);
            at = eol + 2;
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_speed_loop_live_is_bumpless);
    RUN_TEST(test_speed_retune_applied_by_the_medium_task);
    RUN_TEST(test_foc_gain_live_is_bumpless);
    RUN_TEST(test_parameter_tree);
    RUN_TEST(test_listing_lines_whole);
    return UNITY_END();
}
