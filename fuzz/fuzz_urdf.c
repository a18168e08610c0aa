/* SPDX-License-Identifier: MIT */
/* fuzz_urdf.c - the URDF reader (rch_urdf_names_parse). An accepted document
 * gives six joints and their links, every name NUL-terminated inside its
 * buffer; a refused one says why. */
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_urdf.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_name(const char *s)
{
    FZ_CHECK(memchr(s, '\0', RCH_URDF_NAME_MAX) != NULL);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rch_urdf_names n;
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_urdf_names_parse(&n, (const char *)data, size, "fuzz.urdf", &d) == 0) {
        check_name(n.robot);
        check_name(n.base_link);
        check_name(n.flange_joint);
        check_name(n.flange_link);
        FZ_CHECK(n.flange_link[0] != '\0' && n.flange_joint[0] != '\0');
        for (int i = 0; i < RC_NJ; ++i) {
            check_name(n.joint[i]);
            check_name(n.link[i]);
            FZ_CHECK(n.joint[i][0] != '\0' && n.link[i][0] != '\0');
            FZ_CHECK(n.continuous[i] == 0 || n.continuous[i] == 1);
        }
    } else {
        FZ_CHECK(d.msg[0] != '\0');
    }
    return 0;
}
