/* Register-level STM32G4 model for the HAL tests (g4_model.h). */
#include "g4_model.h"

#include "g4_flash.h"

#include <stdio.h>
#include <string.h>

#define G4_DEFINE_ARRAY(N, n, addr, bytes) uint32_t g4_mem_##n[(bytes) / 4u];
G4_PERIPHS(G4_DEFINE_ARRAY)
#undef G4_DEFINE_ARRAY
/* The two settings pages (g4_flash.h): non-volatile, so g4_model_reset (a
 * power cycle) keeps them; erased (0xFF) until the first g4_model_reset. */
uint32_t g4_mem_flash_settings[2u * G4_FLASH_PAGE_SIZE / 4u];
static bool g4_model_flash_blank;

g4_model_t g4_model;

typedef struct {
    const char *name;
    uintptr_t base;
    uint32_t bytes;
} g4_region_t;

#define G4_REGION(N, n, addr, bytes) {#N, (uintptr_t)g4_mem_##n, (bytes)},
static const g4_region_t g4_regions[] = {G4_PERIPHS(G4_REGION){
    "FLASHMEM", (uintptr_t)g4_mem_flash_settings, sizeof g4_mem_flash_settings}};
#undef G4_REGION
#define G4_N_REGIONS (sizeof g4_regions / sizeof g4_regions[0])

static uint32_t *g4_model_cell(uintptr_t reg)
{
    for (size_t i = 0; i < G4_N_REGIONS; i++) {
        if (reg >= g4_regions[i].base && reg < g4_regions[i].base + g4_regions[i].bytes) {
            return (uint32_t *)reg;
        }
    }
    fprintf(stderr, "g4_model: access outside the peripheral arrays: %p\n", (void *)reg);
    return NULL;
}

void g4_model_reset(void)
{
#define G4_CLEAR(N, n, addr, bytes) memset(g4_mem_##n, 0, sizeof g4_mem_##n);
    G4_PERIPHS(G4_CLEAR)
#undef G4_CLEAR
    memset(&g4_model, 0, sizeof g4_model);
    if (!g4_model_flash_blank) {
        g4_model_flash_blank = true;
        memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings);
    }
    g4_model.adc_regular = 128u;
    /* Every modelled register starts at its RM0440 reset value, so that a
     * whole-register write that clobbers a bit shows in the image. */
    g4_mem_flash[G4_FLASH_ACR / 4u] = G4_FLASH_ACR_RESET; /* 0x0004_0600: DBG_SWEN, DCEN, ICEN */
    /* FLASH_OPTR holds the option bytes: as ST ships the B-G431B-ESC1
     * (factory 0xFFEF_F8AA with nSWBOOT0 = 0: BOOT0 from nBOOT0 = 1). */
    g4_mem_flash[G4_FLASH_OPTR / 4u] = 0xFFEFF8AAu & ~G4_FLASH_OPTR_nSWBOOT0;
    g4_mem_rcc[G4_RCC_CR / 4u] = 0x00000500u;                              /* HSION, HSIRDY */
    g4_mem_rcc[G4_RCC_CFGR / 4u] = 0x00000005u;                            /* SW = SWS = HSI16 */
    g4_mem_rcc[G4_RCC_PLLCFGR / 4u] = 0x00001000u;                         /* PLLN = 16 */
    g4_mem_rcc[G4_RCC_AHB1ENR / 4u] = 0x00000100u;                         /* FLASHEN */
    g4_mem_rcc[G4_RCC_APB1ENR1 / 4u] = 0x00000400u;                        /* RTCAPBEN */
    g4_mem_rcc[G4_RCC_CSR / 4u] = G4_RCC_CSR_PINRSTF | G4_RCC_CSR_BORRSTF; /* power-on */
    g4_mem_pwr[G4_PWR_CR1 / 4u] = G4_PWR_CR1_VOS_RANGE1;                   /* 0x200 */
    g4_mem_pwr[G4_PWR_CR3 / 4u] = 0x00008000u;                             /* EIWUL */
    g4_mem_pwr[G4_PWR_CR5 / 4u] = G4_PWR_CR5_R1MODE;                       /* 0x100: boost off */
    g4_mem_gpioa[G4_GPIO_MODER / 4u] = 0xABFFFFFFu; /* analog, PA13/14/15 debug AF */
    g4_mem_gpioa[G4_GPIO_OSPEEDR / 4u] = 0x0C000000u;
    g4_mem_gpioa[G4_GPIO_PUPDR / 4u] = 0x64000000u;
    g4_mem_gpiob[G4_GPIO_MODER / 4u] = 0xFFFFFEBFu; /* analog, PB3/PB4 debug AF */
    g4_mem_gpiob[G4_GPIO_PUPDR / 4u] = 0x00000100u;
    g4_mem_gpioc[G4_GPIO_MODER / 4u] = 0xFFFFFFFFu;
    g4_mem_adc1[G4_ADC_CR / 4u] = G4_ADC_CR_DEEPPWD;
    g4_mem_adc2[G4_ADC_CR / 4u] = G4_ADC_CR_DEEPPWD;
    g4_mem_adc1[G4_ADC_CFGR / 4u] = G4_ADC_CFGR_JQDIS;
    g4_mem_adc2[G4_ADC_CFGR / 4u] = G4_ADC_CFGR_JQDIS;
    g4_mem_flash[G4_FLASH_CR / 4u] = 0xC0000000u; /* LOCK, OPTLOCK */
    g4_mem_tim1[G4_TIM_ARR / 4u] = 0xFFFFu;
    g4_mem_tim1[G4_TIM_AF1 / 4u] = G4_TIM_AF1_BKINE; /* 0x0000_0001: the BKIN pin enabled */
    g4_mem_tim4[G4_TIM_ARR / 4u] = 0xFFFFu;
    g4_mem_tim2[G4_TIM_ARR / 4u] = 0xFFFFFFFFu;
    g4_mem_iwdg[G4_IWDG_RLR / 4u] = 0xFFFu;
    g4_mem_usart2[G4_USART_ISR / 4u] = G4_USART_ISR_TXE | G4_USART_ISR_TC;
}

/* An interrupt of priority 0 is pending while its enable and its flag are
 * both set (the NVIC takes it again as soon as the handler returns). */
bool g4_model_break_pending(void)
{
    return (g4_mem_tim1[G4_TIM_DIER / 4u] & G4_TIM_DIER_BIE) != 0u &&
           (g4_mem_tim1[G4_TIM_SR / 4u] & (G4_TIM_SR_BIF | G4_TIM_SR_B2IF | G4_TIM_SR_SBIF)) != 0u;
}

const char *g4_model_name(uintptr_t reg)
{
    static char buf[4][32];
    static unsigned k;
    char *b = buf[k++ % 4u];
    for (size_t i = 0; i < G4_N_REGIONS; i++) {
        if (reg >= g4_regions[i].base && reg < g4_regions[i].base + g4_regions[i].bytes) {
            (void)snprintf(b, 32, "%s+0x%02X", g4_regions[i].name,
                           (unsigned)(reg - g4_regions[i].base));
            return b;
        }
    }
    return "?";
}

uint32_t g4_model_get(uintptr_t reg)
{
    uint32_t *c = g4_model_cell(reg);
    return c != NULL ? *c : 0u;
}

void g4_model_put(uintptr_t reg, uint32_t value)
{
    uint32_t *c = g4_model_cell(reg);
    if (c != NULL) {
        *c = value;
    }
}

int g4_model_find(uintptr_t reg, uint32_t mask, uint32_t want, int from)
{
    for (uint32_t i = from < 0 ? 0u : (uint32_t)from; i < g4_model.n_log; i++) {
        if (g4_model.log[i].reg == reg && (g4_model.log[i].value & mask) == want) {
            return (int)i;
        }
    }
    return -1;
}

int g4_model_find_last(uintptr_t reg, uint32_t mask, uint32_t want)
{
    for (uint32_t i = g4_model.n_log; i-- > 0u;) {
        if (g4_model.log[i].reg == reg && (g4_model.log[i].value & mask) == want) {
            return (int)i;
        }
    }
    return -1;
}

/* USART2's receive flags from the model's RDR / RXFIFO: RXNE (RXFNE) while
 * a character waits, RXFF with the RXFIFO full, FE raised when a character
 * with a framing error is the one in RDR (cleared only by ICR.FECF). */
static void g4_model_usart_flags(void)
{
    const uint32_t cr1 = g4_mem_usart2[G4_USART_CR1 / 4u];
    uint32_t isr = g4_mem_usart2[G4_USART_ISR / 4u] & ~(G4_USART_ISR_RXNE | G4_USART_ISR_RXFF);
    if (g4_model.usart_n > 0u) {
        isr |= G4_USART_ISR_RXNE;
        if ((g4_model.usart_fifo[0] & 0x100u) != 0u) {
            isr |= G4_USART_ISR_FE;
        }
    }
    if ((cr1 & G4_USART_CR1_FIFOEN) != 0u && g4_model.usart_n == G4_USART_FIFO_DEPTH) {
        isr |= G4_USART_ISR_RXFF;
    }
    g4_mem_usart2[G4_USART_ISR / 4u] = isr;
}

void g4_model_usart_rx(uint8_t c, bool framing_error)
{
    const uint32_t cr1 = g4_mem_usart2[G4_USART_CR1 / 4u];
    if ((cr1 & (G4_USART_CR1_UE | G4_USART_CR1_RE)) != (G4_USART_CR1_UE | G4_USART_CR1_RE)) {
        return;
    }
    const uint32_t depth = (cr1 & G4_USART_CR1_FIFOEN) != 0u ? G4_USART_FIFO_DEPTH : 1u;
    if (g4_model.usart_n >= depth) {
        g4_mem_usart2[G4_USART_ISR / 4u] |= G4_USART_ISR_ORE;
        g4_model.usart_lost++;
        return;
    }
    g4_model.usart_fifo[g4_model.usart_n++] = (uint16_t)(c | (framing_error ? 0x100u : 0u));
    g4_model_usart_flags();
}

uint32_t g4_trace_read(uintptr_t reg)
{
    uint32_t *c = g4_model_cell(reg);
    if (c == NULL) {
        return 0u;
    }
    /* Time passes: every read of the cycle counter advances it. */
    if (reg == G4_DWT + G4_DWT_CYCCNT) {
        *c += 16u;
    }
    if (reg == G4_RCC + G4_RCC_CR) {
        uint32_t v = *c & ~(G4_RCC_CR_HSERDY | G4_RCC_CR_PLLRDY);
        if ((v & G4_RCC_CR_HSEON) != 0u && !g4_model.hse_broken) {
            v |= G4_RCC_CR_HSERDY;
        }
        if ((v & G4_RCC_CR_PLLON) != 0u && (v & G4_RCC_CR_HSERDY) != 0u) {
            v |= G4_RCC_CR_PLLRDY;
        }
        *c = v;
    }
    if (reg == G4_RCC + G4_RCC_CFGR && !g4_model.sws_stuck) {
        *c = (*c & ~G4_RCC_CFGR_SWS_MASK) | ((*c & G4_RCC_CFGR_SW_MASK) << 2);
    }
    if (reg == G4_DAC3 + G4_DAC_SR) {
        const uint32_t cr = g4_mem_dac3[G4_DAC_CR / 4u];
        *c = ((cr & G4_DAC_CR_EN1) != 0u ? G4_DAC_SR_DAC1RDY : 0u) |
             ((cr & G4_DAC_CR_EN2) != 0u ? G4_DAC_SR_DAC2RDY : 0u);
    }
    if (reg == G4_TIM1 + G4_TIM_CR1) {
        /* Right after an update the counter counts down if the update was at
         * the peak (RCR written before the start: RM0440 chapter 29,
         * repetition counter in centre-aligned mode). */
        const bool peak = g4_model.rcr_before_cen && !g4_model.uev_at_valley;
        *c = (*c & ~G4_TIM_CR1_DIR) | (peak ? G4_TIM_CR1_DIR : 0u);
    }
    if (reg == G4_TIM1 + G4_TIM_SR && (g4_mem_tim1[G4_TIM_CR1 / 4u] & G4_TIM_CR1_CEN) != 0u) {
        *c |= G4_TIM_SR_UIF; /* the counter runs: updates come */
    }
    /* TIM2's captures (CC1S, CC2S inputs, the throttle): reading CCRx
     * clears CCxIF (RM0440 TIMx_SR). */
    if (reg == G4_TIM2 + G4_TIM_CCR1) {
        g4_mem_tim2[G4_TIM_SR / 4u] &= ~G4_TIM_SR_CC1IF;
    }
    if (reg == G4_TIM2 + G4_TIM_CCR2) {
        g4_mem_tim2[G4_TIM_SR / 4u] &= ~G4_TIM_SR_CC2IF;
    }
    if (reg == G4_USART2 + G4_USART_RDR && g4_model.usart_n > 0u) {
        *c = g4_model.usart_fifo[0] & 0xFFu; /* the oldest leaves */
        g4_model.usart_n--;
        memmove(&g4_model.usart_fifo[0], &g4_model.usart_fifo[1],
                g4_model.usart_n * sizeof g4_model.usart_fifo[0]);
        g4_model_usart_flags();
    }
    if (reg >= G4_COMP && reg < G4_COMP + 0x10u) {
        *c = (*c & ~G4_COMP_CSR_VALUE) | (g4_model.comp_high ? G4_COMP_CSR_VALUE : 0u);
    }
    const uint32_t v = *c;
    if (g4_model.irq_on_read == reg && g4_model.irq != NULL) {
        /* An interrupt taken right after this load: the caller stores what it
         * read, modified, after the handler has run; with PRIMASK set, held
         * pending until it clears. */
        void (*irq)(void) = g4_model.irq;
        g4_model.irq = NULL;
        if (g4_model.primask != 0u) {
            g4_model.irq_pending = irq;
        } else {
            irq();
        }
    }
    return v;
}

uint32_t g4_trace_irq_lock(void)
{
    const uint32_t prev = g4_model.primask;
    g4_model.primask = 1u;
    g4_model.n_locks++;
    return prev;
}

void g4_trace_irq_unlock(uint32_t primask)
{
    g4_model.primask = primask;
    if (primask == 0u && g4_model.irq_pending != NULL) {
        void (*irq)(void) = g4_model.irq_pending;
        g4_model.irq_pending = NULL;
        irq();
    }
}

static void g4_model_write(uintptr_t reg, uint32_t value);

void g4_trace_write(uintptr_t reg, uint32_t value)
{
    g4_model_write(reg, value);
    if (g4_model.on_write != NULL) {
        g4_model.on_write(reg, value);
    }
}

static void g4_model_write(uintptr_t reg, uint32_t value)
{
    uint32_t *c = g4_model_cell(reg);
    if (g4_model.n_log < G4_MODEL_LOG_MAX) {
        g4_model.log[g4_model.n_log].reg = reg;
        g4_model.log[g4_model.n_log].value = value;
        g4_model.n_log++;
    } else {
        g4_model.log_overflow = true;
    }
    if (c == NULL) {
        return;
    }
    /* ADC: ISR is write-1-to-clear; ADCAL ends at once; ADEN raises ADRDY;
     * ADSTART converts at once (EOC, DR). */
    uintptr_t adc = 0u;
    if (reg >= G4_ADC1 && reg < G4_ADC1 + 0x100u) {
        adc = G4_ADC1;
    } else if (reg >= G4_ADC2 && reg < G4_ADC2 + 0x100u) {
        adc = G4_ADC2;
    }
    if (adc != 0u && reg == adc + G4_ADC_ISR) {
        *c &= ~value;
        return;
    }
    if (adc != 0u && reg == adc + G4_ADC_CR) {
        uint32_t *isr = (uint32_t *)(adc + G4_ADC_ISR);
        const uint32_t v = (*c & (G4_ADC_CR_ADEN | G4_ADC_CR_JADSTART)) | value;
        if ((value & G4_ADC_CR_ADEN) != 0u) {
            *isr |= G4_ADC_ISR_ADRDY;
        }
        if ((value & G4_ADC_CR_ADSTART) != 0u) {
            *isr |= G4_ADC_ISR_EOC | G4_ADC_ISR_EOS;
            *(uint32_t *)(adc + G4_ADC_DR) = g4_model.adc_regular;
        }
        *c = v & ~(G4_ADC_CR_ADCAL | G4_ADC_CR_ADSTART);
        return;
    }
    /* Flash (RM0440 sec. 3.3.5-3.3.8, simply: operations end at once, BSY
     * never reads set): KEY1 then KEY2 clears FLASH_CR.LOCK; a locked
     * FLASH_CR ignores writes; STRT with PER erases page PNB (the settings
     * pages hold memory, other pages are not modelled); with PG set a word
     * written into the settings pages programs it (bits only go 1 -> 0). The
     * detailed model of the interface is tests/board/test_g4_flash.c's. */
    if (reg == G4_FLASH + G4_FLASH_SR) {
        *c &= ~(value & 0xFFFFu); /* the flags are rc_w1 */
        return;
    }
    if (reg == G4_FLASH + G4_FLASH_ECCR) {
        const uint32_t w1c = G4_FLASH_ECCR_ECCC | G4_FLASH_ECCR_ECCD;
        *c = ((*c & ~(value & w1c)) & ~G4_FLASH_ECCR_ECCIE) | (value & G4_FLASH_ECCR_ECCIE);
        return;
    }
    if (reg == G4_FLASH + G4_FLASH_KEYR) {
        if (value == G4_FLASH_KEY2 && g4_model.flash_key1) {
            g4_mem_flash[G4_FLASH_CR / 4u] &= ~G4_FLASH_CR_LOCK;
        }
        g4_model.flash_key1 = value == G4_FLASH_KEY1;
        return;
    }
    if (reg == G4_FLASH + G4_FLASH_CR) {
        if ((*c & G4_FLASH_CR_LOCK) != 0u) {
            return;
        }
        *c = value & ~G4_FLASH_CR_STRT;
        const uint32_t page = (value & G4_FLASH_CR_PNB_MASK) >> G4_FLASH_CR_PNB_POS;
        if ((value & (G4_FLASH_CR_STRT | G4_FLASH_CR_PER)) ==
                (G4_FLASH_CR_STRT | G4_FLASH_CR_PER) &&
            page >= G4_FLASH_SETTINGS_PAGE) {
            memset(
                &g4_mem_flash_settings[(page - G4_FLASH_SETTINGS_PAGE) * G4_FLASH_PAGE_SIZE / 4u],
                0xFF, G4_FLASH_PAGE_SIZE);
        }
        return;
    }
    if (reg >= (uintptr_t)g4_mem_flash_settings &&
        reg < (uintptr_t)g4_mem_flash_settings + sizeof g4_mem_flash_settings) {
        if ((g4_mem_flash[G4_FLASH_CR / 4u] & G4_FLASH_CR_PG) != 0u) {
            *c &= value;
        }
        return;
    }
    /* USART ICR clears ISR flags. */
    if (reg == G4_USART2 + G4_USART_ICR) {
        g4_mem_usart2[G4_USART_ISR / 4u] &= ~value;
        return;
    }
    uintptr_t tb = 0u;
    if (reg >= G4_TIM1 && reg < G4_TIM1 + 0x400u) {
        tb = G4_TIM1;
    } else if (reg >= G4_TIM4 && reg < G4_TIM4 + 0x400u) {
        tb = G4_TIM4;
    } else if (reg >= G4_TIM2 && reg < G4_TIM2 + 0x400u) {
        tb = G4_TIM2;
    }
    if (tb != 0u) {
        if (reg == tb + G4_TIM_SR) {
            *c &= value; /* rc_w0 */
            /* RM0440 TIM1 break: BIF cannot be cleared while the break input
             * (here: a comparator output) is still active. */
            if (tb == G4_TIM1 && g4_model.comp_high &&
                (g4_mem_tim1[G4_TIM_BDTR / 4u] & G4_TIM_BDTR_BKE) != 0u) {
                *c |= G4_TIM_SR_BIF;
            }
            return;
        }
        if (reg == tb + G4_TIM_EGR) {
            if ((value & G4_TIM_EGR_BG) != 0u) {
                /* Software break: MOE cleared by the hardware, BIF set. */
                *(uint32_t *)(tb + G4_TIM_BDTR) &= ~G4_TIM_BDTR_MOE;
                *(uint32_t *)(tb + G4_TIM_SR) |= G4_TIM_SR_BIF;
            }
            return;
        }
        if (tb == G4_TIM1 && reg == tb + G4_TIM_RCR) {
            g4_model.rcr_written = true;
        }
        if (tb == G4_TIM1 && reg == tb + G4_TIM_CR1 && (value & G4_TIM_CR1_CEN) != 0u &&
            (*c & G4_TIM_CR1_CEN) == 0u) {
            g4_model.rcr_before_cen = g4_model.rcr_written;
        }
    }
    *c = value;
}
