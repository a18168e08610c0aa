/* cmd_bench.c - placeholder until issue 2 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_bench(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal bench: not implemented yet (issue 2)\n");
    return 2;
}
