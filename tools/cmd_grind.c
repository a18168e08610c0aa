/* cmd_grind.c - placeholder until issue 5 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_grind(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal grind: not implemented yet (issue 5)\n");
    return 2;
}
