/* cmd_diagnose.c - placeholder until issue 6 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_diagnose(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal diagnose: not implemented yet (issue 6)\n");
    return 2;
}
