/* Machine data for the MPC tests: the shipped machine files (docs/README.md,
 * "Machines"), ini_thesis_spmsm, ini_thesis_ipmsm80, ini_chapter_ipmsm. */
#ifndef TESTS_MPC_MACHINES_H
#define TESTS_MPC_MACHINES_H

#include "../plant/ini_machines.h"

#endif /* TESTS_MPC_MACHINES_H */
