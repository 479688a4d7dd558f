/* The control interrupt of the B-G431B-ESC1 image (esc1_app.h). */
#include "esc1_app.h"

void esc1_control_isr(esc1_t *s)
{
    g4_hal_adc_irq_ack(&s->hal);
    fw_isr(&s->fw);
    s->isr_count++;
}
