/* SPDX-License-Identifier: MIT */
/* rc_method.c - the solver methods' and exits' names (rc_problem.h): the one
 * table (RC_METHODS) a command line, a model file and a report read them
 * from. */
#include <stddef.h>
#include <string.h>

#include "rc_problem.h"

#define RC_METHOD_DESC_(id, name, paper, ltlm, deg, text) {RC_METHOD_##id, name, paper, ltlm, deg, text},
static const rc_method_desc method_table[] = {RC_METHODS(RC_METHOD_DESC_)};
#undef RC_METHOD_DESC_

const rc_method_desc *rc_method_describe(unsigned method)
{
    return method < sizeof method_table / sizeof method_table[0] ? &method_table[method] : NULL;
}

const char *rc_method_name(rc_method method)
{
    const rc_method_desc *d = rc_method_describe((unsigned)method);
    return d != NULL ? d->name : "unknown";
}

rc_status rc_method_from_name(rc_method *out, const char *name)
{
    RC_ASSERT(out != NULL);
    if (name == NULL)
        return RC_ERR_ARG;
    for (size_t i = 0; i < sizeof method_table / sizeof method_table[0]; ++i)
        if (strcmp(method_table[i].name, name) == 0) {
            *out = method_table[i].method;
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
