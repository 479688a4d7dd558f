/* The control interrupt of the B-G431B-ESC1 image (esc1_app.h). */
#include "esc1_app.h"
#include "g4_core.h"

void esc1_control_isr(esc1_t *s)
{
    g4_hal_adc_irq_ack(&s->hal);
    if (fw_isr_fast(&s->fw)) {
        g4_pendsv_pend(); /* the medium-rate task (PendSV_Handler, esc1_main.c) */
    }
    s->isr_count++;
}
