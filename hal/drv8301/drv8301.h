/*
 * TI DRV8301 three-phase gate driver (with two current-sense amplifiers and
 * a buck converter) behind its SPI interface: the frames, the configuration
 * words, the read-back check and the fault names. Hardware-free: the board
 * gives a transport that exchanges one 16-bit frame with the chip selected.
 *
 * Facts (TI DRV8301 data sheet SLOS719 and its automotive twin SLOS842
 * "SPI Communication", "SPI Control and Status Registers"; the same in the
 * register maps of TI's MotorWare drv8301.h, VESC hwconf/drv8301.c and ODrive
 * Firmware/Drivers/DRV8301):
 *   - SPI mode 1 (CPOL 0, CPHA 1: data sampled on the falling SCLK edge),
 *     16-bit frames, MSB first, SCLK up to 10 MHz.
 *   - Command word: bit 15 R/W (1 = read), bits 14:11 address, bits 10:0
 *     data. The response word shifted out during a frame answers the
 *     PREVIOUS frame: bit 15 frame-error flag (F0 in SLOS842 table 4 "SPI
 *     Output Data Response Word Format"), bits 14:11 the address of the
 *     register it carries, bits 10:0 its data. A read therefore takes two
 *     frames.
 *   - Registers: 0 status 1, 1 status 2 (read-only; status bits latch until
 *     read), 2 control 1, 3 control 2 (read/write, 0 after reset).
 *   - Control 1: GATE_CURRENT 1:0 (00 1.7 A, 01 0.7 A, 10 0.25 A peak),
 *     GATE_RESET 2 (1 resets the latched faults, then reads 0), PWM_MODE 3
 *     (0 = six PWM inputs), OCP_MODE 5:4 (00 cycle-by-cycle current limit,
 *     01 latch shut down, 10 report only, 11 disabled), OC_ADJ_SET 10:6 (the
 *     VDS over-current threshold, table below).
 *   - Control 2: OCTW_MODE 1:0 (00 over-temperature and over-current on
 *     nOCTW, 01 over-temperature only, 10 over-current only), GAIN 3:2 (10,
 *     20, 40, 80 V/V), DC_CAL_CH1 4, DC_CAL_CH2 5 (inputs shorted for offset
 *     calibration), OC_TOFF 6 (0 cycle by cycle, 1 off-time control).
 *   - Status 1: FETLC_OC 0, FETHC_OC 1, FETLB_OC 2, FETHB_OC 3, FETLA_OC 4,
 *     FETHA_OC 5, OTW 6, OTSD 7, PVDD_UV 8, GVDD_UV 9, FAULT 10. Status 2:
 *     device ID 3:0, GVDD_OV 7.
 *   - EN_GATE low for more than 20 us resets the device (its registers
 *     too); SPI is ready at most 10 ms after EN_GATE rises (ODrive's driver
 *     waits 20 ms).
 */
#ifndef HAL_DRV8301_DRV8301_H
#define HAL_DRV8301_DRV8301_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define DRV8301_REG_STATUS1 0u
#define DRV8301_REG_STATUS2 1u
#define DRV8301_REG_CONTROL1 2u
#define DRV8301_REG_CONTROL2 3u

#define DRV8301_FRAME_READ 0x8000u  /* command word: read */
#define DRV8301_FRAME_ERROR 0x8000u /* response word: the answered frame was invalid */
#define DRV8301_FRAME_ADDR_POS 11u
#define DRV8301_FRAME_ADDR_MASK 0x7800u
#define DRV8301_FRAME_DATA_MASK 0x07FFu

#define DRV8301_CR1_GATE_RESET 0x004u
#define DRV8301_S1_FAULT 0x400u
#define DRV8301_S2_GVDD_OV 0x080u
#define DRV8301_S2_ID_MASK 0x00Fu

#define DRV8301_RESET_US 40u        /* EN_GATE low: above the 20 us full reset */
#define DRV8301_SPI_READY_US 20000u /* EN_GATE high to the first frame */

/* Return codes. */
#define DRV8301_OK 0
#define DRV8301_E_CONFIG (-1)   /* a field outside its encoding */
#define DRV8301_E_SPI (-2)      /* the transport failed (SPI time-out) or a frame error */
#define DRV8301_E_SILENT (-3)   /* the answer names another register: nothing answered */
#define DRV8301_E_READBACK (-4) /* a control register reads back other than written */
#define DRV8301_E_FAULT (-5)    /* the status registers report a fault */

typedef struct {
    uint8_t gate_current; /* CR1 GATE_CURRENT code 0..2 */
    uint8_t ocp_mode;     /* CR1 OCP_MODE 0..3 */
    uint8_t oc_adj;       /* CR1 OC_ADJ_SET 0..31 (drv8301_vds_mv) */
    uint8_t gain;         /* CR2 GAIN code 0..3 (drv8301_gain) */
    uint8_t octw_mode;    /* CR2 OCTW_MODE 0..2 */
    bool oc_toff;         /* CR2 OC_TOFF */
} drv8301_cfg_t;

/* One frame with the chip selected (the transport raises and lowers nSCS
 * and keeps its high time between frames): 0 or a negative transport
 * code. */
typedef struct {
    int (*xfer)(void *ctx, uint16_t out, uint16_t *in);
    void *ctx;
} drv8301_port_t;

typedef struct {
    drv8301_port_t port;
    uint16_t want[2];   /* CR1, CR2 as configured (11 data bits) */
    uint16_t got[2];    /* as last read back */
    uint16_t answer;    /* the last response word (whole frame) */
    uint16_t status[2]; /* status 1, 2 as last read */
    uint8_t reg;        /* the register the last error concerns */
    int err;            /* the last operation's result */
} drv8301_t;

/* Command word. */
uint16_t drv8301_frame(bool read, uint32_t addr, uint32_t data);
/* Control words (11 data bits) of a configuration; DRV8301_E_CONFIG when a
 * code is reserved or out of range. */
int drv8301_words(const drv8301_cfg_t *c, uint16_t *cr1, uint16_t *cr2);
/* The VDS threshold of an OC_ADJ_SET code, mV (0.060 V .. 2.400 V); 0 for a
 * code above 31. */
uint32_t drv8301_vds_mv(uint32_t oc_adj);
/* The largest OC_ADJ_SET code whose threshold is at most vds_mv; -1 below
 * the smallest (60 mV). */
int drv8301_oc_adj_at_most(uint32_t vds_mv);
/* Amplifier gain of a GAIN code, V/V (10, 20, 40, 80); the macro for a
 * constant initialiser (a board's sense gain). */
#define DRV8301_GAIN_VV(code) (10u << ((code)&3u))
uint32_t drv8301_gain(uint32_t code);

/* A register's 11 data bits: a read frame, then a second frame whose
 * response must carry that register's address. DRV8301_OK, _E_SILENT
 * (d->answer says what came back) or _E_SPI: the transport failed, or
 * either response word has its frame-error bit set (d->answer is that
 * word). */
int drv8301_read(drv8301_t *d, uint32_t addr, uint16_t *data);
int drv8301_write(drv8301_t *d, uint32_t addr, uint32_t data);
/* Writes CR1 then CR2 and reads both back, up to three times while they
 * differ (the first frames after EN_GATE rises may be lost: ODrive writes
 * its CR1 five times); then both status registers. DRV8301_OK only when both
 * control registers read back as written and no status bit is set; else
 * _E_SILENT, _E_READBACK (d->want / d->got, d->reg), _E_FAULT (d->status) or
 * _E_SPI. Call it after an EN_GATE reset (DRV8301_RESET_US, then
 * DRV8301_SPI_READY_US). */
int drv8301_configure(drv8301_t *d, const drv8301_cfg_t *c);
/* Both status registers (d->status); the control registers read back
 * against d->want (DRV8301_E_READBACK when they changed: a GVDD
 * under-voltage or an EN_GATE glitch resets them). */
int drv8301_check(drv8301_t *d);
/* CR1 with GATE_RESET: the latched faults cleared (the bit reads 0 again). */
int drv8301_gate_reset(drv8301_t *d);

/* "FETHA_OC GVDD_UV ..." for the set bits of status 1 and 2 (GVDD_OV of
 * status 2), "none" when none: at most cap - 1 characters. */
size_t drv8301_fault_names(uint16_t s1, uint16_t s2, char *buf, size_t cap);
/* One line about the last error of d: "no answer on SPI (register 2 came
 * back as 0x0000)", "control 1 reads 0x000, wrote 0x543", "fault GVDD_UV",
 * "SPI frame error (register 2, answer 0x9000)", "SPI time-out (register 3)". */
size_t drv8301_explain(const drv8301_t *d, char *buf, size_t cap);
const char *drv8301_strerror(int rc);

#endif /* HAL_DRV8301_DRV8301_H */
