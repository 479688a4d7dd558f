/* hal.h on QEMU mps2-an386 with the plant in the loop (see hal_qemu.h). */
#include "hal_qemu.h"

#include <stddef.h>
#include <string.h>

#include "qemu_mps2.h"

int hal_qemu_init(hal_t *h, hal_qemu_plant_t *plant, uint32_t cpu_hz)
{
    if (h == NULL || plant == NULL || cpu_hz == 0u) {
        return HAL_QEMU_EINVAL;
    }
    memset(h, 0, sizeof *h);
    h->plant = plant;
    hal_qemu_plant_info(plant, &h->info);
    h->ticks_per_kinstr = timer1_ticks_per_kinstr();
    /* Budget cpu_hz / fs instructions (1 instruction per cycle) expressed in
     * Timer1 ticks: ticks = instructions * ticks_per_kinstr / 1000. */
    const uint64_t hz = (uint64_t)cpu_hz * h->ticks_per_kinstr / 1000u;
    h->info.cycle_clock_hz = hz > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)hz;
    h->plant_rc = PLANT_OK;
    return HAL_QEMU_OK;
}

int hal_qemu_period_end(hal_t *h)
{
    if (h == NULL) {
        return PLANT_EINVAL;
    }
    if (h->primed) {
        /* The period that just ended, with the compare values active in it. */
        const int rc = hal_qemu_plant_end(h->plant);
        if (rc != PLANT_OK && h->plant_rc == PLANT_OK) {
            h->plant_rc = rc;
        }
        h->primed = false;
    }
    return h->plant_rc;
}

void hal_qemu_period_begin(hal_t *h)
{
    if (h != NULL) {
        hal_qemu_plant_begin(h->plant);
        h->primed = true;
        h->periods++;
    }
}

hal_qemu_plant_t *hal_qemu_plant_models(hal_t *h)
{
    return h != NULL ? h->plant : NULL;
}

/* CMSDK UART0 (QEMU.md): DATA +0x0, STATE +0x4 (bit 1: RX buffer full),
 * CTRL +0x8 (bit 0 TX enable, set by board_init; bit 1 RX enable). */
#define HAL_QEMU_UART0_DATA (*(volatile uint32_t *)0x40004000u)
#define HAL_QEMU_UART0_STATE (*(volatile uint32_t *)0x40004004u)
#define HAL_QEMU_UART0_CTRL (*(volatile uint32_t *)0x40004008u)

void hal_qemu_uart_rx_enable(void)
{
    HAL_QEMU_UART0_CTRL |= 0x2u;
}

int hal_qemu_uart_getc(void)
{
    if ((HAL_QEMU_UART0_STATE & 0x2u) == 0u) {
        return -1;
    }
    return (int)(HAL_QEMU_UART0_DATA & 0xFFu);
}

uint32_t hal_qemu_ticks_per_kinstr(const hal_t *h)
{
    return h != NULL ? h->ticks_per_kinstr : 0u;
}

uint32_t hal_qemu_ticks_to_instr(const hal_t *h, uint32_t ticks)
{
    if (h == NULL || h->ticks_per_kinstr == 0u) {
        return 0u;
    }
    const uint64_t n = ((uint64_t)ticks * 1000u + h->ticks_per_kinstr / 2u) / h->ticks_per_kinstr;
    return n > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)n;
}

/* ---- hal.h ---- */

void hal_info_get(const hal_t *h, hal_info_t *info)
{
    if (h != NULL && info != NULL) {
        *info = h->info;
    }
}

void hal_adc_read(hal_t *h, hal_adc_raw_t *raw)
{
    if (h != NULL) {
        hal_qemu_plant_adc(h->plant, raw);
    }
}

void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc)
{
    if (h != NULL) {
        hal_qemu_plant_encoder(h->plant, enc);
    }
}

void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm)
{
    if (h != NULL) {
        hal_qemu_plant_pwm(h->plant, pwm);
    }
}

void hal_ctrl_hold(hal_t *h, bool hold)
{
    if (h == NULL) {
        return;
    }
    if (hold) {
        if (h->hold_depth++ == 0u) {
            h->hold_was_on = board_timer0_irq_mask();
        }
    } else if (h->hold_depth != 0u && --h->hold_depth == 0u && h->hold_was_on) {
        board_timer0_irq_unmask();
    }
}

void hal_gate_enable(hal_t *h, bool enable)
{
    if (h != NULL) {
        hal_qemu_plant_gate(h->plant, enable);
    }
}

bool hal_trip_active(const hal_t *h)
{
    return h != NULL && hal_qemu_plant_trip(h->plant);
}

void hal_trip_clear(hal_t *h)
{
    if (h != NULL) {
        hal_qemu_plant_trip_clear(h->plant);
    }
}

uint32_t hal_cycles(const hal_t *h)
{
    (void)h;
    return timer1_read();
}
