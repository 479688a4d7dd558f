/* The throttle on the B-G431B-ESC1's PWM pad (esc1_app.h): TIM2 captures to
 * the hardware-free decoder (firmware/throttle), its decisions to the drive. */
#include "esc1_app.h"
#include "g4_periph.h"
#include "g4_tim.h"

void esc1_throttle_init(esc1_t *s, uint32_t f_cpu_hz)
{
    /* TIM2 counting microseconds. An unplugged pad reads low (pull-down): no
     * edges, no pulses. Decoding starts when throttle.mode is set. */
    thr_config_t c;
    thr_config_default(&c);
    thr_init(&s->thr, &c, s->now_ms);
    g4_gpio_config(s->hal.board->throttle, G4_PIN_AF, 2u);
    g4_tim2_capture_init(f_cpu_hz / 1000000u - 1u, s->hal.board->throttle_filter);
}

void esc1_throttle_poll(esc1_t *s)
{
    thr_t *t = &s->thr;
    if (t->cfg.mode == THR_MODE_OFF) {
        return;
    }
    uint32_t width, period;
    if (g4_tim2_capture_read(&width, &period)) {
        thr_pulse(t, width, period, s->now_ms); /* 1 MHz ticks: us */
    }
    fw_t *fw = &s->fw;
    if (t->state == THR_ARMED && !fw_gates_on_or_pending(fw)) {
        /* The drive left running without the throttle (a fault, a link
         * disarm or stop, a refused arm): the stick must come back to its low
         * end for 1 s before it drives again, as at power-up. */
        thr_init(t, &t->cfg, s->now_ms);
    }
    const uint8_t before = t->state;
    const thr_out_t o = thr_update(t, s->now_ms);
    const bool speed = t->cfg.mode == THR_MODE_SPEED;
    if (o.event == THR_EV_ARM) {
        fw_set_torque_ref(fw, 0);
        fw_cmd_arm(fw);
    }
    if (t->state == THR_ARMED) {
        if (speed) {
            fw_set_speed_ref_rpm(fw, (double)o.ref / FX_ONE * fw->speed_info.speed_ref_max_rpm);
            s->thr_tref = fw_speed_loop_torque(fw); /* the medium task's last */
        } else {
            fw_set_torque_ref(fw, fx_mul(o.ref, fw->torque_ref_max));
        }
    } else if (t->state == THR_RAMP_DOWN) {
        /* Torque to zero along the ramp: the throttle's torque, or in speed
         * mode the speed loop's last torque. */
        fw_set_torque_ref(fw,
                          speed ? fx_mul(s->thr_tref, o.ramp) : fx_mul(o.ref, fw->torque_ref_max));
        if (before == THR_ARMED) {
            s->thr_losses++; /* the main loop says so (not from inside a write) */
        }
    }
    if (o.event == THR_EV_DISARM) {
        fw_set_torque_ref(fw, 0);
        fw_cmd_disarm(fw);
    }
}
