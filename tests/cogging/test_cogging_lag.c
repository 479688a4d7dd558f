/*
 * The anti-cogging look-ahead (docs/anticogging.md, "The look-ahead") in the
 * plant: the torque a controller makes answers the reference formed from the
 * position it sampled a delay tau later, when the rotor has moved on; the
 * table is read ahead by the speed times the tau derived for the controller
 * (pipeline_config.c, fw_cogging_lead). The gimbal motor's cogging (264
 * periods per revolution: 132 Hz at 30 r/min) is where the delay shows: FOC's
 * 0.43 ms there is 21 degrees of a cogging period and leaves 35 % of the
 * cogging at its frequency without the look-ahead.
 *
 * Torque mode at 5 % of the rated torque on the dynamometer at 30 r/min, the
 * table the calibration would measure (the plant's cogging, half a count on
 * for the encoder's floor), the electromagnetic torque's phasor at the
 * cogging fundamental against -T_cog's:
 *   - the cogging at its frequency reduced by at least 80 %;
 *   - the torque's remaining lag behind -T_cog within one period Ts of zero:
 *     the derived tau matches the plant's delay (a tau of the wrong sign
 *     doubles the lag, and none leaves it whole).
 * FOC (tau = 1.5 Ts + 1 / wc), and M2PTFC and SVM-DTC (2 Ts).
 */
#include <math.h>
#include <stdio.h>

#include "cog_util.h"
#include "loop_util.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define LAG_PI 3.14159265358979323846

static int16_t tab[CTRL_COG_N];

static void lag_case(const char *ctrl)
{
    const sim_machine_t m = loop_machine_file("nonideal/gbm5208_gimbal_stress.ini");
    cog_table_counted(&m, tab);
    const double rpm = 30.0;
    const double f_cog = rpm / 60.0 * (double)sim_machine_cog_per_rev(&m);
    double te0[2], c0[2], te1[2], c1[2];
    cog_torque_phasor(&m, ctrl, NULL, rpm, 0.05, 0.4, 0.25, te0, c0);
    cog_torque_phasor(&m, ctrl, tab, rpm, 0.05, 0.4, 0.25, te1, c1);
    /* residual at the cogging frequency: Te - (-T_cog) */
    const double r0 = hypot(te0[0] - c0[0], te0[1] - c0[1]);
    const double r1 = hypot(te1[0] - c1[0], te1[1] - c1[1]);
    /* Te / (-T_cog): gain and lag */
    const double den = c1[0] * c1[0] + c1[1] * c1[1];
    const double gr = (te1[0] * c1[0] + te1[1] * c1[1]) / den;
    const double gi = (te1[1] * c1[0] - te1[0] * c1[1]) / den;
    const double lag_s = -atan2(gi, gr) / (2.0 * LAG_PI * f_cog);
    const double ts = 1.0 / (double)ctrl_find(ctrl)->fs_default_hz;
    printf("%s: cogging at %.1f Hz: %.5f -> %.5f N*m (%.1f %%); torque against -T_cog: gain %.3f, "
           "lag %.1f us (%.2f Ts)\n",
           ctrl, f_cog, r0, r1, 100.0 * r1 / r0, hypot(gr, gi), lag_s * 1e6, lag_s / ts);
    TEST_ASSERT_TRUE_MESSAGE(r1 < 0.2 * r0, ctrl);
    TEST_ASSERT_TRUE_MESSAGE(fabs(lag_s) < ts, ctrl);
}

static void test_foc(void)
{
    lag_case("foc");
}

static void test_m2ptfc(void)
{
    lag_case("m2ptfc");
}

static void test_svm_dtc(void)
{
    lag_case("svm_dtc");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_foc);
    RUN_TEST(test_m2ptfc);
    RUN_TEST(test_svm_dtc);
    return UNITY_END();
}
