/*
 * Analog front end of the STM32G4: op-amps in PGA mode (RM0440 OPAMP
 * chapter), comparators (COMP chapter) with DAC3 thresholds (DAC chapter).
 * OPAMP and COMP registers are clocked through SYSCFG (RCC_APB2ENR.SYSCFGEN).
 */
#ifndef HAL_STM32G4_G4_ANALOG_H
#define HAL_STM32G4_G4_ANALOG_H

#include <stdbool.h>
#include <stdint.h>

#include "g4_board.h"

#define G4_DAC_STEPS 4096u /* 12-bit DAC: V_out = VREF+ x DOR / 4096 (RM0440) */

/* OPAMPx_CSR without OPAEN: non-inverting input VINPy (vpsel 0..3), PGA mode
 * (VMSEL = 10), PGA_GAIN code (e.g. 01011 = non-inverting gain 16 with the
 * inverting input on VINM0 as input or bias: V_out = 16 V_INP - 15 V_INM0),
 * high-speed mode, output on its pin (OPAINTOEN = 0). */
uint32_t g4_opamp_csr(uint32_t vpsel, uint32_t pga_gain_code, bool high_speed);
/* Configure (OPAEN = 0), then enable in a second write (x = 1..3). */
void g4_opamp_init(uint32_t x, uint32_t csr);

/* DAC code for a voltage: floor(v / vref x 4096), i.e. the threshold is at or
 * below v; G4_OK or G4_E_CONFIG outside [0, vref). */
int g4_dac_code(double v, double vref, uint32_t *code);
/* DAC3 both channels to on-chip peripherals (MODE = 011), high-frequency
 * interface for HCLK > 160 MHz, codes loaded, enabled, DACxRDY waited for. */
int g4_dac3_init(uint32_t code1, uint32_t code2, uint32_t f_cpu_hz);
/* New threshold codes (DHR12Rx; no trigger: the output follows at once). */
void g4_dac3_set(uint32_t code1, uint32_t code2);

/* COMPx_CSR: plus input IO1, minus input DAC3 (INMSEL = 100), output not
 * inverted (high when V+ > V-), hysteresis code hyst (000 none .. 111). */
uint32_t g4_comp_csr_dac3(uint32_t hyst);
/* Configure, enable, then wait t_START (5 us here; datasheet <= 5 us). */
void g4_comp_init(uint32_t x, uint32_t csr, uint32_t f_cpu_hz);
/* Comparator output level (COMPx_CSR.VALUE). */
bool g4_comp_value(uint32_t x);

/* Expected phase-current code at zero current, as hal_adc_read returns it
 * (mirrored for a negative sense gain), and its worst-case deviation, counts,
 * from the board's bias network (g4_board_t); both 0 when the board does not
 * describe it (hal_info_t.adc_current_zero, adc_current_zero_tol). */
void g4_sense_zero(const g4_board_t *b, uint16_t *zero, uint16_t *tol);

#endif /* HAL_STM32G4_G4_ANALOG_H */
