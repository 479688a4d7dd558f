/* Machine data for the DRR tests: the shipped machine files (docs/README.md, "Machines"),
 * ini_thesis_spmsm (sim_host/machines/thesis_spmsm.ini) and the others. */
#ifndef TESTS_DRR_MACHINES_H
#define TESTS_DRR_MACHINES_H

#include "../plant/ini_machines.h"

#endif /* TESTS_DRR_MACHINES_H */
