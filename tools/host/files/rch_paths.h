/* SPDX-License-Identifier: MIT */
/* rch_paths.h - where the data files shipped with rcal (data/irb120.json, the
 * demo data set) are found at run time, so that a program works from the
 * build tree and from an installed (or copied, relocated) prefix alike.
 *
 * A file is looked for, in order, in
 *   1. $RCAL_DATA_DIR/<file>                      (environment, when set)
 *   2. <dir of the running program>/<bin-to-data>/<file>, i.e.
 *      <prefix>/bin/../share/rcal/<file> for an installed program
 *      (the running program from /proc/self/exe)
 *   3. <source tree>/data/<file>, only when the running program lives in the
 *      build tree it was built in (an installed program never reads the
 *      source tree)
 * and the first that exists is taken.
 *
 * Host side: uses POSIX (readlink, access). rch_default_robot() keeps its
 * answer in a static buffer: not thread-safe on its first call.
 */
#ifndef RCH_PATHS_H
#define RCH_PATHS_H

#include <stddef.h>

/* Path of the data file `file` (a bare name, e.g. "irb120.json") into buf
 * (len bytes). Returns 0 when found; -1 when not found in any place (buf then
 * holds the place an installed program would use, for messages) or when the
 * path does not fit in len (buf then holds ""). */
int rch_data_path(char *buf, size_t len, const char *file);

/* The nominal robot model, irb120.json, by rch_data_path(): a path that
 * lives until the program exits. Never NULL. */
const char *rch_default_robot(void);

#ifndef RCAL_DEFAULT_ROBOT
#define RCAL_DEFAULT_ROBOT rch_default_robot()
#endif

#endif /* RCH_PATHS_H */
