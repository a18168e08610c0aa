/* SPDX-License-Identifier: MIT */
/* rc_version.c - the version of the core and the object that proves, at link
 * time, which compile-time limits it was built with (rc_version.h). Constant
 * data only: no state. */
#include "rc_config.h"

/* Defined here only: a program compiled with other limits references another
 * name and does not link. */
const unsigned char RC_ABI_SYMBOL = 1;

const char *rc_version(void)
{
    return RC_VERSION_STRING;
}
