/* SPDX-License-Identifier: MIT */
/* rch_cell_read.h - a robot file's "links" (capsules) and "cell" (floor,
 * boxes) members into an rch_cell (rch_cell.h; docs/model-format.md).
 * Either member may be NULL (absent). 0, or -1 with d set at the value's
 * file:line:col (unknown keys refused as everywhere in the file). */
#ifndef RCH_CELL_READ_H
#define RCH_CELL_READ_H

#include "rch_cell.h"
#include "rch_diag.h"
#include "rch_json.h"

int rch_cell_read(rch_cell *out, const rch_json *links, const rch_json *cell, const char *file, rch_diag *d);

#endif
