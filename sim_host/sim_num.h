/*
 * A number written as text in the simulator's inputs (machine files, scenarios,
 * the command line): the whole string one finite number. Host only.
 */
#ifndef SIM_HOST_SIM_NUM_H
#define SIM_HOST_SIM_NUM_H

/* 0 with the value in *out when s is exactly one finite number (strtod's
 * syntax, nothing before or after it, not out of double's range); -1 otherwise,
 * *out unchanged. */
int sim_num_parse(const char *s, double *out);

#endif /* SIM_HOST_SIM_NUM_H */
