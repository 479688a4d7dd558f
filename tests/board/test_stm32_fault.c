/*
 * The fault record a Cortex-M4 image leaves for its next start-up
 * (hal/stm32/stm32_fault.h): filled from an exception frame only when the
 * frame lies inside RAM, believed only with its magic and check word (RAM
 * after a power-on holds anything), taken once, and described by name: the
 * exception, the stacked PC, LR and xPSR, and every CFSR / HFSR fault bit by
 * its ARMv7-M ARM meaning (B3.2.15, B3.2.16).
 */
#include <stdio.h>
#include <string.h>

#include "stm32_fault.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

/* r0 r1 r2 r3 r12 lr pc xpsr, 8-byte aligned as the core stacks it; "RAM"
 * is its first 64 words (the rest lets a frame straddle RAM's end). */
static uint32_t ram[72] __attribute__((aligned(8)));

static void frame_at(unsigned i, uint32_t lr, uint32_t pc, uint32_t xpsr)
{
    memset(&ram[i], 0, 8u * sizeof ram[0]);
    ram[i + STM32_FRAME_LR] = lr;
    ram[i + STM32_FRAME_PC] = pc;
    ram[i + STM32_FRAME_XPSR] = xpsr;
}

static void describe(const stm32_fault_rec_t *r, char *out, size_t cap)
{
    const int n = stm32_fault_describe(r, out, cap);
    TEST_ASSERT_TRUE(n > 0 && (size_t)n < cap);
}

/* A bus fault on an instruction fetch from nowhere (QEMU's boot test makes
 * one): the frame's PC is the address, CFSR.IBUSERR named. */
static void test_bus_fault_described(void)
{
    stm32_fault_rec_t rec, got;
    frame_at(8, 0xFFFFFFE9u, 0x30000000u, 0x61000037u);
    stm32_fault_fill(&rec, 5u, &ram[8], (uintptr_t)ram, (uintptr_t)(ram + 64), 0x100u, 0u, 0u, 0u);
    TEST_ASSERT_TRUE(stm32_fault_take(&rec, &got));
    char text[192];
    describe(&got, text, sizeof text);
    TEST_ASSERT_EQUAL_STRING("BusFault at pc 0x30000000 (lr 0xffffffe9, xpsr 0x61000037): "
                             "instruction bus error; CFSR 0x100 HFSR 0x0",
                             text);
    /* taken once: the record is cleared */
    TEST_ASSERT_FALSE(stm32_fault_take(&rec, &got));
}

/* An escalated fault: HardFault with FORCED, the configurable fault's bits
 * and the faulting address when BFARVALID says it is valid. */
static void test_escalated_with_address(void)
{
    stm32_fault_rec_t rec, got;
    frame_at(0, 0x08001235u, 0x08004010u, 0x01000000u);
    stm32_fault_fill(&rec, 3u, &ram[0], (uintptr_t)ram, (uintptr_t)(ram + 64),
                     (1u << 9) | (1u << 15), 1u << 30, 0u, 0x40080000u);
    TEST_ASSERT_TRUE(stm32_fault_take(&rec, &got));
    char text[192];
    describe(&got, text, sizeof text);
    TEST_ASSERT_NOT_NULL(strstr(text, "HardFault at pc 0x8004010"));
    TEST_ASSERT_NOT_NULL(strstr(text, "precise data bus error, escalated to HardFault"));
    TEST_ASSERT_NOT_NULL(strstr(text, "BFAR 0x40080000"));
    /* usage faults by name */
    stm32_fault_fill(&rec, 6u, &ram[0], (uintptr_t)ram, (uintptr_t)(ram + 64), 1u << 25, 0u, 0u,
                     0u);
    describe(&rec, text, sizeof text);
    TEST_ASSERT_NOT_NULL(strstr(text, "UsageFault at pc"));
    TEST_ASSERT_NOT_NULL(strstr(text, "division by zero"));
}

/* A stack pointer outside RAM (a cause of faults): the frame is not read. */
static void test_frame_outside_ram_not_read(void)
{
    stm32_fault_rec_t rec, got;
    frame_at(60, 1u, 2u, 3u);
    /* the frame's last words would lie past the end of RAM */
    stm32_fault_fill(&rec, 4u, &ram[60], (uintptr_t)ram, (uintptr_t)(ram + 64), 1u << 1, 0u, 0u,
                     0u);
    TEST_ASSERT_TRUE(stm32_fault_take(&rec, &got));
    TEST_ASSERT_EQUAL_UINT32(0u, got.frame_ok);
    TEST_ASSERT_EQUAL_UINT32(0u, got.pc);
    char text[192];
    describe(&got, text, sizeof text);
    TEST_ASSERT_NOT_NULL(strstr(text, "MemManage (stack pointer outside RAM: no frame)"));
    TEST_ASSERT_NOT_NULL(strstr(text, "data access violation"));
    /* below RAM and misaligned: not read either */
    stm32_fault_fill(&rec, 3u, (const uint32_t *)(uintptr_t)0x10u, (uintptr_t)ram,
                     (uintptr_t)(ram + 64), 0u, 0u, 0u, 0u);
    TEST_ASSERT_EQUAL_UINT32(0u, rec.frame_ok);
    stm32_fault_fill(&rec, 3u, (const uint32_t *)((uintptr_t)&ram[4] + 2u), (uintptr_t)ram,
                     (uintptr_t)(ram + 64), 0u, 0u, 0u, 0u);
    TEST_ASSERT_EQUAL_UINT32(0u, rec.frame_ok);
}

/* An interrupt without a handler (the fault handler's alias) and a stop by
 * the program itself (abort, exit). */
static void test_irq_and_stop(void)
{
    stm32_fault_rec_t rec;
    char text[192];
    frame_at(16, 0u, 0x08010000u, 0u);
    stm32_fault_fill(&rec, 16u + 39u, &ram[16], (uintptr_t)ram, (uintptr_t)(ram + 64), 0u, 0u, 0u,
                     0u);
    describe(&rec, text, sizeof text);
    TEST_ASSERT_NOT_NULL(strstr(text, "IRQ 39 (no handler) at pc 0x8010000"));
    TEST_ASSERT_NOT_NULL(strstr(text, "no fault status bit"));
    stm32_fault_fill(&rec, 0u, NULL, 0u, 0u, 0u, 0u, 0u, 0u);
    describe(&rec, text, sizeof text);
    TEST_ASSERT_EQUAL_STRING("stop: no fault status bit; CFSR 0x0 HFSR 0x0", text);
}

/* RAM after a power-on: no magic, or a magic with a wrong check, or any
 * word changed since the record was written: not believed, and cleared. */
static void test_garbage_not_believed(void)
{
    stm32_fault_rec_t rec, got;
    memset(&rec, 0xA5, sizeof rec);
    TEST_ASSERT_FALSE(stm32_fault_take(&rec, &got));
    TEST_ASSERT_EQUAL_UINT32(0u, rec.magic);
    memset(&rec, 0xA5, sizeof rec);
    rec.magic = STM32_FAULT_MAGIC;
    TEST_ASSERT_FALSE(stm32_fault_take(&rec, &got));
    frame_at(0, 1u, 2u, 3u);
    const uint32_t words = sizeof rec / sizeof(uint32_t);
    for (uint32_t w = 1; w + 1u < words; w++) { /* every word but magic and check */
        stm32_fault_fill(&rec, 5u, &ram[0], (uintptr_t)ram, (uintptr_t)(ram + 64), 0x100u, 0u, 0u,
                         0u);
        ((uint32_t *)&rec)[w] ^= 1u << (w % 32u);
        TEST_ASSERT_FALSE_MESSAGE(stm32_fault_take(&rec, &got), "a changed word believed");
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bus_fault_described);
    RUN_TEST(test_escalated_with_address);
    RUN_TEST(test_frame_outside_ram_not_read);
    RUN_TEST(test_irq_and_stop);
    RUN_TEST(test_garbage_not_believed);
    return UNITY_END();
}
