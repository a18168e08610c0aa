/* SPDX-License-Identifier: MIT */
/* rt_rsi_loop.h - rcal-rt as a KUKA RSI partner in correction mode
 * (rcal-rt --model M.json --rsi-port PORT ...; docs/rsi.md). */
#ifndef RT_RSI_LOOP_H
#define RT_RSI_LOOP_H

#include <stdio.h>

/* The whole RSI mode (rcal_rt.c calls it when an option starts with --rsi-): its options, the model, the UDP loop until --seconds
 * or SIGINT/SIGTERM, the report. Exit status: 0 after a clean stop, 1 for a
 * model, file or socket error, 2 for a usage error. */
int rt_rsi_main(int argc, char **argv);

/* The RSI options' help (part of rcal-rt --help). */
void rt_rsi_usage(FILE *f);

#endif
