/* Helpers of the anti-cogging tests: the plant's cogging as a table, the
 * ripple runs, the calibration run (test_cogging.c, test_cogging_start.c). */
#ifndef TESTS_COGGING_COG_UTIL_H
#define TESTS_COGGING_COG_UTIL_H

#include <stdint.h>

#include "cm_cogging.h"
#include "sim_run.h"

/* The plant's cogging torque at mechanical angle th (rad), N*m. */
double cog_truth(const plant_config_t *pc, double th);
/* The ideal table: -T_cog at each entry's angle (encoder aligned, counting up). */
void cog_table_truth(const sim_machine_t *m, int16_t *table);

/* The ideal table as the calibration measures it: the encoder's count is the
 * floor of the angle, so a count's samples average half a count beyond it
 * (the bins centred on their entries keep that): -T_cog half a count after
 * each entry's angle. */
void cog_table_counted(const sim_machine_t *m, int16_t *table);

/* Torque mode at frac of the rated torque on the dynamometer at rpm with
 * table (NULL: none), window_s (whole cogging periods) after settle_s: the
 * phasors at the cogging fundamental of the mechanical angle (re, im; N*m) of
 * the electromagnetic torque te and of -T_cog (what it should be). */
void cog_torque_phasor(const sim_machine_t *m, const char *ctrl, const int16_t *table, double rpm,
                       double frac, double settle_s, double window_s, double te[2], double cog[2]);

typedef struct {
    double speed_sd_rpm;  /* speed mode at 30 r/min: sd of the true speed */
    double speed_cog_rpm; /* its amplitude at the cogging harmonics of the angle (RSS) */
    double torque_sd_nm;  /* torque mode at 5 % rated, dynamometer at 30 r/min: sd of
                             Te + T_cog sampled once a period */
    double torque_cog_nm; /* its amplitude at the cogging harmonics of the angle (RSS) */
} cog_ripple_t;

/* The two ripple runs with table (NULL: no feed-forward); window_s after
 * settle_s. */
void cog_ripple(const sim_machine_t *m, const char *ctrl, const int16_t *table, double settle_s,
                double window_s, cog_ripple_t *out);

/* The calibration (step "cogging") on m at rpm / bw_hz: 0 and the table, or
 * the step's error (cm_err_t). */
int cog_calibrate(const sim_machine_t *m, double rpm, double bw_hz, int16_t *table,
                  double *friction_nm, double *peak_nm, double *seconds);

/* The calibration on m at rpm / bw_hz, its table against the plant's
 * cogging and the friction it reports, then the ripple without and with the
 * table, printed; asserts each of the cogging's shares reduced by 80 %. */
void cog_case(const char *name, const sim_machine_t *m, double rpm, double bw_hz);

#endif /* TESTS_COGGING_COG_UTIL_H */
