/* Register-level STM32F405 model for the F4 chip-support tests (f4_model.h). */
#include "f4_model.h"

#include <stdio.h>
#include <string.h>

#include "f4_flash.h"

#define F4_DEFINE_ARRAY(N, n, addr, bytes) uint32_t f4_mem_##n[(bytes) / 4u];
F4_PERIPHS(F4_DEFINE_ARRAY)
#undef F4_DEFINE_ARRAY
uint32_t f4_mem_flash_settings[2u * F4_FLASH_SECTOR_SIZE / 4u];

f4_model_t f4_model;

typedef struct {
    const char *name;
    uintptr_t base;
    uint32_t bytes;
} f4_region_t;

#define F4_REGION(N, n, addr, bytes) {#N, (uintptr_t)f4_mem_##n, (bytes)},
static const f4_region_t f4_regions[] = {F4_PERIPHS(F4_REGION){
    "FLASH_SETTINGS", (uintptr_t)f4_mem_flash_settings, (uint32_t)sizeof f4_mem_flash_settings}};
#undef F4_REGION
#define F4_N_REGIONS (sizeof f4_regions / sizeof f4_regions[0])

static uint32_t *f4_model_cell(uintptr_t reg)
{
    for (size_t i = 0; i < F4_N_REGIONS; i++) {
        if (reg >= f4_regions[i].base && reg < f4_regions[i].base + f4_regions[i].bytes) {
            return (uint32_t *)reg;
        }
    }
    fprintf(stderr, "f4_model: access outside the peripheral arrays: %p\n", (void *)reg);
    return NULL;
}

static uint32_t *f4_reg(uintptr_t base, uint32_t off)
{
    return (uint32_t *)(base + off);
}

void f4_model_reset(void)
{
#define F4_CLEAR(N, n, addr, bytes) memset(f4_mem_##n, 0, sizeof f4_mem_##n);
    F4_PERIPHS(F4_CLEAR)
#undef F4_CLEAR
    memset(&f4_model, 0, sizeof f4_model);
    memset(f4_mem_flash_settings, 0xFF, sizeof(uint32_t) * 2u * F4_FLASH_SECTOR_SIZE / 4u);
    f4_model.adc_regular = 2048u;
    for (unsigned p = 0; p < 4u; p++) {
        f4_model.gpio_in[p] = 0xFFFFu;
    }
    /* RM0090 reset values of every register these tests look at. */
    *f4_reg(F4_RCC, F4_RCC_CR) = F4_RCC_CR_RESET;            /* 0x83: HSION, HSIRDY */
    *f4_reg(F4_RCC, F4_RCC_PLLCFGR) = F4_RCC_PLLCFGR_RESET;  /* 0x2400_3010 */
    *f4_reg(F4_RCC, F4_RCC_AHB1ENR) = 0x00100000u;           /* CCMDATARAMEN */
    *f4_reg(F4_RCC, F4_RCC_CSR) = 0x0E000000u;               /* PORRSTF, PINRSTF, BORRSTF */
    *f4_reg(F4_PWR, F4_PWR_CR) = F4_PWR_CR_VOS;              /* 0x4000: scale 1 */
    *f4_reg(F4_FLASH, F4_FLASH_CR) = F4_FLASH_CR_RESET;      /* LOCK */
    *f4_reg(F4_GPIOA, F4_GPIO_MODER) = F4_GPIOA_MODER_RESET; /* PA13/14/15 debug AF */
    *f4_reg(F4_GPIOA, F4_GPIO_OSPEEDR) = F4_GPIOA_OSPEEDR_RESET;
    *f4_reg(F4_GPIOA, F4_GPIO_PUPDR) = F4_GPIOA_PUPDR_RESET;
    *f4_reg(F4_GPIOB, F4_GPIO_MODER) = F4_GPIOB_MODER_RESET; /* PB3/PB4 debug AF */
    *f4_reg(F4_GPIOB, F4_GPIO_OSPEEDR) = F4_GPIOB_OSPEEDR_RESET;
    *f4_reg(F4_GPIOB, F4_GPIO_PUPDR) = F4_GPIOB_PUPDR_RESET;
    *f4_reg(F4_TIM1, F4_TIM_ARR) = 0xFFFFu;
    *f4_reg(F4_TIM3, F4_TIM_ARR) = 0xFFFFu;
    *f4_reg(F4_TIM4, F4_TIM_ARR) = 0xFFFFu;
    *f4_reg(F4_TIM2, F4_TIM_ARR) = 0xFFFFFFFFu;
    *f4_reg(F4_TIM5, F4_TIM_ARR) = 0xFFFFFFFFu;
    *f4_reg(F4_IWDG, F4_IWDG_RLR) = 0xFFFu;
    const uintptr_t usarts[5] = {F4_USART1, F4_USART2, F4_USART3, F4_UART4, F4_USART6};
    for (unsigned k = 0; k < 5u; k++) {
        *f4_reg(usarts[k], F4_USART_SR) = F4_USART_SR_TXE | F4_BIT(6); /* 0xC0: TXE, TC */
    }
    const uintptr_t spis[3] = {F4_SPI1, F4_SPI2, F4_SPI3};
    for (unsigned k = 0; k < 3u; k++) {
        *f4_reg(spis[k], F4_SPI_SR) = F4_SPI_SR_TXE; /* 0x0002 */
    }
}

const char *f4_model_name(uintptr_t reg)
{
    static char buf[4][40];
    static unsigned k;
    char *b = buf[k++ % 4u];
    for (size_t i = 0; i < F4_N_REGIONS; i++) {
        if (reg >= f4_regions[i].base && reg < f4_regions[i].base + f4_regions[i].bytes) {
            (void)snprintf(b, 40, "%s+0x%02X", f4_regions[i].name,
                           (unsigned)(reg - f4_regions[i].base));
            return b;
        }
    }
    return "?";
}

uint32_t f4_model_get(uintptr_t reg)
{
    uint32_t *c = f4_model_cell(reg);
    return c != NULL ? *c : 0u;
}

void f4_model_put(uintptr_t reg, uint32_t value)
{
    uint32_t *c = f4_model_cell(reg);
    if (c != NULL) {
        *c = value;
    }
}

int f4_model_find(uintptr_t reg, uint32_t mask, uint32_t want, int from)
{
    for (uint32_t i = from < 0 ? 0u : (uint32_t)from; i < f4_model.n_log; i++) {
        if (f4_model.log[i].reg == reg && (f4_model.log[i].value & mask) == want) {
            return (int)i;
        }
    }
    return -1;
}

int f4_model_find_last(uintptr_t reg, uint32_t mask, uint32_t want)
{
    for (uint32_t i = f4_model.n_log; i-- > 0u;) {
        if (f4_model.log[i].reg == reg && (f4_model.log[i].value & mask) == want) {
            return (int)i;
        }
    }
    return -1;
}

static uintptr_t f4_model_gpio(uint32_t port)
{
    const uintptr_t ports[4] = {F4_GPIOA, F4_GPIOB, F4_GPIOC, F4_GPIOD};
    return ports[port & 3u];
}

bool f4_model_pin_out(uint32_t port, uint32_t pin)
{
    return (*f4_reg(f4_model_gpio(port), F4_GPIO_ODR) & F4_BIT(pin)) != 0u;
}

uint32_t f4_model_pin_mode(uint32_t port, uint32_t pin)
{
    return (*f4_reg(f4_model_gpio(port), F4_GPIO_MODER) >> (2u * pin)) & 3u;
}

uint32_t f4_model_pin_af(uint32_t port, uint32_t pin)
{
    const uint32_t afr = *f4_reg(f4_model_gpio(port), pin < 8u ? F4_GPIO_AFRL : F4_GPIO_AFRH);
    return (afr >> (4u * (pin % 8u))) & 0xFu;
}

void f4_model_pin_in(uint32_t port, uint32_t pin, bool high)
{
    if (high) {
        f4_model.gpio_in[port] = (uint16_t)(f4_model.gpio_in[port] | F4_BIT(pin));
    } else {
        f4_model.gpio_in[port] = (uint16_t)(f4_model.gpio_in[port] & ~F4_BIT(pin));
    }
}

/* The peripheral whose block holds reg, -1 if none of the kinds below. */
static int f4_model_index(uintptr_t reg, const uintptr_t *bases, unsigned n, uint32_t span)
{
    for (unsigned i = 0; i < n; i++) {
        if (reg >= bases[i] && reg < bases[i] + span) {
            return (int)i;
        }
    }
    return -1;
}

/* The access to reg after an RCC clock enable: the read-back of that
 * enable register, or counted as too early. */
static void f4_model_rcc_sync(uintptr_t reg, bool read)
{
    if (f4_model.rcc_enable_pending == 0u) {
        return;
    }
    if (read && reg == f4_model.rcc_enable_pending) {
        f4_model.rcc_enable_pending = 0u;
    } else if (reg != f4_model.rcc_enable_pending) {
        f4_model.rcc_enable_unsynced++;
        f4_model.rcc_enable_pending = 0u;
    }
}

void f4_model_usart_rx(uintptr_t base, uint8_t c, uint32_t errors)
{
    const uint32_t on = F4_USART_CR1_UE | F4_USART_CR1_RE;
    if ((*f4_reg(base, F4_USART_CR1) & on) != on) {
        return;
    }
    f4_model.usart_rx_base = base;
    uint32_t *sr = f4_reg(base, F4_USART_SR);
    if ((*sr & F4_USART_SR_RXNE) != 0u) {
        *sr |= F4_USART_SR_ORE;
        f4_model.usart_lost++;
        return;
    }
    f4_model.usart_rdr = c;
    *sr |= F4_USART_SR_RXNE | (errors & (F4_USART_SR_FE | F4_USART_SR_NF));
}

uint32_t f4_trace_read(uintptr_t reg)
{
    uint32_t *c = f4_model_cell(reg);
    f4_model_rcc_sync(reg, true);
    if (c == NULL) {
        return 0u;
    }
    if (reg == F4_DWT + F4_DWT_CYCCNT) {
        *c += 16u; /* time passes: every read of the cycle counter advances it */
    }
    if (reg == F4_RCC + F4_RCC_CR) {
        uint32_t v = *c & ~(F4_RCC_CR_HSERDY | F4_RCC_CR_PLLRDY);
        if ((v & F4_RCC_CR_HSEON) != 0u && !f4_model.hse_broken) {
            v |= F4_RCC_CR_HSERDY;
        }
        if ((v & F4_RCC_CR_PLLON) != 0u && !f4_model.pll_broken) {
            v |= F4_RCC_CR_PLLRDY;
        }
        *c = v;
    }
    if (reg == F4_RCC + F4_RCC_CFGR && !f4_model.sws_stuck) {
        *c = (*c & ~F4_RCC_CFGR_SWS_MASK) | ((*c & F4_RCC_CFGR_SW_MASK) << 2);
    }
    if (reg == F4_FLASH + F4_FLASH_ACR && f4_model.latency_stuck) {
        *c &= ~F4_FLASH_ACR_LATENCY_MASK;
    }
    if (reg == F4_IWDG + F4_IWDG_SR) {
        const uint32_t since = *f4_reg(F4_DWT, F4_DWT_CYCCNT) - f4_model.iwdg_written_at;
        *c = since < f4_model.iwdg_update_cycles ? 0x3u : 0u; /* PVU, RVU */
    }
    if (reg == F4_FLASH + F4_FLASH_SR) {
        *c = (*c & ~F4_FLASH_SR_BSY) | (f4_model.flash_bsy_stuck ? F4_FLASH_SR_BSY : 0u);
    }
    if (reg == F4_TIM1 + F4_TIM_CR1) {
        /* Right after an update the counter counts down if the update was at
         * the peak (RCR written before the start: RM0090 sec. 17.3.3). */
        const bool peak = f4_model.rcr_before_cen && !f4_model.uev_at_valley;
        *c = (*c & ~F4_TIM_CR1_DIR) | (peak ? F4_TIM_CR1_DIR : 0u);
    }
    if (reg == F4_TIM1 + F4_TIM_SR && !f4_model.tim1_dead &&
        (f4_mem_tim1[F4_TIM_CR1 / 4u] & F4_TIM_CR1_CEN) != 0u) {
        *c |= F4_TIM_SR_UIF; /* the counter runs: updates come */
    }
    /* A read of TIMx_CCRn clears CCnIF (RM0090 sec. 17.4.5). */
    const uintptr_t tims[5] = {F4_TIM1, F4_TIM2, F4_TIM3, F4_TIM4, F4_TIM5};
    const int t = f4_model_index(reg, tims, 5u, 0x54u);
    if (t >= 0 && reg >= tims[t] + F4_TIM_CCR(1u) && reg <= tims[t] + F4_TIM_CCR(4u)) {
        const uint32_t ch = (uint32_t)(reg - tims[t] - F4_TIM_CCR(1u)) / 4u + 1u;
        *f4_reg(tims[t], F4_TIM_SR) &= ~F4_TIM_SR_CCIF(ch);
    }
    const uintptr_t gpios[4] = {F4_GPIOA, F4_GPIOB, F4_GPIOC, F4_GPIOD};
    const int g = f4_model_index(reg, gpios, 4u, 0x28u);
    if (g >= 0 && reg == gpios[g] + F4_GPIO_IDR) {
        /* An output pin reads its output, every other one its input. */
        const uint32_t moder = *f4_reg(gpios[g], F4_GPIO_MODER);
        const uint32_t odr = *f4_reg(gpios[g], F4_GPIO_ODR);
        uint32_t v = 0u;
        for (uint32_t p = 0; p < 16u; p++) {
            const bool out = ((moder >> (2u * p)) & 3u) == 1u;
            const uint32_t lvl = out ? (odr >> p) & 1u : ((uint32_t)f4_model.gpio_in[g] >> p) & 1u;
            v |= lvl << p;
        }
        *c = v;
    }
    const uintptr_t spis[3] = {F4_SPI1, F4_SPI2, F4_SPI3};
    const int s = f4_model_index(reg, spis, 3u, 0x24u);
    if (s >= 0 && reg == spis[s] + F4_SPI_DR) {
        *f4_reg(spis[s], F4_SPI_SR) &= ~F4_SPI_SR_RXNE;
    }
    const uintptr_t ub = f4_model.usart_rx_base;
    if (ub != 0u && reg == ub + F4_USART_SR) {
        f4_model.usart_sr_read = true;
    }
    if (ub != 0u && reg == ub + F4_USART_DR) {
        /* the received character; RXNE cleared, the errors by the sequence
         * SR read then DR read (RM0090 sec. 30.6.1) */
        *c = f4_model.usart_rdr;
        const uint32_t errs = F4_USART_SR_ORE | F4_USART_SR_FE | F4_USART_SR_NF;
        *f4_reg(ub, F4_USART_SR) &= ~(F4_USART_SR_RXNE | (f4_model.usart_sr_read ? errs : 0u));
        f4_model.usart_sr_read = false;
    }
    const uint32_t v = *c;
    if (f4_model.irq_on_read == reg && f4_model.irq != NULL) {
        /* An interrupt taken right after this load: the caller stores what it
         * read, modified, after the handler has run; with PRIMASK set, held
         * pending until it clears. */
        void (*irq)(void) = f4_model.irq;
        f4_model.irq = NULL;
        if (f4_model.primask != 0u) {
            f4_model.irq_pending = irq;
        } else {
            irq();
        }
    }
    return v;
}

uint32_t f4_trace_irq_lock(void)
{
    const uint32_t prev = f4_model.primask;
    f4_model.primask = 1u;
    f4_model.n_locks++;
    return prev;
}

void f4_trace_irq_unlock(uint32_t primask)
{
    f4_model.primask = primask;
    if (primask == 0u && f4_model.irq_pending != NULL) {
        void (*irq)(void) = f4_model.irq_pending;
        f4_model.irq_pending = NULL;
        irq();
    }
}

/* FLASH_CR and the settings sectors: the flash interface's side effects. */
static void f4_model_flash_write(uintptr_t reg, uint32_t *c, uint32_t value)
{
    uint32_t *cr = f4_reg(F4_FLASH, F4_FLASH_CR);
    uint32_t *sr = f4_reg(F4_FLASH, F4_FLASH_SR);
    if (reg == F4_FLASH + F4_FLASH_KEYR) {
        if (value == F4_FLASH_KEY1) {
            f4_model.flash_key1 = true;
        } else if (value == F4_FLASH_KEY2 && f4_model.flash_key1) {
            *cr &= ~F4_FLASH_CR_LOCK;
            f4_model.flash_key1 = false;
        } else {
            f4_model.flash_key1 = false; /* a wrong key: locked until reset */
        }
        return;
    }
    if (reg == F4_FLASH + F4_FLASH_SR) {
        *c &= ~value; /* rc_w1 */
        return;
    }
    if (reg == F4_FLASH + F4_FLASH_CR) {
        if ((*cr & F4_FLASH_CR_LOCK) != 0u) {
            return; /* locked: writes ignored */
        }
        *c = value;
        if ((value & F4_FLASH_CR_STRT) != 0u && (value & F4_FLASH_CR_SER) != 0u) {
            const uint32_t snb = (value & F4_FLASH_CR_SNB_MASK) >> F4_FLASH_CR_SNB_POS;
            if (snb < 12u && f4_model.flash_wrp[snb]) {
                *sr |= F4_FLASH_SR_WRPERR;
            } else if (snb == 1u || snb == 2u) {
                memset(f4_mem_flash_settings + (snb - 1u) * (F4_FLASH_SECTOR_SIZE / 4u), 0xFF,
                       F4_FLASH_SECTOR_SIZE);
            }
            *c &= ~F4_FLASH_CR_STRT;
        }
        return;
    }
    /* A word written into the settings sectors: programmed only in a
     * programming sequence (PG set, unlocked, PSIZE x32 for a word), and
     * flash bits only go from 1 to 0. */
    const uint32_t psize = (*cr & F4_FLASH_CR_PSIZE_MASK) >> F4_FLASH_CR_PSIZE_POS;
    const uint32_t sector =
        1u + (uint32_t)((reg - (uintptr_t)f4_mem_flash_settings) / F4_FLASH_SECTOR_SIZE);
    if ((*cr & F4_FLASH_CR_PG) == 0u || (*cr & F4_FLASH_CR_LOCK) != 0u) {
        *sr |= F4_FLASH_SR_PGSERR;
    } else if (psize != 2u) {
        *sr |= F4_FLASH_SR_PGPERR;
    } else if (f4_model.flash_wrp[sector]) {
        *sr |= F4_FLASH_SR_WRPERR;
    } else {
        *c &= value;
    }
}

void f4_trace_write(uintptr_t reg, uint32_t value)
{
    uint32_t *c = f4_model_cell(reg);
    if (f4_model.n_log < F4_MODEL_LOG_MAX) {
        f4_model.log[f4_model.n_log].reg = reg;
        f4_model.log[f4_model.n_log].value = value;
        f4_model.n_log++;
    } else {
        f4_model.log_overflow = true;
    }
    f4_model_rcc_sync(reg, false);
    if (c == NULL) {
        return;
    }
    if ((reg == F4_RCC + F4_RCC_AHB1ENR || reg == F4_RCC + F4_RCC_APB1ENR ||
         reg == F4_RCC + F4_RCC_APB2ENR) &&
        (value & ~*c) != 0u) {
        f4_model.rcc_enable_pending = reg;
    }
    if ((reg >= F4_FLASH && reg < F4_FLASH + 0x18u) ||
        (reg >= (uintptr_t)f4_mem_flash_settings &&
         reg < (uintptr_t)f4_mem_flash_settings + 2u * F4_FLASH_SECTOR_SIZE)) {
        if (reg != F4_FLASH + F4_FLASH_ACR) {
            f4_model_flash_write(reg, c, value);
            return;
        }
    }
    /* ADC: SR rc_w0; SWSTART converts at once (EOC, DR) and clears itself. */
    const uintptr_t adcs[3] = {F4_ADC1, F4_ADC2, F4_ADC3};
    const int a = f4_model_index(reg, adcs, 3u, 0x50u);
    if (a >= 0 && reg == adcs[a] + F4_ADC_SR) {
        *c &= value;
        return;
    }
    if (a >= 0 && reg == adcs[a] + F4_ADC_CR2) {
        if ((value & F4_ADC_CR2_SWSTART) != 0u && !f4_model.adc_dead) {
            *f4_reg(adcs[a], F4_ADC_SR) |= F4_ADC_SR_EOC | F4_ADC_SR_STRT;
            *f4_reg(adcs[a], F4_ADC_DR) = f4_model.adc_regular;
        }
        *c = value & ~F4_ADC_CR2_SWSTART;
        return;
    }
    /* GPIO: BSRR sets / resets ODR bits (reset wins per RM0090: set first). */
    const uintptr_t gpios[4] = {F4_GPIOA, F4_GPIOB, F4_GPIOC, F4_GPIOD};
    const int g = f4_model_index(reg, gpios, 4u, 0x28u);
    if (g >= 0 && reg == gpios[g] + F4_GPIO_BSRR) {
        uint32_t *odr = f4_reg(gpios[g], F4_GPIO_ODR);
        *odr = (*odr | (value & 0xFFFFu)) & ~(value >> 16);
        return;
    }
    /* EXTI_PR rc_w1. */
    if (reg == F4_EXTI + F4_EXTI_PR) {
        *c &= ~value;
        return;
    }
    /* SPI: a frame to the peer; RXNE with its answer. */
    const uintptr_t spis[3] = {F4_SPI1, F4_SPI2, F4_SPI3};
    const int s = f4_model_index(reg, spis, 3u, 0x24u);
    if (s >= 0 && reg == spis[s] + F4_SPI_DR) {
        if ((*f4_reg(spis[s], F4_SPI_CR1) & F4_SPI_CR1_SPE) != 0u) {
            f4_model.spi_frames++;
            *c = f4_model.spi_peer != NULL ? f4_model.spi_peer((uint32_t)s + 1u, (uint16_t)value)
                                           : 0u;
            *f4_reg(spis[s], F4_SPI_SR) |= F4_SPI_SR_RXNE;
        }
        return;
    }
    if (s >= 0 && reg == spis[s] + F4_SPI_SR) {
        return; /* read-only here */
    }
    /* Timers: SR rc_w0, the software break, the RCR / CEN order. */
    const uintptr_t tims[5] = {F4_TIM1, F4_TIM2, F4_TIM3, F4_TIM4, F4_TIM5};
    const int t = f4_model_index(reg, tims, 5u, 0x54u);
    if (t >= 0) {
        const uintptr_t tb = tims[t];
        if (reg == tb + F4_TIM_SR) {
            *c &= value;
            return;
        }
        if (reg == tb + F4_TIM_EGR) {
            if ((value & F4_TIM_EGR_BG) != 0u) {
                *f4_reg(tb, F4_TIM_BDTR) &= ~F4_TIM_BDTR_MOE;
                *f4_reg(tb, F4_TIM_SR) |= F4_TIM_SR_BIF;
            }
            return;
        }
        if (tb == F4_TIM1 && reg == tb + F4_TIM_RCR) {
            f4_model.rcr_written = true;
        }
        if (tb == F4_TIM1 && reg == tb + F4_TIM_CR1 && (value & F4_TIM_CR1_CEN) != 0u &&
            (*c & F4_TIM_CR1_CEN) == 0u) {
            f4_model.rcr_before_cen = f4_model.rcr_written;
        }
    }
    if (reg == F4_IWDG + F4_IWDG_PR || reg == F4_IWDG + F4_IWDG_RLR) {
        f4_model.iwdg_written_at = *f4_reg(F4_DWT, F4_DWT_CYCCNT);
    }
    /* IWDG: the start key forces the LSI on, which is ready at once here
     * (RM0090 sec. 21.3.2; RCC_CSR LSION, LSIRDY); SR stays 0. */
    if (reg == F4_IWDG + F4_IWDG_KR && value == F4_IWDG_KR_START && !f4_model.lsi_dead) {
        *f4_reg(F4_RCC, F4_RCC_CSR) |= F4_RCC_CSR_LSIRDY | F4_RCC_CSR_LSION;
    }
    if (reg == F4_RCC + F4_RCC_CSR) {
        /* LSION on: LSIRDY (at once here); the reset flags read-only, RMVF
         * clears them */
        const uint32_t keep = *c & 0xFE000000u;
        *c = (value & F4_RCC_CSR_LSION) | ((value & F4_RCC_CSR_RMVF) != 0u ? 0u : keep) |
             ((value & F4_RCC_CSR_LSION) != 0u && !f4_model.lsi_dead ? F4_RCC_CSR_LSIRDY : 0u);
        return;
    }
    /* USART: DR written is the byte sent (SR keeps TXE). */
    *c = value;
}
