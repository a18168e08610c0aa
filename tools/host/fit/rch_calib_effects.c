/* SPDX-License-Identifier: MIT */
/* rch_calib_effects.c - --method, --effects and --fix read into a model, and
 * the nuisance stripped (see rch_calib_effects.h). */
#include "rch_calib_effects.h"

#include <stdio.h>
#include <string.h>

#include "rch_comp.h"
#include "rch_opt.h"

int rch_method_parse(rc_method *out, const char *name)
{
    return rc_method_from_name(out, name) == RC_OK ? 0 : -1;
}

/* The effects --effects may name, from the one table (rc_effect_desc.user),
 * for messages: "length_offset, ..., joint_periodic:J". */
static void effect_list(char *buf, size_t len)
{
    size_t pos = 0;
    buf[0] = '\0';
    for (unsigned k = 1; k <= RC_EFF_LAST && pos < len; ++k) {
        const rc_effect_desc *ds = rc_effect_describe(k);
        if (!ds || !ds->user)
            continue;
        pos += (size_t)snprintf(buf + pos, len - pos, "%s%s%s", pos ? ", " : "", ds->name,
                                ds->arg == RC_EFF_ARG_JOINT ? ":J" : ds->arg == RC_EFF_ARG_PERIOD ? ":P" : "");
    }
}

int rch_calib_effects(rc_model *m, const char *list, rch_diag *d)
{
    char buf[512], names[512];
    if (strlen(list) >= sizeof buf) {
        rch_diag_set(d, "", 0, 0, "--effects: list longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    memcpy(buf, list, strlen(list) + 1);
    for (char *tok = buf, *next; tok && *tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        char *colon = strchr(tok, ':');
        if (colon)
            *colon++ = '\0';
        const int kind = rc_effect_by_name(tok);
        const rc_effect_desc *ds = kind > 0 ? rc_effect_describe((unsigned)kind) : NULL;
        if (!ds || !ds->user) {
            effect_list(names, sizeof names);
            rch_diag_set(d, "", 0, 0, "--effects: unknown effect '%s' (%s)", tok, names);
            return -1;
        }
        if (ds->arg == RC_EFF_ARG_PERIOD) { /* the period's start value, mm */
            double per = 0.0;
            if (!colon || rch_parse_double(colon, &per) != 0 || !(per >= 1.0 && per <= 1000.0)) {
                rch_diag_set(d, "", 0, 0, "--effects: %s needs its period in mm (1..1000), e.g. %s:137", tok, tok);
                return -1;
            }
            rc_status st = rc_model_add_effect(m, (rc_effect_kind)kind, 0, 0);
            if (st != RC_OK) {
                rch_diag_set(d, "", 0, 0, "--effects: cannot add %s: %s", tok, rc_strerror(st));
                return -1;
            }
            m->x[m->effects[m->n_effects - 1].first + 2] = per;
            continue;
        }
        unsigned long j = 0;
        const int needs_joint = ds->arg == RC_EFF_ARG_JOINT;
        if (needs_joint && (!colon || rch_parse_ulong(colon, &j) != 0 || j < 1 || j > 6)) {
            rch_diag_set(d, "", 0, 0, "--effects: %s needs the joint, e.g. %s:2", tok, tok);
            return -1;
        }
        rc_status st = rc_model_add_effect(m, (rc_effect_kind)kind, needs_joint ? (unsigned)j - 1u : 0u, 0);
        if (st != RC_OK) {
            rch_diag_set(d, "", 0, 0, "--effects: cannot add %s%s%s: %s", tok, colon ? ":" : "", colon ? colon : "",
                         rc_strerror(st));
            return -1;
        }
    }
    return 0;
}

void rch_model_strip_nuisance(rc_model *out, const rc_model *m)
{
    rch_model_rebuild(out, m, 1, 0, NULL);
}

int rch_calib_fix(uint8_t *fixed, const rc_model *m, const char *list, rch_diag *d)
{
    const char *p = list;
    while (p && *p) {
        const char *end = strchr(p, ',');
        const size_t len = end ? (size_t)(end - p) : strlen(p);
        unsigned k;
        char name[64];
        for (k = 0; k < m->n_params; ++k) {
            rc_param_name(name, sizeof name, m, k);
            if (len > 0 && strlen(name) == len && strncmp(name, p, len) == 0)
                break;
        }
        if (len > 0 && k == m->n_params) {
            rch_diag_set(d, "", 0, 0, "--fix: unknown parameter '%.*s'", (int)(len < 64 ? len : 64), p);
            return -1;
        }
        if (len > 0)
            fixed[k] = 1;
        p = end ? end + 1 : NULL;
    }
    return 0;
}
