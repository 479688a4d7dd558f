/* TI DRV8301 over SPI: frames, configuration, read-back, faults (drv8301.h). */
#include "drv8301.h"

#include <stdio.h>
#include <string.h>

/* OC_ADJ_SET -> VDS threshold, mV (data sheet table "Over-current
 * adjustment"; the same 32 values in TI MotorWare's DRV8301_VdsLevel_e). */
static const uint16_t drv8301_vds_table[32] = {
    60,  68,  76,  86,  97,  109, 123, 138, 155,  175,  197,  222,  250,  282,  317,  358,
    403, 454, 511, 576, 648, 730, 822, 926, 1043, 1175, 1324, 1491, 1679, 1892, 2131, 2400,
};

uint16_t drv8301_frame(bool read, uint32_t addr, uint32_t data)
{
    return (uint16_t)((read ? DRV8301_FRAME_READ : 0u) |
                      ((addr << DRV8301_FRAME_ADDR_POS) & DRV8301_FRAME_ADDR_MASK) |
                      (data & DRV8301_FRAME_DATA_MASK));
}

int drv8301_words(const drv8301_cfg_t *c, uint16_t *cr1, uint16_t *cr2)
{
    if (c->gate_current > 2u || c->ocp_mode > 3u || c->oc_adj > 31u || c->gain > 3u ||
        c->octw_mode > 2u) {
        return DRV8301_E_CONFIG;
    }
    /* PWM_MODE 0 (six inputs: TIM1's complementary outputs with their dead
     * time), GATE_RESET 0. */
    *cr1 = (uint16_t)((uint32_t)c->gate_current | ((uint32_t)c->ocp_mode << 4) |
                      ((uint32_t)c->oc_adj << 6));
    /* DC_CAL_CH1/2 0: the amplifiers measure. */
    *cr2 =
        (uint16_t)((uint32_t)c->octw_mode | ((uint32_t)c->gain << 2) | (c->oc_toff ? 0x40u : 0u));
    return DRV8301_OK;
}

uint32_t drv8301_vds_mv(uint32_t oc_adj)
{
    return oc_adj < 32u ? drv8301_vds_table[oc_adj] : 0u;
}

int drv8301_oc_adj_at_most(uint32_t vds_mv)
{
    int code = -1;
    for (int i = 0; i < 32; i++) {
        if (drv8301_vds_table[i] <= vds_mv) {
            code = i;
        }
    }
    return code;
}

uint32_t drv8301_gain(uint32_t code)
{
    return DRV8301_GAIN_VV(code);
}

int drv8301_read(drv8301_t *d, uint32_t addr, uint16_t *data)
{
    uint16_t prev = 0u, in = 0u;
    /* The read command, then the same again: its response word is the
     * first one's answer (the first frame's own response answers the frame
     * before it). */
    const uint16_t cmd = drv8301_frame(true, addr, 0u);
    d->reg = (uint8_t)addr;
    d->answer = 0u;
    if (d->port.xfer(d->port.ctx, cmd, &prev) != 0 || d->port.xfer(d->port.ctx, cmd, &in) != 0) {
        return DRV8301_E_SPI;
    }
    d->answer = in;
    if (((uint32_t)in & DRV8301_FRAME_ADDR_MASK) >> DRV8301_FRAME_ADDR_POS != addr) {
        return DRV8301_E_SILENT;
    }
    /* Bit 15 of a response word: the frame it answers was not a valid
     * 16-clock frame and was ignored (a write lost, a read not done): the
     * data cannot be trusted. Checked after the address, so that a bus
     * pulled up (0xFFFF) stays "no answer". */
    if (((prev | in) & DRV8301_FRAME_ERROR) != 0u) {
        d->answer = (in & DRV8301_FRAME_ERROR) != 0u ? in : prev;
        return DRV8301_E_SPI;
    }
    *data = (uint16_t)(in & DRV8301_FRAME_DATA_MASK);
    return DRV8301_OK;
}

int drv8301_write(drv8301_t *d, uint32_t addr, uint32_t data)
{
    uint16_t in = 0u;
    if (d->port.xfer(d->port.ctx, drv8301_frame(false, addr, data), &in) != 0) {
        d->reg = (uint8_t)addr;
        d->answer = 0u;
        return DRV8301_E_SPI;
    }
    return DRV8301_OK;
}

/* Status 1 and 2 into d->status; DRV8301_E_FAULT when a bit is set. */
static int drv8301_status(drv8301_t *d)
{
    for (uint32_t r = 0u; r < 2u; r++) {
        const int rc = drv8301_read(d, DRV8301_REG_STATUS1 + r, &d->status[r]);
        if (rc != DRV8301_OK) {
            return rc;
        }
    }
    if (d->status[0] != 0u || (d->status[1] & DRV8301_S2_GVDD_OV) != 0u) {
        d->reg = DRV8301_REG_STATUS1;
        return DRV8301_E_FAULT;
    }
    return DRV8301_OK;
}

/* CR1 and CR2 read back into d->got; DRV8301_E_READBACK when either differs
 * from d->want. The control registers first: a silent bus reading all
 * zeros would pass as an empty status 1 (address 0). */
static int drv8301_readback(drv8301_t *d)
{
    for (uint32_t i = 0u; i < 2u; i++) {
        const int rc = drv8301_read(d, DRV8301_REG_CONTROL1 + i, &d->got[i]);
        if (rc != DRV8301_OK) {
            return rc;
        }
    }
    for (uint32_t i = 0u; i < 2u; i++) {
        if (d->got[i] != d->want[i]) {
            d->reg = (uint8_t)(DRV8301_REG_CONTROL1 + i);
            return DRV8301_E_READBACK;
        }
    }
    return DRV8301_OK;
}

int drv8301_configure(drv8301_t *d, const drv8301_cfg_t *c)
{
    memset(d->got, 0, sizeof d->got);
    memset(d->status, 0, sizeof d->status);
    d->answer = 0u;
    d->reg = 0u;
    int rc = drv8301_words(c, &d->want[0], &d->want[1]);
    for (unsigned attempt = 0u; rc == DRV8301_OK && attempt < 3u; attempt++) {
        rc = drv8301_write(d, DRV8301_REG_CONTROL1, d->want[0]);
        if (rc == DRV8301_OK) {
            rc = drv8301_write(d, DRV8301_REG_CONTROL2, d->want[1]);
        }
        if (rc == DRV8301_OK) {
            rc = drv8301_readback(d);
        }
        if (rc != DRV8301_E_READBACK) {
            break; /* as written, or a transport / silence error */
        }
        if (attempt < 2u) {
            rc = DRV8301_OK; /* differs: written again */
        }
    }
    if (rc == DRV8301_OK) {
        rc = drv8301_status(d);
    }
    d->err = rc;
    return rc;
}

int drv8301_check(drv8301_t *d)
{
    int rc = drv8301_readback(d);
    if (rc == DRV8301_OK) {
        rc = drv8301_status(d);
    }
    d->err = rc;
    return rc;
}

int drv8301_gate_reset(drv8301_t *d)
{
    const int rc = drv8301_write(d, DRV8301_REG_CONTROL1, d->want[0] | DRV8301_CR1_GATE_RESET);
    d->err = rc;
    return rc;
}

size_t drv8301_fault_names(uint16_t s1, uint16_t s2, char *buf, size_t cap)
{
    static const char *const names[11] = {
        "FETLC_OC", "FETHC_OC", "FETLB_OC", "FETHB_OC", "FETLA_OC", "FETHA_OC",
        "OTW",      "OTSD",     "PVDD_UV",  "GVDD_UV",  "FAULT",
    };
    size_t n = 0u;
    if (cap > 0u) {
        buf[0] = '\0';
    }
    for (unsigned b = 0u; b < 12u; b++) {
        const bool set = b < 11u ? (s1 & (1u << b)) != 0u : (s2 & DRV8301_S2_GVDD_OV) != 0u;
        if (set) {
            const int k = snprintf(buf + n, cap > n ? cap - n : 0u, "%s%s", n > 0u ? " " : "",
                                   b < 11u ? names[b] : "GVDD_OV");
            n += k > 0 ? (size_t)k : 0u;
        }
    }
    if (n == 0u) {
        const int k = snprintf(buf, cap, "none");
        n = k > 0 ? (size_t)k : 0u;
    }
    return n < cap ? n : (cap > 0u ? cap - 1u : 0u);
}

const char *drv8301_strerror(int rc)
{
    switch (rc) {
    case DRV8301_OK:
        return "ok";
    case DRV8301_E_CONFIG:
        return "configuration has no register encoding";
    case DRV8301_E_SPI:
        return "SPI time-out or frame error";
    case DRV8301_E_SILENT:
        return "no answer on SPI";
    case DRV8301_E_READBACK:
        return "read-back differs";
    case DRV8301_E_FAULT:
        return "fault reported";
    default:
        return "unknown";
    }
}

size_t drv8301_explain(const drv8301_t *d, char *buf, size_t cap)
{
    int k;
    switch (d->err) {
    case DRV8301_E_SILENT:
        k = snprintf(buf, cap, "no answer on SPI (register %u came back as 0x%x)", (unsigned)d->reg,
                     (unsigned)d->answer);
        break;
    case DRV8301_E_SPI:
        if ((d->answer & DRV8301_FRAME_ERROR) != 0u) {
            k = snprintf(buf, cap, "SPI frame error (register %u, answer 0x%x)", (unsigned)d->reg,
                         (unsigned)d->answer);
        } else {
            k = snprintf(buf, cap, "SPI time-out (register %u)", (unsigned)d->reg);
        }
        break;
    case DRV8301_E_READBACK:
        k = snprintf(buf, cap, "control %u reads 0x%x, wrote 0x%x",
                     (unsigned)(d->reg - DRV8301_REG_CONTROL1 + 1u),
                     (unsigned)d->got[d->reg - DRV8301_REG_CONTROL1],
                     (unsigned)d->want[d->reg - DRV8301_REG_CONTROL1]);
        break;
    case DRV8301_E_FAULT: {
        char names[96];
        (void)drv8301_fault_names(d->status[0], d->status[1], names, sizeof names);
        k = snprintf(buf, cap, "fault %s", names);
        break;
    }
    default:
        k = snprintf(buf, cap, "%s", drv8301_strerror(d->err));
        break;
    }
    const size_t n = k > 0 ? (size_t)k : 0u;
    return n < cap ? n : (cap > 0u ? cap - 1u : 0u);
}
