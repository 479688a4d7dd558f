/* The control interrupt of the STM32F405 board images (f405_app.h). */
#include "f405_app.h"
#include "f4_core.h"

void f405_control_isr(f405_t *s)
{
    f4_hal_adc_irq_ack(&s->hal);
    if (fw_isr_fast(&s->app.fw)) {
        f4_pendsv_pend(); /* the medium-rate task (PendSV_Handler, f405_main.c) */
    }
    s->app.isr_count++;
}
