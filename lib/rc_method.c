/* SPDX-License-Identifier: MIT */
/* rc_method.c - the solver methods' and exits' names (rc_solve.h): the one
 * table a command line, a model file and a report read them from. */
#include <stddef.h>
#include <string.h>

#include "rc_solve.h"

static const struct {
    rc_method method;
    const char *name;
} method_names[] = {
    {RC_METHOD_LM, "lm"},
    {RC_METHOD_LTLM, "ltlm"},
    {RC_METHOD_LM_PAPER, "lm-paper"},
    {RC_METHOD_LTLM_PAPER, "ltlm-paper"},
    {RC_METHOD_LM_PAPER_DEG, "lm-paper-deg"},
    {RC_METHOD_LTLM_PAPER_DEG, "ltlm-paper-deg"},
};

const char *rc_method_name(rc_method method)
{
    for (size_t i = 0; i < sizeof method_names / sizeof method_names[0]; ++i)
        if (method_names[i].method == method)
            return method_names[i].name;
    return "unknown";
}

rc_status rc_method_from_name(rc_method *out, const char *name)
{
    RC_ASSERT(out != NULL);
    if (name == NULL)
        return RC_ERR_ARG;
    for (size_t i = 0; i < sizeof method_names / sizeof method_names[0]; ++i)
        if (strcmp(method_names[i].name, name) == 0) {
            *out = method_names[i].method;
            return RC_OK;
        }
    return RC_ERR_ARG;
}

const char *rc_exit_str(rc_exit e)
{
    switch (e) {
    case RC_EXIT_NONE: return "none";
    case RC_EXIT_SMALL_STEP: return "step below tolerance";
    case RC_EXIT_SMALL_COST: return "cost decrease below tolerance";
    case RC_EXIT_SMALL_GRAD: return "no significant step left";
    case RC_EXIT_MAX_ITER: return "iteration limit";
    case RC_EXIT_NO_DESCENT: return "no further descent (damping limit)";
    case RC_EXIT_NONFINITE: return "diverged to non-finite values";
    }
    return "unknown";
}
