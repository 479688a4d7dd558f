/*
 * Every register constant of the STM32F405 chip support (f4_regs.h and the
 * flash driver's f4_flash.h) against the list of facts in f4_facts.txt,
 * written from ST's CMSIS header stm32f405xx.h, RM0090 and the ARMv7-M
 * Architecture Reference Manual (each line names its source). The table is
 * generated from that list at build time (f4_facts_gen.py): the compiler
 * evaluates the chip support's constant, this test compares it with the
 * listed value, and requires a fact for every constant the headers define
 * (at least one for each function-like one), so that a new constant cannot
 * come without its source.
 *
 * Built without F4_MEM_ARRAYS: the peripheral bases are the chip's
 * addresses (nothing is dereferenced).
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "f4_flash.h"
#include "f4_regs.h"
#include "unity.h"

typedef struct {
    const char *expr;
    uint32_t actual, expected;
    const char *source;
} f4_fact_t;

typedef struct {
    const char *name;
    bool function_like;
} f4_name_t;

#include "f4_facts_table.h"

#define N_FACTS (sizeof f4_facts / sizeof f4_facts[0])
#define N_NAMES (sizeof f4_names / sizeof f4_names[0])

void setUp(void)
{
}

void tearDown(void)
{
}

/* Each fact's value equals the chip support's constant. */
static void test_values(void)
{
    unsigned bad = 0u;
    for (size_t i = 0; i < N_FACTS; i++) {
        if (f4_facts[i].actual != f4_facts[i].expected) {
            char msg[256];
            (void)snprintf(msg, sizeof msg, "%s = 0x%08X, %s says 0x%08X", f4_facts[i].expr,
                           (unsigned)f4_facts[i].actual, f4_facts[i].source,
                           (unsigned)f4_facts[i].expected);
            TEST_MESSAGE(msg);
            bad++;
        }
    }
    TEST_ASSERT_EQUAL_UINT_MESSAGE(0u, bad, "register constants that differ from the facts");
}

/* The fact that names a constant: its expression is the name, or (for a
 * function-like one) the name followed by '('. */
static bool f4_has_fact(const f4_name_t *n)
{
    const size_t len = strlen(n->name);
    for (size_t i = 0; i < N_FACTS; i++) {
        const char *e = f4_facts[i].expr;
        if (strncmp(e, n->name, len) == 0 && (n->function_like ? e[len] == '(' : e[len] == '\0')) {
            return true;
        }
    }
    return false;
}

/* Every constant the headers define has a fact. */
static void test_coverage(void)
{
    unsigned missing = 0u;
    for (size_t i = 0; i < N_NAMES; i++) {
        if (!f4_has_fact(&f4_names[i])) {
            char msg[96];
            (void)snprintf(msg, sizeof msg, "no fact for %s", f4_names[i].name);
            TEST_MESSAGE(msg);
            missing++;
        }
    }
    TEST_ASSERT_EQUAL_UINT_MESSAGE(0u, missing, "constants without a fact in f4_facts.txt");
    TEST_ASSERT_TRUE(N_FACTS >= N_NAMES);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_values);
    RUN_TEST(test_coverage);
    return UNITY_END();
}
