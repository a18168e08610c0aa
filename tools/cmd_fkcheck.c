/* cmd_fkcheck.c - placeholder until issue 2 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_fkcheck(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal fkcheck: not implemented yet (issue 2)\n");
    return 2;
}
