/* SPI master, 16-bit polled frames (f4_spi.h). */
#include "f4_spi.h"

#include "f4_core.h"
#include "f4_regs.h"

int f4_spi_find(uint32_t n, f4_spi_t *s)
{
    switch (n) {
    case 1u:
        *s = (f4_spi_t){F4_SPI1, 2u, F4_RCC_APB2ENR_SPI1EN};
        return F4_OK;
    case 2u:
        *s = (f4_spi_t){F4_SPI2, 1u, F4_RCC_APB1ENR_SPI2EN};
        return F4_OK;
    case 3u:
        *s = (f4_spi_t){F4_SPI3, 1u, F4_RCC_APB1ENR_SPI3EN};
        return F4_OK;
    default:
        return F4_E_CONFIG;
    }
}

int f4_spi_br(uint32_t pclk_hz, uint32_t max_hz, uint32_t *br, uint32_t *sck_hz)
{
    for (uint32_t b = 0u; b <= 7u; b++) {
        const uint32_t f = pclk_hz >> (b + 1u);
        if (f <= max_hz) {
            *br = b;
            *sck_hz = f;
            return F4_OK;
        }
    }
    return F4_E_CONFIG;
}

void f4_spi_init(const f4_spi_t *s, uint32_t br, bool cpol, bool cpha)
{
    f4_rcc_enable(s->apb == 2u ? F4_RCC_APB2ENR : F4_RCC_APB1ENR, s->en);
    /* Configured while disabled (sec. 28.3.3), then SPE. */
    const uint32_t cr1 = F4_SPI_CR1_MSTR | F4_SPI_CR1_SSM | F4_SPI_CR1_SSI | F4_SPI_CR1_DFF |
                         F4_FIELD(br & 7u, F4_SPI_CR1_BR_POS) | (cpol ? F4_SPI_CR1_CPOL : 0u) |
                         (cpha ? F4_SPI_CR1_CPHA : 0u);
    f4_wr(s->base + F4_SPI_CR1, cr1);
    f4_wr(s->base + F4_SPI_CR1, cr1 | F4_SPI_CR1_SPE);
}

int f4_spi_xfer16(const f4_spi_t *s, uint16_t out, uint16_t *in, uint32_t timeout_cycles)
{
    const uintptr_t sr = s->base + F4_SPI_SR;
    if (!f4_wait_bits(sr, F4_SPI_SR_TXE, F4_SPI_SR_TXE, timeout_cycles)) {
        return F4_E_SPI;
    }
    f4_wr(s->base + F4_SPI_DR, out);
    if (!f4_wait_bits(sr, F4_SPI_SR_RXNE, F4_SPI_SR_RXNE, timeout_cycles)) {
        return F4_E_SPI;
    }
    *in = (uint16_t)f4_rd(s->base + F4_SPI_DR);
    if (!f4_wait_bits(sr, F4_SPI_SR_BSY, 0u, timeout_cycles)) {
        return F4_E_SPI;
    }
    return F4_OK;
}
