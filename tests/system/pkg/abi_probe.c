/* SPDX-License-Identifier: MIT */
/* abi_probe.c - compiled by the pkg_limits_* tests (tests/system/pkg/CMakeLists.txt)
 * against rc_version.h headers generated with other limits, to show that a
 * disagreement with the library is refused at compile or link time. Run when
 * it does link: prints the limits it was compiled with. */
#include <stdio.h>

#include "rc_model.h"

int main(void)
{
    static rc_model m;
    printf("abi_probe: core %s, RC_MAX_PARAMS %d, sizeof(rc_model) %u\n", rc_version(), RC_MAX_PARAMS,
           (unsigned)sizeof m);
    return 0;
}
