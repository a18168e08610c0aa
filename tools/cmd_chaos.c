/* cmd_chaos.c - placeholder until issue 3 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_chaos(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal chaos: not implemented yet (issue 3)\n");
    return 2;
}
