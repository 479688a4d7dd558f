/* The DRV8301 SPI model (drv8301_model.h). */
#include "drv8301_model.h"

#include <string.h>

#include "f4_model.h"

drv8301_model_t drv8301_model;

static void drv8301_model_reset_regs(void)
{
    drv8301_model_t *m = &drv8301_model;
    memset(m->reg, 0, sizeof m->reg);
    m->reg[1] = 0x001u; /* device ID 1 (status 2 bits 3:0) */
    m->next = 0u;
    m->lost = 0u;
    /* A condition that persists (an under-voltage) latches again at once. */
    m->reg[0] = m->persist1;
    f4_model_pin_in(m->nfault.port, m->nfault.pin, m->persist1 == 0u);
}

static uint16_t drv8301_model_frame(uint32_t spi, uint16_t out)
{
    drv8301_model_t *m = &drv8301_model;
    const bool enabled = f4_model_pin_out(m->en_gate.port, m->en_gate.pin);
    const bool selected = !f4_model_pin_out(m->cs.port, m->cs.pin);
    if (spi != m->spi || !m->connected || !selected) {
        return m->idle;
    }
    if (!enabled) {
        m->was_enabled = false;
        return m->idle; /* SPI off while EN_GATE is low */
    }
    if (!m->was_enabled) {
        drv8301_model_reset_regs(); /* EN_GATE went low then high: reset */
        m->was_enabled = true;
    }
    m->frames++;
    const uint16_t answer = m->next;
    const uint32_t addr = (out >> 11) & 0xFu;
    const uint16_t data = (uint16_t)(out & 0x7FFu);
    if (m->frame_fault) {
        /* Ignored; its answer carries the frame-error bit. */
        m->next = (uint16_t)(0x8000u | (addr << 11));
        return answer;
    }
    if ((out & 0x8000u) != 0u) {
        const uint16_t v = addr < 4u ? m->reg[addr] : 0u;
        m->next = (uint16_t)((addr << 11) | v);
        if (addr == 0u) {
            m->reg[0] = m->persist1; /* status 1 clears on read */
        } else if (addr == 1u) {
            m->reg[1] = 0x001u; /* GVDD_OV clears on read */
        }
    } else {
        m->writes++;
        if (addr == 2u || addr == 3u) {
            if (m->lost < m->lose_writes) {
                m->lost++;
            } else {
                uint16_t v = (uint16_t)(data & ~m->stuck_zero[addr - 2u]);
                if (addr == 2u && (v & 0x004u) != 0u) {
                    /* GATE_RESET: latched faults cleared, the bit reads 0 */
                    m->gate_resets++;
                    m->reg[0] = m->persist1;
                    v &= (uint16_t)~0x004u;
                    if (m->persist1 == 0u) {
                        f4_model_pin_in(m->nfault.port, m->nfault.pin, true);
                    }
                }
                m->reg[addr] = v;
            }
        }
        m->next = (uint16_t)((addr << 11) | (addr < 4u ? m->reg[addr] : 0u));
    }
    return answer;
}

void drv8301_model_attach(f4_pin_t en_gate, f4_pin_t cs, f4_pin_t nfault, uint32_t spi)
{
    memset(&drv8301_model, 0, sizeof drv8301_model);
    drv8301_model.en_gate = en_gate;
    drv8301_model.cs = cs;
    drv8301_model.nfault = nfault;
    drv8301_model.spi = spi;
    drv8301_model.connected = true;
    drv8301_model_reset_regs();
    f4_model.spi_peer = drv8301_model_frame;
}

void drv8301_model_fault(uint16_t status1, bool persist)
{
    drv8301_model.reg[0] = (uint16_t)(drv8301_model.reg[0] | status1 | 0x400u);
    if (persist) {
        drv8301_model.persist1 = (uint16_t)(drv8301_model.persist1 | status1 | 0x400u);
    }
    f4_model_pin_in(drv8301_model.nfault.port, drv8301_model.nfault.pin, false);
}
