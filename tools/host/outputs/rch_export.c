/* SPDX-License-Identifier: MIT */
/* rch_export.c - URDF and DH-CSV exports of a model (see rch_export.h). */
#include "rch_export.h"

#include "rch_urdf_robot.h"
#include "rch_comp.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_file.h"
#include "rch_text.h"
#include "rch_json.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define RAD2DEG (180.0 / M_PI)

/* ---------------------------------------------------------------- XML out */

/* Write s as XML character data or an attribute value: & < > " ' as
 * references; characters XML 1.0 cannot carry at all (controls other than
 * tab, newline, return; invalid UTF-8) as '?'. In a comment (comment != 0)
 * nothing is escaped but "--" never appears and the text never ends in '-'. */
static void xml_put(FILE *f, const char *s, int comment)
{
    const unsigned char *p = (const unsigned char *)(s ? s : "");
    unsigned char prev = 0;
    if (!comment) {
        rch_xml_put(f, s, RCH_XML_WS_REFS); /* attribute values: raw white space would be normalised */
        return;
    }
    while (*p) {
        const unsigned c = *p;
        const size_t n = rch_utf8_len(p);
        if (n == 0 || (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7F) {
            fputc('?', f); /* a comment takes no character reference */
            prev = '?';
            ++p;
            continue;
        }
        if (c == '-' && (prev == '-' || p[1] == '\0'))
            fputc(' ', f);
        fwrite(p, 1, n, f);
        prev = (unsigned char)c;
        p += n;
    }
}

/* ---------------------------------------------------------------- origins */

void rch_urdf_origins(rch_urdf_origin origin[RC_NJ + 1], const rc_model *m)
{
    memset(origin, 0, (RC_NJ + 1) * sizeof origin[0]);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double a = m->x[RC_P_A(i)], d = m->x[RC_P_D(i)];
        const double al = m->x[RC_P_ALPHA(i)], th = m->x[RC_P_THETA(i)];
        rch_urdf_origin *o = &origin[i + 1];
        o->xyz_m[0] = a * cos(th) * 1e-3;
        o->xyz_m[1] = a * sin(th) * 1e-3;
        o->xyz_m[2] = d * 1e-3;
        o->rpy_rad[0] = al;
        o->rpy_rad[1] = 0.0;
        o->rpy_rad[2] = th;
    }
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        if (ef->kind != RC_EFF_AXIS_TILT || ef->joint >= RC_NJ)
            continue;
        /* Rz(theta) Rx(alpha) Ry(beta) as URDF's rpy: R = Rz(yaw) Ry(pitch) Rx(roll) */
        rch_urdf_origin *o = &origin[ef->joint + 1];
        const double th = o->rpy_rad[2], al = o->rpy_rad[0], b = m->x[ef->first];
        const double ct = cos(th), st = sin(th), ca = cos(al), sa = sin(al), cb = cos(b), sb = sin(b);
        const double A[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca};
        double R[9];
        for (int r = 0; r < 3; ++r) { /* A Ry(b) */
            R[3 * r] = A[3 * r] * cb - A[3 * r + 2] * sb;
            R[3 * r + 1] = A[3 * r + 1];
            R[3 * r + 2] = A[3 * r] * sb + A[3 * r + 2] * cb;
        }
        o->rpy_rad[2] = atan2(R[3], R[0]);
        o->rpy_rad[1] = atan2(-R[6], sqrt(R[7] * R[7] + R[8] * R[8]));
        o->rpy_rad[0] = atan2(R[7], R[8]);
    }
    for (unsigned e = 0; e < m->n_effects; ++e) {
        if (m->effects[e].kind != RC_EFF_TOOL_OFFSET)
            continue;
        /* xyz += Rz(theta6) Rx(alpha6) t */
        const double *t = &m->x[m->effects[e].first];
        const double ct = cos(origin[RC_NJ].rpy_rad[2]), st = sin(origin[RC_NJ].rpy_rad[2]);
        const double ca = cos(origin[RC_NJ].rpy_rad[0]), sa = sin(origin[RC_NJ].rpy_rad[0]);
        const double R[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca};
        for (unsigned r = 0; r < 3; ++r)
            origin[RC_NJ].xyz_m[r] += (R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2]) * 1e-3;
    }
}

/* ------------------------------------------------------- standard errors */

static int se_num(int *has, double *v, const rch_json *j, const char *file, rch_diag *d)
{
    if (!j || j->type == RCH_JNULL)
        return 0;
    if (j->type != RCH_JNUM || !(j->num >= 0.0)) {
        rch_diag_set(d, file, j->line, j->col, "a standard error must be a number >= 0 (or null)");
        return -1;
    }
    *has = 1;
    *v = j->num;
    return 0;
}

int rch_export_se_parse(rch_export_se *se, const char *text, size_t len, const char *file, rch_diag *d)
{
    static const char *const keys[4] = {"a_mm", "d_mm", "alpha_deg", "theta_deg"};
    memset(se, 0, sizeof *se);
    rch_json *root = rch_json_parse(text, len, file, d);
    if (!root)
        return -1;
    int rc = -1;
    const rch_json *blk = NULL, *cal = rch_json_get(root, "calibration");
    const rch_json *where[2] = {root, cal};
    for (int w = 0; w < 2 && !blk; ++w) {
        if (!where[w] || where[w]->type != RCH_JOBJ)
            continue;
        blk = rch_json_get(where[w], "std_error");
        if (!blk)
            blk = rch_json_get(where[w], "standard_error");
    }
    if (!blk) {
        /* a model file (rcal-model/2): its posterior's standard errors, by name
         * (a1..theta6 in mm and deg, ex, ey, ez in mm; null: none) */
        const rch_json *unc = rch_json_get(root, "uncertainty");
        const rch_json *ps = unc && unc->type == RCH_JOBJ ? rch_json_get(unc, "parameters") : NULL;
        static const char *const pre[4] = {"a", "d", "alpha", "theta"};
        for (size_t i = 0; ps && ps->type == RCH_JARR && i < ps->n; ++i) {
            const rch_json *pk = ps->items[i];
            const rch_json *nm = pk->type == RCH_JOBJ ? rch_json_get(pk, "name") : NULL;
            const rch_json *v = pk->type == RCH_JOBJ ? rch_json_get(pk, "std_error") : NULL;
            if (!nm || nm->type != RCH_JSTR || !v || v->type != RCH_JNUM)
                continue;
            for (unsigned k = 0; k < 4; ++k)
                for (unsigned j = 0; j < RC_NJ; ++j) {
                    char want[16];
                    snprintf(want, sizeof want, "%s%u", pre[k], j + 1);
                    if (strcmp(nm->str, want) == 0 && se_num(&se->has_dh[j][k], &se->dh[j][k], v, file, d) != 0)
                        goto done;
                }
            for (unsigned k = 0; k < 3; ++k) {
                const char want[3] = {'e', (char)('x' + k), '\0'};
                if (strcmp(nm->str, want) == 0 && se_num(&se->has_enc[k], &se->enc_mm[k], v, file, d) != 0)
                    goto done;
            }
            se->has = 1;
        }
        rc = 0;
        goto done;
    }
    const rch_json *dh = blk->type == RCH_JOBJ ? rch_json_get(blk, "dh") : NULL;
    const rch_json *enc = blk->type == RCH_JOBJ ? rch_json_get(blk, "encoder_mm") : NULL;
    if (blk->type != RCH_JOBJ || (dh && (dh->type != RCH_JARR || dh->n != RC_NJ)) ||
        (enc && (enc->type != RCH_JARR || enc->n != 3))) {
        rch_diag_set(d, file, blk->line, blk->col,
                     "the standard-error block must be {\"dh\": [6 rows], \"encoder_mm\": [x, y, z]}");
        goto done;
    }
    se->has = 1;
    for (unsigned i = 0; dh && i < RC_NJ; ++i) {
        const rch_json *row = dh->items[i];
        if (row->type == RCH_JNULL)
            continue;
        if (row->type != RCH_JOBJ) {
            rch_diag_set(d, file, row->line, row->col, "a standard-error dh row must be an object");
            goto done;
        }
        for (unsigned k = 0; k < 4; ++k)
            if (se_num(&se->has_dh[i][k], &se->dh[i][k], rch_json_get(row, keys[k]), file, d) != 0)
                goto done;
    }
    for (unsigned k = 0; enc && k < 3; ++k)
        if (se_num(&se->has_enc[k], &se->enc_mm[k], enc->items[k], file, d) != 0)
            goto done;
    rc = 0;
done:
    rch_json_free(root);
    return rc;
}

/* ------------------------------------------------------------------- URDF */

static int joint_side(const rc_effect *e)
{
    return e->kind == RC_EFF_JOINT_COMPLIANCE || e->kind == RC_EFF_JOINT_PERIODIC;
}

static int has_tool(const rc_model *m)
{
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == RC_EFF_TOOL_OFFSET)
            return 1;
    return 0;
}

static void xml_attr(FILE *f, const char *key, const char *v)
{
    fprintf(f, " %s=\"", key);
    xml_put(f, v, 0);
    fputc('"', f);
}

/* v with the fewest significant digits that read back as exactly v
 * (0.174452183, not 0.17445218300000001): a reader gets the same double. */
static const char *num(char buf[32], double v)
{
    /* at least the integer digits, so that 290 is not written 2.9e+02 */
    const double a = fabs(v);
    int p = a >= 1.0 && a < 1e17 ? (int)floor(log10(a)) + 1 : 1;
    for (p = p < 17 ? p : 17; p <= 17; ++p) {
        snprintf(buf, 32, "%.*g", p, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    return buf;
}

static void write_origin(FILE *f, const rch_urdf_origin *o)
{
    char b[6][32];
    fprintf(f, "    <origin xyz=\"%s %s %s\" rpy=\"%s %s %s\"/>\n", num(b[0], o->xyz_m[0]), num(b[1], o->xyz_m[1]),
            num(b[2], o->xyz_m[2]), num(b[3], o->rpy_rad[0]), num(b[4], o->rpy_rad[1]), num(b[5], o->rpy_rad[2]));
}

static void write_link(FILE *f, const char *name)
{
    fputs("  <link", f);
    xml_attr(f, "name", name);
    fputs("/>\n", f);
}

static double wrap_deg(double v)
{
    v = fmod(v, 360.0);
    if (v > 180.0)
        v -= 360.0;
    else if (v <= -180.0)
        v += 360.0;
    return v;
}

/* Comment on the origin that carries DH row i (0-based) of the model. */
static void dh_comment(FILE *f, const rch_robot *r, unsigned i)
{
    const double *x = r->model.x, *nx = r->nominal.x;
    fprintf(f,
            "    <!-- DH row %u: a %.9g mm, d %.9g mm, alpha %.9g deg, theta %.9g deg (joint %u's zero offset, "
            "folded into yaw; calibrated - nominal = %.9g deg) -->\n",
            i + 1, x[RC_P_A(i)], x[RC_P_D(i)], x[RC_P_ALPHA(i)] * RAD2DEG, x[RC_P_THETA(i)] * RAD2DEG, i + 1,
            wrap_deg((x[RC_P_THETA(i)] - nx[RC_P_THETA(i)]) * RAD2DEG));
}

static void write_urdf(FILE *f, const rch_export_cfg *cfg, const rch_robot *r, const rch_urdf_names *n,
                       rch_export_result *res)
{
    rch_urdf_origin o[RC_NJ + 1];
    /* the robot compensation uses: its flange, never the cable attachment
     * the calibration measured (named in a comment below) */
    static rc_model pm;
    rch_comp_point_model(&pm, &r->model, NULL);
    rch_urdf_origins(o, &pm);
    fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Generated by rcal export from ", f);
    xml_put(f, cfg->source ? cfg->source : "a model", 1);
    fputs(" (model \"", f);
    xml_put(f, r->name, 1);
    fputs("\"). Kinematics only: no visual, collision or inertial elements.\n"
          "     Layout (docs/export.md): joint i rotates about its z axis by rcal's joint reading q_i; the\n"
          "     origin of joint i+1 (and of the fixed flange joint after joint 6) is DH row i,\n"
          "     Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) = xyz (a cos theta, a sin theta, d), rpy (alpha, 0, theta).\n"
          "     The joint-zero offsets theta_i are folded into those yaw angles, not written as <calibration>:\n"
          "     URDF's calibration element marks reference-switch edges that kinematics consumers do not apply.\n"
          "     Lengths in m, angles in rad. Effort and velocity limits are unknown to rcal (written as 0). -->\n",
          f);
    for (unsigned e = 0; e < r->model.n_effects; ++e) {
        const rc_effect *ef = &r->model.effects[e];
        if (ef->kind == RC_EFF_TOOL_OFFSET || ef->kind == RC_EFF_AXIS_TILT) /* carried by the origins */
            continue;
        fprintf(f, "<!-- Model effect %s%s not carried by this URDF%s -->\n", rc_effect_name((rc_effect_kind)ef->kind),
                joint_side(ef) ? " (joint-side)" : " (cable-length side)",
                joint_side(ef) ? ": forward kinematics from this file differ from rcal's" : "");
        ++res->n_effects_left;
    }
    if (n->n_dropped)
        fprintf(f, "<!-- %u joint(s) of the nominal URDF outside the arm's chain are not written. -->\n",
                n->n_dropped);
    fputs("<robot", f);
    xml_attr(f, "name", n->robot);
    fputs(">\n", f);
    write_link(f, n->base_link);
    for (unsigned i = 0; i <= RC_NJ; ++i) {
        const int flange = i == RC_NJ;
        fputs("  <joint", f);
        xml_attr(f, "name", flange ? n->flange_joint : n->joint[i]);
        xml_attr(f, "type", flange ? "fixed" : n->continuous[i] ? "continuous" : "revolute");
        fputs(">\n", f);
        if (i == 0)
            fputs("    <!-- the base frame is rcal's DH frame 0 -->\n", f);
        else
            dh_comment(f, r, i - 1);
        if (flange && has_tool(&r->model)) {
            for (unsigned e = 0; e < r->model.n_effects; ++e)
                if (r->model.effects[e].kind == RC_EFF_TOOL_OFFSET) {
                    const double *t = &r->model.x[r->model.effects[e].first];
                    fprintf(f, "    <!-- the cable was attached at (%.6g, %.6g, %.6g) mm in this flange frame: "
                               "not a link (the flange is the robot's) -->\n", t[0], t[1], t[2]);
                    break;
                }
        }
        write_origin(f, &o[i]);
        fputs("    <parent", f);
        xml_attr(f, "link", i == 0 ? n->base_link : n->link[i - 1]);
        fputs("/>\n    <child", f);
        xml_attr(f, "link", flange ? n->flange_link : n->link[i]);
        fputs("/>\n", f);
        if (!flange) {
            fputs("    <axis xyz=\"0 0 1\"/>\n", f);
            if (n->continuous[i])
                fputs("    <limit effort=\"0\" velocity=\"0\"/>\n", f);
            else {
                char lo[32], hi[32];
                fprintf(f, "    <limit lower=\"%s\" upper=\"%s\" effort=\"0\" velocity=\"0\"/>\n",
                        num(lo, r->model.q_min_rad[i]), num(hi, r->model.q_max_rad[i]));
            }
        }
        fputs("  </joint>\n", f);
        write_link(f, flange ? n->flange_link : n->link[i]);
        ++res->n_joints;
    }
    fputs("</robot>\n", f);
}

/* -------------------------------------------------------------------- CSV */

static void csv_num(FILE *f, int has, double v)
{
    char b[32];
    fputc(',', f);
    if (has)
        fputs(num(b, v), f);
}

static void write_csv(FILE *f, const rch_export_cfg *cfg, const rch_robot *r, rch_export_result *res)
{
    static const char *const names[4] = {"a", "d", "alpha", "theta"};
    const rch_export_se *se = cfg->se && cfg->se->has ? cfg->se : NULL;
    fputs("joint,name,unit,nominal,calibrated,correction,standard_error\n", f);
    for (unsigned i = 0; i < RC_NJ; ++i)
        for (unsigned k = 0; k < 4; ++k) {
            const int ang = k >= 2;
            const double s = ang ? RAD2DEG : 1.0;
            const double nom = r->nominal.x[4 * i + k] * s, cal = r->model.x[4 * i + k] * s;
            const double corr = ang ? wrap_deg(cal - nom) : cal - nom;
            fprintf(f, "%u,%s,%s", i + 1, names[k], ang ? "deg" : "mm");
            csv_num(f, 1, nom);
            csv_num(f, 1, cal);
            csv_num(f, 1, corr);
            csv_num(f, se && se->has_dh[i][k], se ? se->dh[i][k] : 0.0);
            fputc('\n', f);
            ++res->n_rows;
        }
    for (unsigned k = 0; r->has_encoder && k < 3; ++k) {
        fprintf(f, "encoder,%c,mm,", "xyz"[k]);
        csv_num(f, 1, r->model.x[RC_P_ENC + k]);
        fputc(',', f);
        csv_num(f, se && se->has_enc[k], se ? se->enc_mm[k] : 0.0);
        fputc('\n', f);
        ++res->n_rows;
    }
    for (unsigned e = 0; e < r->model.n_effects; ++e) {
        const rc_effect *ef = &r->model.effects[e];
        for (unsigned k = ef->first; k < (unsigned)ef->first + ef->count; ++k) {
            char name[64];
            const int unit = rc_param_unit(&r->model, k);
            const double s = unit == 1 ? RAD2DEG : 1.0;
            const char *u = unit == 0 ? "mm" : unit == 1 ? "deg" : ef->kind == RC_EFF_JOINT_COMPLIANCE ? "rad/m" : "1";
            fprintf(f, "effect,%s,%s", rc_param_name(name, sizeof name, &r->model, k), u);
            csv_num(f, 1, 0.0);
            csv_num(f, 1, r->model.x[k] * s);
            csv_num(f, 1, r->model.x[k] * s);
            fputs(",\n", f);
            ++res->n_rows;
        }
    }
    res->has_se = se != NULL;
}

/* -------------------------------------------------------------- entries */

int rch_export_write(rch_export_result *res, FILE *f, const rch_export_cfg *cfg, const rch_robot *r, rch_diag *d)
{
    memset(res, 0, sizeof *res);
    if (cfg->format == RCH_EXPORT_URDF) {
        for (unsigned e = 0; e < r->model.n_effects; ++e)
            if (joint_side(&r->model.effects[e]) && !cfg->drop_joint_effects) {
                rch_diag_set(d, cfg->source ? cfg->source : "", 0, 0,
                             "the model has a %s effect on joint %u, which a URDF cannot express: refused "
                             "(--drop-joint-effects writes the geometry alone)",
                             rc_effect_name((rc_effect_kind)r->model.effects[e].kind), r->model.effects[e].joint + 1u);
                return -1;
            }
        rch_urdf_names gen;
        if (!cfg->names)
            rch_urdf_names_default(&gen, r->name);
        write_urdf(f, cfg, r, cfg->names ? cfg->names : &gen, res);
    } else {
        write_csv(f, cfg, r, res);
    }
    const int err = errno;
    errno = 0;
    if (fflush(f) != 0 || ferror(f)) {
        rch_diag_set(d, "", 0, 0, "write error: %s", strerror(errno ? errno : err ? err : EIO));
        return -1;
    }
    return 0;
}

int rch_export_file(rch_export_result *res, FILE *f, rch_export_format format, const char *model_path,
                    const char *nominal_urdf, int drop_joint_effects, rch_diag *d)
{
    char *text = NULL;
    size_t len = 0;
    rch_robot *r = malloc(sizeof *r);
    rch_urdf_names *names = malloc(sizeof *names);
    rch_export_se se;
    int rc = -1;
    memset(res, 0, sizeof *res);
    if (!r || !names) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    if (rch_read_file(&text, &len, model_path, (size_t)1 << 20, d) != 0 ||
        rch_robot_parse(r, text, len, model_path, d) != 0 || rch_export_se_parse(&se, text, len, model_path, d) != 0)
        goto done;
    free(text);
    text = NULL;
    if (nominal_urdf && (rch_read_file(&text, &len, nominal_urdf, (size_t)16 << 20, d) != 0 ||
                         rch_urdf_names_parse(names, text, len, nominal_urdf, d) != 0))
        goto done;
    const rch_export_cfg cfg = {format, nominal_urdf ? names : NULL, &se, model_path, drop_joint_effects};
    if (nominal_urdf && format == RCH_EXPORT_URDF) {
        /* the overlay, when the URDF is the model's nominal robot */
        rch_export_result tmp;
        FILE *null = fopen("/dev/null", "w");
        if (!null || rch_export_write(&tmp, null, &cfg, r, d) != 0) { /* the effects' refusal */
            if (null)
                fclose(null);
            goto done;
        }
        fclose(null);
        char *buf = NULL;
        size_t blen = 0;
        FILE *mem = open_memstream(&buf, &blen);
        rch_diag dd;
        int moved = 0;
        const int o = mem ? rch_urdf_overlay_write(mem, &moved, text, len, nominal_urdf, &r->nominal, &r->model, &dd)
                          : -1;
        if (mem)
            fclose(mem);
        if (o == 0) {
            *res = tmp;
            res->overlay = 1;
            res->flange_moved = moved;
            rc = fwrite(buf, 1, blen, f) == blen && fflush(f) == 0 ? 0 : -1;
            if (rc != 0)
                rch_diag_set(d, "", 0, 0, "write error: %s", strerror(errno));
            free(buf);
            goto done;
        }
        free(buf);
        if (o != -2) {
            *d = dd;
            goto done;
        }
        rc = rch_export_write(res, f, &cfg, r, d);
        snprintf(res->overlay_why, sizeof res->overlay_why, "%.250s", dd.msg);
        goto done;
    }
    rc = rch_export_write(res, f, &cfg, r, d);
done:
    free(text);
    free(names);
    free(r);
    return rc;
}
