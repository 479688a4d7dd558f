/*
 * Open-loop replay: apply a recorded switching sequence to the plant and write
 * the true signals at the end of every interval.
 *
 * Input CSV: header "t_start_s,duration_s,S1,S2,S3", then one row per interval;
 * duration_s is converted to whole nanoseconds (rounded; any value >= 0, not
 * on a grid); t_start_s is checked to be consecutive (|t_start - t_end_prev|
 * < 1 ns, else error). S1..S3 in {0, 1}. Lines that are empty or start with
 * '#' are skipped.
 * Trace CSV: header "t,i_a,i_b,i_c,i_d,i_q,psi_alpha,psi_beta,torque", one row
 * at the end of each interval (%.9g for t, %.12g for the rest).
 */
#ifndef SIM_HOST_SIM_REPLAY_H
#define SIM_HOST_SIM_REPLAY_H

#include <stddef.h>
#include <stdio.h>

#include "plant.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double speed_rpm;    /* imposed mechanical speed */
    double theta0_e_rad; /* initial electrical angle */
    double id0_a, iq0_a; /* initial currents */
} sim_replay_opts_t;

/* A malformed replay file (or one that cannot be opened, or a trace that
 * cannot be created): the input's fault, not the run's. */
#define SIM_REPLAY_EINPUT (-2)

/* base: plant configuration of the machine (its mech/initial fields are
 * overridden by opts). Returns 0; SIM_REPLAY_EINPUT with "file:line: message"
 * in err for a malformed input; -1 for a plant or I/O failure. */
int sim_replay_run(const plant_config_t *base, const sim_replay_opts_t *opts, FILE *in,
                   const char *in_name, FILE *trace, char *err, size_t errlen);

/* Same, by file names. */
int sim_replay_files(const plant_config_t *base, const sim_replay_opts_t *opts, const char *in_path,
                     const char *trace_path, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif /* SIM_HOST_SIM_REPLAY_H */
