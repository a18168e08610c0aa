/* cmd_compensate.c - placeholder until issue 5 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_compensate(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal compensate: not implemented yet (issue 5)\n");
    return 2;
}
