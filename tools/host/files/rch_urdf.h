/* SPDX-License-Identifier: MIT */
/* rch_urdf.h - the URDF reader: the XML parsed by expat (libexpat), the
 * robot's joints (type, parent, child, origin, axis, limits, and where the
 * <origin> start tag sits in the text, for the overlay of `rcal export
 * --nominal-urdf`) and links; the names a calibrated URDF keeps; the
 * six-joint serial chain (rch_urdf_robot.h turns it into a model). A parser
 * of outside input: fuzzed (fuzz/fuzz_urdf.c) like the others.
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

#define RCH_URDF_MAX_JOINTS 512
#define RCH_URDF_MAX_LINKS 1024

/* One <joint> of <robot>. */
typedef struct {
    char name[RCH_URDF_NAME_MAX], type[32], parent[RCH_URDF_NAME_MAX], child[RCH_URDF_NAME_MAX];
    double xyz[3], rpy[3];  /* <origin> (m, rad; 0 when absent) */
    double axis[3];         /* <axis xyz> (default 1 0 0) */
    int has_origin, has_limit;
    double lower, upper;    /* <limit> (rad) */
    size_t origin_at, origin_len; /* the <origin ...> start tag's bytes in the text (has_origin) */
    size_t tag_end;         /* the byte after the <joint ...> start tag */
    unsigned line, col;
} rch_urdf_joint;

typedef struct {
    char robot[RCH_URDF_NAME_MAX];
    rch_urdf_joint *joint; /* (n_joints) in document order */
    size_t n_joints;
    char (*link)[RCH_URDF_NAME_MAX];
    size_t n_links;
} rch_urdf_doc;

/* Parse text[0..len) (a UTF-8 byte-order mark allowed; no external entity is
 * loaded). 0, or -1 with d set (file:line:col, expat's reason for XML that is
 * not well formed). Free with rch_urdf_doc_free. */
int rch_urdf_doc_parse(rch_urdf_doc *doc, const char *text, size_t len, const char *file, rch_diag *d);
void rch_urdf_doc_free(rch_urdf_doc *doc);

/* The six movable joints in chain order (indices into doc->joint): every
 * movable joint revolute or continuous, six of them, each the only one
 * downstream of the one before through fixed joints. 0, or -1 with the
 * reason in d. */
int rch_urdf_chain(size_t chain[RC_NJ], const rch_urdf_doc *doc, const char *file, rch_diag *d);

/* robot (or "robot" when NULL), link_0, joint_1..joint_6, link_1..link_6,
 * flange_joint, flange; all revolute. */
void rch_urdf_names_default(rch_urdf_names *n, const char *robot);

/* Names from a nominal URDF's text: the robot name, and the six movable
 * joints (revolute or continuous; a prismatic or planar one is refused) in
 * chain order, each with its parent and child link, plus the first fixed
 * joint hanging from the last link (the flange; generated names when there is
 * none). Joints inside <transmission> or other elements are ignored. The
 * XML is expat's: a document that is not well formed is refused with
 * expat's reason, as is a missing attribute or a name over 127 bytes. file
 * names the input in messages. */
int rch_urdf_names_parse(rch_urdf_names *n, const char *text, size_t len, const char *file, rch_diag *d);

#endif
