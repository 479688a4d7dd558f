/*
 * The anti-cogging calibration and the ripple it removes on the shipped
 * stress machines whose cogging has many periods per revolution, which
 * makes the calibration's sweep long (ctest label "long", outside the
 * default run: ctest -L long):
 *   outrunner_24v_stress: 12 slots, 7 pole pairs: 84 cogging periods per
 *     revolution; the sweep at 12 r/min keeps them at 16.8 Hz, under a
 *     quarter of the position loop's 80 Hz (cm_cogging.h): 2 x 5 s;
 *   gbm5208_gimbal_stress: 24 slots, 11 pole pairs: 264 periods per
 *     revolution; 4 r/min (17.6 Hz) at 80 Hz: 2 x 15 s;
 *   mj5208_drone_stress: 12 slots, 7 pole pairs: 84 periods; 15 r/min
 *     (21 Hz) at 80 Hz: 2 x 4 s.
 * The same assertions as test_cogging.c's (cog_case): the table within 25 %
 * rms of the plant's cogging, the friction within 10 %, the cogging's share
 * of the speed ripple at 30 r/min and the torque ripple at 5 % of rated each
 * reduced by 80 %.
 */
#include "cog_util.h"
#include "loop_util.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static void test_outrunner_24v_stress(void)
{
    const sim_machine_t m = loop_machine_file("nonideal/outrunner_24v_stress.ini");
    cog_case("outrunner_24v_stress", &m, 12.0, 80.0);
}

static void test_gbm5208_gimbal_stress(void)
{
    const sim_machine_t m = loop_machine_file("nonideal/gbm5208_gimbal_stress.ini");
    cog_case("gbm5208_gimbal_stress", &m, 4.0, 80.0);
}

static void test_mj5208_drone_stress(void)
{
    const sim_machine_t m = loop_machine_file("nonideal/mj5208_drone_stress.ini");
    cog_case("mj5208_drone_stress", &m, 15.0, 80.0);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_outrunner_24v_stress);
    RUN_TEST(test_gbm5208_gimbal_stress);
    RUN_TEST(test_mj5208_drone_stress);
    return UNITY_END();
}
