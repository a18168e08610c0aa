/* cmd_poses.c - placeholder until issue 4 lands: says so and fails. */
#include <stdio.h>

#include "rcal_cmds.h"

int rcal_cmd_poses(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "rcal poses: not implemented yet (issue 4)\n");
    return 2;
}
