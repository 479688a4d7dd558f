#ifndef HELP_TEXT_H
#define HELP_TEXT_H

/*
 * One-line descriptions of tunables, parameters and telemetry signals.
 * PMSM_HELP_TEXT = 0 (the B-G431B-ESC1 image) drops them from the image: they
 * belong on the PC, where `./tools/sim --list-tunables NAME`, the host and QEMU
 * builds' `param list` / `tel list` show them. Listings then end without
 * them. NULL marks "no text".
 */
#ifndef PMSM_HELP_TEXT
#define PMSM_HELP_TEXT 1
#endif

#if PMSM_HELP_TEXT
#define HELP_TEXT(text) (text)
#else
#define HELP_TEXT(text) ((const char *)0)
#endif

#endif /* HELP_TEXT_H */
