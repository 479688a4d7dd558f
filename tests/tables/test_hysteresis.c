/*
 * Hysteresis regulators of Fig. 4.2 (control/hysteresis.h): the error walks up
 * and down through the bands and every output is the one Fig. 4.2 gives,
 * including the hold inside the band and the inclusive band edges.
 */
#include <stddef.h>
#include <stdint.h>

#include "hysteresis.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define H ((q24_t)335544) /* 0.02 pu in Q24 (2 % band of Table 4.7) */

typedef struct {
    q24_t err;
    int expect;
} step_t;

static void run2(ctrl_hyst2_t *h, const step_t *seq, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(seq[i].expect, ctrl_hyst2_update(h, seq[i].err),
                                      "two-level step");
        TEST_ASSERT_EQUAL_INT(seq[i].expect, h->out);
    }
}

static void run3(ctrl_hyst3_t *h, const step_t *seq, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(seq[i].expect, ctrl_hyst3_update(h, seq[i].err),
                                      "three-level step");
    }
}

/* Fig. 4.2(a): the output changes only when psi_s crosses psi_ref +- h. */
static void test_flux_two_level_walk(void)
{
    ctrl_hyst2_t h;
    ctrl_hyst2_init(&h, H);
    const step_t seq[] = {
        {0, 1}, /* no history: sign of the error (>= 0 -> increase) */
        {H / 2, 1},   {H - 1, 1},  {H, 1},      {2 * H, 1},
        {H / 2, 1},                             /* flux rises back into the band: hold +1 */
        {0, 1},       {-H / 2, 1}, {-H + 1, 1}, /* still inside: hold */
        {-H, -1},                               /* reaches psi_ref + h: inclusive edge switches */
        {-H / 2, -1}, {0, -1},     {H / 2, -1}, {H - 1, -1}, /* hold -1 across the band */
        {H, 1},                                              /* reaches psi_ref - h */
        {-3 * H, -1},                                        /* a jump across the whole band */
        {3 * H, 1},
    };
    run2(&h, seq, sizeof seq / sizeof seq[0]);
}

static void test_flux_two_level_start_below(void)
{
    ctrl_hyst2_t h;
    ctrl_hyst2_init(&h, H);
    const step_t seq[] = {{-1, -1}, {H - 1, -1}, {H, 1}};
    run2(&h, seq, 3);
    ctrl_hyst2_reset(&h);
    TEST_ASSERT_EQUAL_INT(0, h.out);
    TEST_ASSERT_EQUAL_INT(H, h.band); /* reset keeps the band */
    TEST_ASSERT_EQUAL_INT(1, ctrl_hyst2_update(&h, 0));
}

/* Fig. 4.2(b): the output changes when Te hits the reference or Tref +- h_T. */
static void test_torque_three_level_walk(void)
{
    ctrl_hyst3_t h;
    ctrl_hyst3_init(&h, H);
    const step_t seq[] = {
        {0, 0},       {H / 2, 0},
        {H - 1, 0},           /* reset state 0 holds inside +-h */
        {H, 1},               /* Te fell to Tref - h_T: increase */
        {H / 2, 1},   {1, 1}, /* rising through the lower half band: hold */
        {0, 0},               /* Te hits Tref: maintain (inclusive) */
        {H / 2, 0},   {-H / 2, 0},
        {-H + 1, 0},            /* hold 0 in both half bands */
        {-H, -1},               /* Te rose to Tref + h_T: decrease */
        {-H / 2, -1}, {-1, -1}, /* falling through the upper half band: hold */
        {0, 0},                 /* hits Tref from above */
        {H - 1, 0},   {H, 1},
        {-H / 2, 0},                /* overshoot past Tref in one sample: from +1 to 0 */
        {-H, -1},     {H / 2, 0},   /* and from -1 to 0 */
        {2 * H, 1},   {-2 * H, -1}, /* jumps across both bands */
        {2 * H, 1},
    };
    run3(&h, seq, sizeof seq / sizeof seq[0]);
}

static void test_zero_band_and_null(void)
{
    ctrl_hyst2_t h2;
    ctrl_hyst3_t h3;
    ctrl_hyst2_init(&h2, -5); /* negative band taken as 0 */
    ctrl_hyst3_init(&h3, 0);
    TEST_ASSERT_EQUAL_INT(0, h2.band);
    TEST_ASSERT_EQUAL_INT(1, ctrl_hyst2_update(&h2, 0)); /* upper test has priority */
    TEST_ASSERT_EQUAL_INT(-1, ctrl_hyst2_update(&h2, -1));
    TEST_ASSERT_EQUAL_INT(1, ctrl_hyst3_update(&h3, 0));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_hyst3_update(&h3, -1));
    TEST_ASSERT_EQUAL_INT(1, ctrl_hyst3_update(&h3, 1));
    /* Extreme errors: no overflow (UBSan) */
    ctrl_hyst3_init(&h3, FX_MAX);
    TEST_ASSERT_EQUAL_INT(-1, ctrl_hyst3_update(&h3, FX_MIN));
    TEST_ASSERT_EQUAL_INT(1, ctrl_hyst3_update(&h3, FX_MAX));
    h3.band = FX_MIN; /* written directly, not through init */
    (void)ctrl_hyst3_update(&h3, 0);
    /* NULL is not a crash */
    ctrl_hyst2_init(NULL, H);
    ctrl_hyst3_init(NULL, H);
    ctrl_hyst2_reset(NULL);
    ctrl_hyst3_reset(NULL);
    TEST_ASSERT_EQUAL_INT(1, ctrl_hyst2_update(NULL, 3));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_hyst2_update(NULL, -3));
    TEST_ASSERT_EQUAL_INT(0, ctrl_hyst3_update(NULL, 3));
}

/* The regulator on |.|^2 (ctrl_hyst2_sq_t) gives the outputs of
 * ctrl_hyst2_update(ref - fx_mag(x, y)) step for step: amplitudes walking
 * through and around the band edges (where the rounding of the root decides),
 * references that move (the limits formed again), bands from 0 up, the
 * first sample after a reset (the sign), and large values. */
static uint64_t hs_rng = 0x2545F4914F6CDD1Dull;
static uint32_t hs_next(void)
{
    hs_rng ^= hs_rng << 13;
    hs_rng ^= hs_rng >> 7;
    hs_rng ^= hs_rng << 17;
    return (uint32_t)(hs_rng >> 11);
}

static void test_flux_on_square_equals_root(void)
{
    ctrl_hyst2_t ref_h;
    ctrl_hyst2_sq_t sq;
    const q24_t bands[] = {H, 0, 1, 7, FX_ONE, (q24_t)1 << 29};
    const q24_t refs[] = {FX_ONE, FX_ONE + 3, 1, 0, 40 * FX_ONE, (q24_t)1 << 30};
    for (size_t bi = 0; bi < sizeof bands / sizeof bands[0]; bi++) {
        ctrl_hyst2_init(&ref_h, bands[bi]);
        ctrl_hyst2_sq_init(&sq, bands[bi]);
        for (int k = 0; k < 20000; k++) {
            if (k % 5000 == 2500) {
                ctrl_hyst2_reset(&ref_h);
                ctrl_hyst2_reset(&sq.h);
            }
            const q24_t ref = refs[(k / 700) % (sizeof refs / sizeof refs[0])];
            if (k % 700 == 0) {
                ctrl_hyst2_sq_limits(&sq, ref); /* the owner's part: the reference moved */
            }
            /* an amplitude near an edge (ref - band, ref, ref + band) or anywhere */
            const int64_t edge[4] = {(int64_t)ref - bands[bi], ref, (int64_t)ref + bands[bi],
                                     (int64_t)(hs_next() >> 1)};
            const int64_t a = edge[hs_next() % 4u] + (int64_t)(hs_next() % 9u) - 4;
            const int64_t am = a < 0 ? -a : (a > ((int64_t)1 << 30) ? ((int64_t)1 << 30) : a);
            /* (x, y) of that amplitude: on an axis, or split with a rounding */
            const q24_t x = (q24_t)(hs_next() % 2u ? am : (am * 3) / 5);
            const q24_t y =
                (q24_t)(hs_next() % 2u ? 0 : -((am * 4) / 5 + (int64_t)(hs_next() % 3u)));
            const uint64_t s = (uint64_t)((int64_t)x * x) + (uint64_t)((int64_t)y * y);
            const int8_t want = ctrl_hyst2_update(&ref_h, fx_sub(ref, fx_mag(x, y)));
            TEST_ASSERT_EQUAL_INT_MESSAGE(want, ctrl_hyst2_sq_update(&sq, s), "on |.|^2");
        }
    }
    /* band 0, |.| just above 1 pu but rounding to it: err == 0 gives +1 */
    ctrl_hyst2_init(&ref_h, 0);
    ctrl_hyst2_sq_init(&sq, -3); /* negative band taken as 0 */
    ctrl_hyst2_sq_limits(&sq, FX_ONE);
    const uint64_t s1 = (uint64_t)FX_ONE * FX_ONE + 1u;
    TEST_ASSERT_EQUAL_INT(ctrl_hyst2_update(&ref_h, 0), ctrl_hyst2_sq_update(&sq, s1));
    TEST_ASSERT_EQUAL_INT(1, sq.h.out);
    ctrl_hyst2_sq_init(NULL, H); /* NULL is not a crash */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_flux_two_level_walk);
    RUN_TEST(test_flux_two_level_start_below);
    RUN_TEST(test_torque_three_level_walk);
    RUN_TEST(test_zero_band_and_null);
    RUN_TEST(test_flux_on_square_equals_root);
    return UNITY_END();
}
