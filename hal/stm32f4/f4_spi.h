/*
 * SPI master of the STM32F405/407 (RM0090 sec. 28): one 16-bit frame at a
 * time, polled, with time-outs; the chip select is a GPIO the caller drives
 * (software slave management, SSM = SSI = 1).
 */
#ifndef HAL_STM32F4_F4_SPI_H
#define HAL_STM32F4_F4_SPI_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    uintptr_t base;
    uint32_t apb; /* 1 or 2: its clock */
    uint32_t en;  /* its enable bit in RCC_APB1ENR / RCC_APB2ENR */
} f4_spi_t;

/* n = 1 (APB2), 2, 3 (APB1). F4_OK or F4_E_CONFIG. */
int f4_spi_find(uint32_t n, f4_spi_t *s);

/* SPI_CR1.BR for the fastest clock f_PCLK / 2^(BR + 1) not above max_hz;
 * F4_E_CONFIG when even f_PCLK / 256 is above it. *sck_hz: the clock. */
int f4_spi_br(uint32_t pclk_hz, uint32_t max_hz, uint32_t *br, uint32_t *sck_hz);

/* Master, 16-bit frames, MSB first, clock polarity / phase (CPOL, CPHA),
 * software NSS, enabled. */
void f4_spi_init(const f4_spi_t *s, uint32_t br, bool cpol, bool cpha);

/* One frame out, one in: TXE, DR, RXNE, DR, then BSY clear (the frame has
 * left the shift register before the caller raises the chip select).
 * F4_OK or F4_E_SPI after timeout_cycles core cycles at any step. */
int f4_spi_xfer16(const f4_spi_t *s, uint16_t out, uint16_t *in, uint32_t timeout_cycles);

#endif /* HAL_STM32F4_F4_SPI_H */
