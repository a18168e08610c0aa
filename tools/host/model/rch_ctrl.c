/* SPDX-License-Identifier: MIT */
/* rch_ctrl.c - the controller's joint and flange conventions (rch_ctrl.h). */
#include "rch_ctrl.h"
#include "rch_json.h"

#include "rch_jw.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

void rch_ctrl_identity(rch_ctrl *c)
{
    memset(c, 0, sizeof *c);
    c->identity_joints = 1;
    for (int i = 0; i < RC_NJ; ++i)
        c->sign[i] = 1.0;
    c->flange_R[0] = c->flange_R[4] = c->flange_R[8] = 1.0;
    c->base_R[0] = c->base_R[4] = c->base_R[8] = 1.0;
}

void rch_ctrl_rpy_to_rot(double R[9], const double rpy[3])
{
    const double cr = cos(rpy[0]), sr = sin(rpy[0]), cp = cos(rpy[1]), sp = sin(rpy[1]), cy = cos(rpy[2]),
                 sy = sin(rpy[2]);
    const double T[9] = {cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
                         sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
                         -sp,     cp * sr,                cp * cr};
    memcpy(R, T, sizeof T);
}

void rch_ctrl_rot_to_rpy(double rpy[3], const double R[9])
{
    const double sp = -R[6];
    rpy[1] = atan2(sp, sqrt(R[7] * R[7] + R[8] * R[8]));
    if (sqrt(R[7] * R[7] + R[8] * R[8]) > 1e-12) {
        rpy[0] = atan2(R[7], R[8]);
        rpy[2] = atan2(R[3], R[0]);
    } else { /* pitch +-90 deg: roll folded into yaw */
        rpy[0] = 0.0;
        rpy[2] = atan2(-R[1], R[4]);
    }
}

void rch_ctrl_fk(double pos_mm[3], double rot[9], const rch_ctrl *c, const rc_model *m, const double q_rad[RC_NJ])
{
    double p[3], R[9], p2[3], R2[9];
    rc_fk(p, R, m, q_rad);
    /* T F */
    for (int i = 0; i < 3; ++i) {
        p2[i] = p[i];
        for (int j = 0; j < 3; ++j) {
            p2[i] += R[3 * i + j] * c->flange_mm[j];
            R2[3 * i + j] = R[3 * i] * c->flange_R[j] + R[3 * i + 1] * c->flange_R[3 + j] + R[3 * i + 2] * c->flange_R[6 + j];
        }
    }
    /* B (T F) */
    for (int i = 0; i < 3; ++i) {
        pos_mm[i] = c->base_mm[i];
        for (int j = 0; j < 3; ++j)
            pos_mm[i] += c->base_R[3 * i + j] * p2[j];
        if (rot)
            for (int j = 0; j < 3; ++j)
                rot[3 * i + j] = c->base_R[3 * i] * R2[j] + c->base_R[3 * i + 1] * R2[3 + j] + c->base_R[3 * i + 2] * R2[6 + j];
    }
}

/* n numbers of arr into v; -1 with d set */
static int nums(double *v, unsigned n, const rch_json *arr, const char *what, const char *file, rch_diag *d)
{
    if (arr->type != RCH_JARR || arr->n != n) {
        rch_diag_set(d, file, arr->line, arr->col, "\"controller\".\"%s\" must be an array of %u numbers", what, n);
        return -1;
    }
    for (unsigned k = 0; k < n; ++k) {
        const rch_json *x = arr->items[k];
        if (x->type != RCH_JNUM || !isfinite(x->num)) {
            rch_diag_set(d, file, x->line, x->col, "\"controller\".\"%s\"[%u] must be a finite number", what, k);
            return -1;
        }
        v[k] = x->num;
    }
    return 0;
}

int rch_ctrl_read(rch_ctrl *c, const rch_json *m, const char *file, rch_diag *d)
{
    rch_ctrl_identity(c);
    if (m == NULL)
        return 0;
    if (m->type != RCH_JOBJ) {
        rch_diag_set(d, file, m->line, m->col, "\"controller\" must be an object");
        return -1;
    }
    static const char *const keys[] = {"joint_sign", "joint_zero_deg", "q3_coupling", "flange_rpy_deg",
                                       "flange_xyz_mm", "base_rpy_deg", "base_xyz_mm", "note", NULL};
    for (size_t k = 0; k < m->n; ++k) {
        unsigned j = 0;
        while (keys[j] && strcmp(keys[j], m->keys[k]) != 0)
            ++j;
        if (!keys[j]) {
            rch_diag_set(d, file, m->items[k]->key_line, m->items[k]->key_col,
                         "unknown member \"%s\" in \"controller\" (known: joint_sign, joint_zero_deg, q3_coupling, "
                         "flange_rpy_deg, flange_xyz_mm, base_rpy_deg, base_xyz_mm, note)", m->keys[k]);
            return -1;
        }
    }
    c->present = 1;
    const rch_json *s = rch_json_get(m, "joint_sign"), *z = rch_json_get(m, "joint_zero_deg"),
                   *k = rch_json_get(m, "q3_coupling"), *rpy = rch_json_get(m, "flange_rpy_deg"),
                   *xyz = rch_json_get(m, "flange_xyz_mm");
    if (s) {
        if (nums(c->sign, RC_NJ, s, "joint_sign", file, d) != 0)
            return -1;
        for (unsigned i = 0; i < RC_NJ; ++i)
            if (c->sign[i] != 1.0 && c->sign[i] != -1.0) {
                rch_diag_set(d, file, s->items[i]->line, s->items[i]->col,
                             "\"controller\".\"joint_sign\"[%u] is %g: it must be 1 or -1", i, c->sign[i]);
                return -1;
            }
    }
    if (z) {
        if (nums(c->zero_rad, RC_NJ, z, "joint_zero_deg", file, d) != 0)
            return -1;
        for (unsigned i = 0; i < RC_NJ; ++i) {
            if (fabs(c->zero_rad[i]) > 360.0) {
                rch_diag_set(d, file, z->items[i]->line, z->items[i]->col,
                             "\"controller\".\"joint_zero_deg\"[%u] is %g deg: beyond one turn", i, c->zero_rad[i]);
                return -1;
            }
            c->zero_rad[i] *= DEG;
        }
    }
    if (k) {
        if (k->type != RCH_JNUM || !(fabs(k->num) <= 2.0)) {
            rch_diag_set(d, file, k->line, k->col, "\"controller\".\"q3_coupling\" must be a number within [-2, 2]");
            return -1;
        }
        c->q3_coupling = k->num;
    }
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (c->sign[i] != 1.0 || c->zero_rad[i] != 0.0)
            c->identity_joints = 0;
    if (c->q3_coupling != 0.0)
        c->identity_joints = 0;
    double r[3] = {0, 0, 0};
    if (rpy && nums(r, 3, rpy, "flange_rpy_deg", file, d) != 0)
        return -1;
    if (xyz && nums(c->flange_mm, 3, xyz, "flange_xyz_mm", file, d) != 0)
        return -1;
    memcpy(c->flange_rpy_deg, r, sizeof r);
    if (rpy || xyz) {
        const double rr[3] = {r[0] * DEG, r[1] * DEG, r[2] * DEG};
        rch_ctrl_rpy_to_rot(c->flange_R, rr);
        c->has_flange = 1;
    }
    const rch_json *brpy = rch_json_get(m, "base_rpy_deg"), *bxyz = rch_json_get(m, "base_xyz_mm");
    double b[3] = {0, 0, 0};
    if ((brpy && nums(b, 3, brpy, "base_rpy_deg", file, d) != 0) ||
        (bxyz && nums(c->base_mm, 3, bxyz, "base_xyz_mm", file, d) != 0))
        return -1;
    memcpy(c->base_rpy_deg, b, sizeof b);
    if (brpy || bxyz) {
        const double rr[3] = {b[0] * DEG, b[1] * DEG, b[2] * DEG};
        rch_ctrl_rpy_to_rot(c->base_R, rr);
        c->has_base = 1;
    }
    return 0;
}

void rch_ctrl_to_model(double q[RC_NJ], const rch_ctrl *c, const double ctrl[RC_NJ])
{
    double t[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        t[i] = c->sign[i] * (ctrl[i] - c->zero_rad[i]);
    t[2] += c->q3_coupling * t[1];
    memcpy(q, t, sizeof t);
}

void rch_ctrl_from_model(double ctrl[RC_NJ], const rch_ctrl *c, const double q[RC_NJ])
{
    double t[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i) {
        const double qi = i == 2 ? q[2] - c->q3_coupling * q[1] : q[i];
        t[i] = c->sign[i] * qi + c->zero_rad[i]; /* sign is +-1: its own inverse */
    }
    memcpy(ctrl, t, sizeof t);
}

void rch_ctrl_write(rch_jw *w, const rch_ctrl *c)
{
    if (!c->present)
        return;
    double z[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        z[i] = c->zero_rad[i] / DEG;
    rch_jw_obj(w, "controller");
    rch_jw_nums(w, "joint_sign", c->sign, RC_NJ);
    rch_jw_nums(w, "joint_zero_deg", z, RC_NJ);
    rch_jw_num(w, "q3_coupling", c->q3_coupling);
    if (c->has_flange) {
        rch_jw_nums(w, "flange_rpy_deg", c->flange_rpy_deg, 3);
        rch_jw_nums(w, "flange_xyz_mm", c->flange_mm, 3);
    }
    if (c->has_base) {
        rch_jw_nums(w, "base_rpy_deg", c->base_rpy_deg, 3);
        rch_jw_nums(w, "base_xyz_mm", c->base_mm, 3);
    }
    rch_jw_end(w);
}
