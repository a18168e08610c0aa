/* SPDX-License-Identifier: MIT */
/* rch_urdf.h - the URDF reader: the names of a nominal URDF (robot, joints,
 * links, flange) that `rcal export --nominal-urdf` keeps, so that a
 * calibrated URDF drops into a ROS set-up in place of the nominal one. A
 * parser of outside input: fuzzed (fuzz/fuzz_urdf.c) like the others.
 *
 * Host side (prefix rch_urdf_). */
#ifndef RCH_URDF_H
#define RCH_URDF_H

#include <stddef.h>

#include "rc_model.h"
#include "rch_diag.h"

#define RCH_URDF_NAME_MAX 128 /* bytes of a name, NUL included */

/* The names of the URDF: generated (rch_urdf_names_default) or taken from a
 * nominal URDF (rch_urdf_names_parse). */
typedef struct {
    char robot[RCH_URDF_NAME_MAX];
    char base_link[RCH_URDF_NAME_MAX];          /* parent of joint 1 */
    char joint[RC_NJ][RCH_URDF_NAME_MAX];       /* joint i+1 */
    char link[RC_NJ][RCH_URDF_NAME_MAX];        /* child link of joint i+1 */
    int continuous[RC_NJ];                      /* 1: "continuous", 0: "revolute" */
    char flange_joint[RCH_URDF_NAME_MAX];       /* fixed joint after joint 6 */
    char flange_link[RCH_URDF_NAME_MAX];
    unsigned n_dropped;                         /* nominal joints not in the chain (not written) */
} rch_urdf_names;

/* robot (or "robot" when NULL), link_0, joint_1..joint_6, link_1..link_6,
 * flange_joint, flange; all revolute. */
void rch_urdf_names_default(rch_urdf_names *n, const char *robot);

/* Names from a nominal URDF's text: the robot name, and the six movable
 * joints (revolute or continuous; a prismatic or planar one is refused) in
 * chain order, each with its parent and child link, plus the first fixed
 * joint hanging from the last link (the flange; generated names when there is
 * none). Joints inside <transmission> or other elements are ignored. The
 * reader knows XML's comments, processing instructions, DOCTYPE, CDATA, both
 * quote styles and the five named and the numeric character references; it
 * refuses a document that is not well formed where it matters (unclosed or
 * crossed tags, a missing attribute, a name over 127 bytes). file names the
 * input in messages. */
int rch_urdf_names_parse(rch_urdf_names *n, const char *text, size_t len, const char *file, rch_diag *d);

#endif
