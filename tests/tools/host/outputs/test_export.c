/* SPDX-License-Identifier: MIT */
/* test_export.c - rch_export in-process: the URDF origins against rc_fk (with
 * this file's own matrix code), the DH CSV read back, escaping of hostile
 * names, the nominal-URDF reader on good and bad documents, standard errors,
 * refusals. The same URDF read by an independent XML parser is in
 * test_export_cli.py. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_export.h"

#define PI_ 3.14159265358979323846

static const char *truth_path(void) { return RCAL_SOURCE_DIR "/data/sim_irb120_truth.json"; }

static void load(rch_robot *r, const char *path)
{
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(r, path, &d) != 0)
        fail_msg("%s", rch_diag_str(&d, msg, sizeof msg));
}

static void parse_model(rch_robot *r, const char *text)
{
    rch_diag d;
    char msg[1024];
    if (rch_robot_parse(r, text, strlen(text), "test", &d) != 0)
        fail_msg("%s", rch_diag_str(&d, msg, sizeof msg));
}

/* Run rch_export_write into a heap string (through a temporary file). */
static char *export_str(const rch_export_cfg *cfg, const rch_robot *r, rch_export_result *res, int *rc)
{
    FILE *f = tmpfile();
    assert_non_null(f);
    rch_diag d;
    *rc = rch_export_write(res, f, cfg, r, &d);
    const long len = ftell(f);
    assert_true(len >= 0);
    char *buf = malloc((size_t)len + 1);
    assert_non_null(buf);
    rewind(f);
    assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
    buf[len] = '\0';
    assert_int_equal(fclose(f), 0);
    return buf;
}

/* ---- the URDF origins, composed with this file's own 4x4 code ---------- */

typedef struct {
    double m[4][4];
} T4;

static T4 t4_mul(const T4 *a, const T4 *b)
{
    T4 c;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            c.m[i][j] = 0.0;
            for (int k = 0; k < 4; ++k)
                c.m[i][j] += a->m[i][k] * b->m[k][j];
        }
    return c;
}

static T4 t4_rot(int axis, double a)
{
    T4 t;
    memset(&t, 0, sizeof t);
    const double c = cos(a), s = sin(a);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    for (int k = 0; k < 4; ++k)
        t.m[k][k] = 1.0;
    t.m[i][i] = c;
    t.m[i][j] = -s;
    t.m[j][i] = s;
    t.m[j][j] = c;
    return t;
}

/* URDF origin: Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll). */
static T4 t4_origin(const rch_urdf_origin *o)
{
    T4 rz = t4_rot(2, o->rpy_rad[2]), ry = t4_rot(1, o->rpy_rad[1]), rx = t4_rot(0, o->rpy_rad[0]);
    T4 t = t4_mul(&rz, &ry);
    t = t4_mul(&t, &rx);
    for (int r = 0; r < 3; ++r)
        t.m[r][3] = o->xyz_m[r] * 1e3;
    return t;
}

/* Largest distance between the flange composed from origins o (7) and
 * rc_fk of model m, at n random joint vectors inside m's limits. */
static double origins_vs_fk(const rch_urdf_origin o[RC_NJ + 1], const rc_model *m, unsigned n, uint64_t seed)
{
    rc_rng g;
    rc_rng_seed(&g, seed);
    double worst = 0.0;
    for (unsigned k = 0; k < n; ++k) {
        double q[RC_NJ], p[3];
        for (unsigned i = 0; i < RC_NJ; ++i)
            q[i] = m->q_min_rad[i] + (m->q_max_rad[i] - m->q_min_rad[i]) * rc_rng_u01(&g);
        rc_fk(p, NULL, m, q);
        T4 t = t4_origin(&o[0]);
        for (unsigned i = 0; i < RC_NJ; ++i) {
            T4 rq = t4_rot(2, q[i]), oi = t4_origin(&o[i + 1]);
            t = t4_mul(&t, &rq);
            t = t4_mul(&t, &oi);
        }
        const double dx = t.m[0][3] - p[0], dy = t.m[1][3] - p[1], dz = t.m[2][3] - p[2];
        const double dist = sqrt(dx * dx + dy * dy + dz * dz);
        if (dist > worst)
            worst = dist;
    }
    return worst;
}

static double model_vs_own_origins(const rc_model *m, unsigned n, uint64_t seed)
{
    rch_urdf_origin o[RC_NJ + 1];
    rch_urdf_origins(o, m);
    return origins_vs_fk(o, m, n, seed);
}

static void test_origins_reproduce_fk(void **state)
{
    (void)state;
    static rch_robot r;
    load(&r, RCAL_SOURCE_DIR "/data/irb120.json");
    assert_true(model_vs_own_origins(&r.model, 200, 1) < 1e-9);
    load(&r, truth_path());
    assert_true(model_vs_own_origins(&r.model, 200, 2) < 1e-9);
    /* a tool offset lands in the flange origin */
    assert_int_equal(rc_model_add_effect(&r.model, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    r.model.x[r.model.effects[0].first] = 15.0;
    r.model.x[r.model.effects[0].first + 1] = -40.0;
    r.model.x[r.model.effects[0].first + 2] = 25.0;
    assert_true(model_vs_own_origins(&r.model, 200, 3) < 1e-9);
    /* the comparison can fail: origins of a model whose d3 and theta5 then change */
    rch_urdf_origin o[RC_NJ + 1];
    rch_urdf_origins(o, &r.model);
    r.model.x[RC_P_D(2)] += 1e-3;
    assert_true(origins_vs_fk(o, &r.model, 20, 4) > 0.5e-3);
    r.model.x[RC_P_D(2)] -= 1e-3;
    r.model.x[RC_P_THETA(4)] += 1e-6;
    assert_true(origins_vs_fk(o, &r.model, 20, 4) > 1e-6);
}

/* ---- DH CSV ------------------------------------------------------------ */

static const char *const se_model =
    "{\"format\": \"rcal-model/1\", \"name\": \"se\",\n"
    " \"dh\": [{\"a_mm\": 0.5, \"d_mm\": 290, \"alpha_deg\": -90, \"theta_deg\": 179},\n"
    "        {\"a_mm\": 270, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": -90},\n"
    "        {\"a_mm\": 70, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0},\n"
    "        {\"a_mm\": 0, \"d_mm\": 302, \"alpha_deg\": 90, \"theta_deg\": 0},\n"
    "        {\"a_mm\": 0, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0},\n"
    "        {\"a_mm\": 0, \"d_mm\": 72, \"alpha_deg\": 0, \"theta_deg\": 0}],\n"
    " \"encoder_mm\": [250, -460, 10],\n"
    " \"effects\": [{\"kind\": \"joint_periodic\", \"joint\": 2, \"params\": [0.001, 0, 0, 0]},\n"
    "             {\"kind\": \"length_scale\", \"params\": [2e-4]}],\n"
    " \"nominal\": {\"dh\": [{\"a_mm\": 0, \"d_mm\": 290, \"alpha_deg\": -90, \"theta_deg\": -179},\n"
    "        {\"a_mm\": 270, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": -90},\n"
    "        {\"a_mm\": 70, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0},\n"
    "        {\"a_mm\": 0, \"d_mm\": 302, \"alpha_deg\": 90, \"theta_deg\": 0},\n"
    "        {\"a_mm\": 0, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0},\n"
    "        {\"a_mm\": 0, \"d_mm\": 72, \"alpha_deg\": 0, \"theta_deg\": 0}]},\n"
    " \"calibration\": {\"std_error\": {\"dh\": [{\"a_mm\": 0.25, \"theta_deg\": 0.01}, null, null, null, null,\n"
    "                   {\"d_mm\": 0.125}], \"encoder_mm\": [0.5, null, 0.75]}}}\n";

/* Split one CSV line (no quoting needed: rcal's fields have no commas). */
static size_t split(char *line, char *field[16])
{
    size_t n = 0;
    field[n++] = line;
    for (char *p = line; *p && n < 16; ++p)
        if (*p == ',') {
            *p = '\0';
            field[n++] = p + 1;
        }
    return n;
}

static void test_csv_reads_back(void **state)
{
    (void)state;
    static rch_robot r;
    rch_export_se se;
    rch_diag d;
    parse_model(&r, se_model);
    assert_int_equal(rch_export_se_parse(&se, se_model, strlen(se_model), "test", &d), 0);
    assert_int_equal(se.has, 1);
    const rch_export_cfg cfg = {RCH_EXPORT_DH_CSV, NULL, &se, "test", 0};
    rch_export_result res;
    int rc;
    char *csv = export_str(&cfg, &r, &res, &rc);
    assert_int_equal(rc, 0);
    assert_int_equal(res.has_se, 1);
    assert_int_equal(res.n_rows, 24 + 3 + 5);
    char *save = NULL, *line = strtok_r(csv, "\n", &save);
    assert_string_equal(line, "joint,name,unit,nominal,calibrated,correction,standard_error");
    static const char *const names[4] = {"a", "d", "alpha", "theta"};
    unsigned rows = 0;
    while ((line = strtok_r(NULL, "\n", &save)) != NULL) {
        char *f[16];
        assert_int_equal(split(line, f), 7);
        if (rows < 24) {
            const unsigned i = rows / 4, k = rows % 4;
            const double s = k >= 2 ? 180.0 / PI_ : 1.0;
            assert_int_equal(atoi(f[0]), (int)i + 1);
            assert_string_equal(f[1], names[k]);
            assert_string_equal(f[2], k >= 2 ? "deg" : "mm");
            const double nom = strtod(f[3], NULL), cal = strtod(f[4], NULL), corr = strtod(f[5], NULL);
            assert_true(fabs(nom - r.nominal.x[4 * i + k] * s) <= 1e-12 * fmax(1.0, fabs(nom)));
            assert_true(fabs(cal - r.model.x[4 * i + k] * s) <= 1e-12 * fmax(1.0, fabs(cal)));
            if (i == 0 && k == 3)
                assert_true(fabs(corr - (-2.0)) < 1e-9); /* 179 - (-179) wraps to -2 */
            else
                assert_true(fabs(corr - (cal - nom)) <= 1e-12 * fmax(1.0, fabs(cal)));
            if (i == 0 && k == 0)
                assert_string_equal(f[6], "0.25");
            else if (i == 0 && k == 3)
                assert_string_equal(f[6], "0.01");
            else if (i == 5 && k == 1)
                assert_string_equal(f[6], "0.125");
            else
                assert_string_equal(f[6], "");
        } else if (rows < 27) {
            const unsigned k = rows - 24;
            assert_string_equal(f[0], "encoder");
            assert_int_equal(f[1][0], "xyz"[k]);
            assert_string_equal(f[3], "");
            assert_true(fabs(strtod(f[4], NULL) - r.model.x[RC_P_ENC + k]) < 1e-12);
            assert_string_equal(f[5], "");
            assert_string_equal(f[6], k == 0 ? "0.5" : k == 1 ? "" : "0.75");
        } else {
            assert_string_equal(f[0], "effect");
            if (rows == 27) {
                assert_string_equal(f[1], "joint_periodic.j2.s1");
                assert_string_equal(f[2], "deg");
                assert_true(fabs(strtod(f[4], NULL) - 0.001 * 180.0 / PI_) < 1e-15);
            }
            if (rows == 31) {
                assert_string_equal(f[1], "length_scale");
                assert_string_equal(f[2], "1");
                assert_true(fabs(strtod(f[5], NULL) - 2e-4) < 1e-18);
            }
        }
        ++rows;
    }
    assert_int_equal(rows, res.n_rows);
    free(csv);
}

static void test_se_block(void **state)
{
    (void)state;
    rch_export_se se;
    rch_diag d;
    const char *none = "{\"dh\": []}";
    assert_int_equal(rch_export_se_parse(&se, none, strlen(none), "t", &d), 0);
    assert_int_equal(se.has, 0);
    const char *top = "{\"std_error\": {\"encoder_mm\": [1, 2, 3]}}";
    assert_int_equal(rch_export_se_parse(&se, top, strlen(top), "t", &d), 0);
    assert_int_equal(se.has, 1);
    assert_int_equal(se.has_enc[2], 1);
    assert_true(se.enc_mm[2] == 3.0);
    const char *const bad[] = {"{\"std_error\": 3}", "{\"std_error\": {\"dh\": [1, 2]}}",
                               "{\"standard_error\": {\"encoder_mm\": [1, -2, 3]}}",
                               "{\"calibration\": {\"std_error\": {\"dh\": [1, 2, 3, 4, 5, 6]}}}"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i)
        assert_int_equal(rch_export_se_parse(&se, bad[i], strlen(bad[i]), "t", &d), -1);
}

/* ---- escaping ---------------------------------------------------------- */

/* Decode the attribute value that starts at s (after the opening quote). */
static void xml_decode_attr(char *out, size_t cap, const char *s)
{
    size_t k = 0;
    while (*s && *s != '"' && k + 1 < cap) {
        assert_true(*s != '<' && *s != '>' && *s != '\'');
        if (*s != '&') {
            out[k++] = *s++;
            continue;
        }
        static const char *const ent[6] = {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;", "&#39;"};
        int done = 0;
        for (int e = 0; e < 6 && !done; ++e)
            if (strncmp(s, ent[e], strlen(ent[e])) == 0) {
                out[k++] = "&<>\"''"[e];
                s += strlen(ent[e]);
                done = 1;
            }
        if (!done && strncmp(s, "&#xFFFD;", 8) == 0 && k + 3 < cap) { /* U+FFFD, as UTF-8 */
            memcpy(out + k, "\xEF\xBF\xBD", 3);
            k += 3;
            s += 8;
            done = 1;
        }
        assert_true(done);
    }
    out[k] = '\0';
}

static void test_hostile_names_escaped(void **state)
{
    (void)state;
    static rch_robot r;
    load(&r, truth_path());
    const char *evil = "R \"q\" <x> & 'y' --> <!-- ]]>-";
    snprintf(r.name, sizeof r.name, "%s\x01", evil);
    rch_urdf_names n;
    rch_urdf_names_default(&n, r.name);
    snprintf(n.joint[2], sizeof n.joint[2], "j3\"/><evil a='&'");
    const rch_export_cfg cfg = {RCH_EXPORT_URDF, &n, NULL, "a--b-", 0};
    rch_export_result res;
    int rc;
    char *xml = export_str(&cfg, &r, &res, &rc);
    assert_int_equal(rc, 0);
    assert_int_equal(res.n_joints, 7);
    char got[256], want[256];
    const char *at = strstr(xml, "<robot name=\"");
    assert_non_null(at);
    xml_decode_attr(got, sizeof got, at + strlen("<robot name=\""));
    snprintf(want, sizeof want, "%s\xEF\xBF\xBD", evil); /* the control character cannot be in XML at all: U+FFFD */
    assert_string_equal(got, want);
    at = strstr(xml, "<joint name=\"j3");
    assert_non_null(at);
    xml_decode_attr(got, sizeof got, at + strlen("<joint name=\""));
    assert_string_equal(got, n.joint[2]);
    assert_null(strstr(xml, "<evil"));
    /* comments: no "--" inside, none ending in '-' */
    for (const char *c = strstr(xml, "<!--"); c; c = strstr(c, "<!--")) {
        const char *end = strstr(c + 4, "-->");
        assert_non_null(end);
        for (const char *p = c + 4; p < end; ++p)
            assert_false(p[0] == '-' && p[1] == '-');
        assert_true(end[-1] != '-');
        c = end + 3;
    }
    free(xml);
}

/* ---- nominal URDF names --------------------------------------------------- */

static const char *const good_urdf =
    "<?xml version=\"1.0\"?>\n<!-- <joint name=\"in a comment\"/> -->\n"
    "<!DOCTYPE robot [ <!ENTITY x \"y\"> ]>\n"
    "<robot name='arm &amp; &#x3C;co&#62;'>\n"
    " <joint name=\"j4\" type=\"revolute\"><parent link=\"l3\"/><child link=\"l4\"/></joint>\n"
    " <joint name=\"world_joint\" type=\"fixed\"><parent link=\"world\"/><child link=\"base\"/></joint>\n"
    " <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"l1\"/></joint>\n"
    " <joint name=\"j2\" type=\"revolute\"><parent link=\"l1\"/><child link=\"l2\"/></joint>\n"
    " <joint name=\"j3\" type=\"revolute\"><parent link=\"l2\"></parent><child link=\"l3\"/></joint>\n"
    " <transmission name=\"t\"><joint name=\"j1\"><hardwareInterface>x</hardwareInterface></joint></transmission>\n"
    " <joint name=\"sensor\" type=\"fixed\"><parent link=\"l2\"/><child link=\"cam\"/></joint>\n"
    " <joint name=\"j5\" type=\"revolute\"><parent link=\"l4\"/><child link=\"l5\"/></joint>\n"
    " <joint name=\"j6\" type=\"continuous\"><parent link=\"l5\"/><child link=\"l6\"/></joint>\n"
    " <joint name=\"tool\" type=\"fixed\"><parent link=\"l6\"/><child link=\"tool0\"/></joint>\n"
    " <![CDATA[ <joint name=\"cdata\" type=\"revolute\"/> ]]>\n"
    "</robot>\n";

static void test_names_from_nominal(void **state)
{
    (void)state;
    rch_urdf_names n;
    rch_diag d;
    char msg[1024];
    if (rch_urdf_names_parse(&n, good_urdf, strlen(good_urdf), "good.urdf", &d) != 0)
        fail_msg("%s", rch_diag_str(&d, msg, sizeof msg));
    assert_string_equal(n.robot, "arm & <co>");
    assert_string_equal(n.base_link, "base");
    for (unsigned i = 0; i < RC_NJ; ++i) {
        char j[8], l[8];
        snprintf(j, sizeof j, "j%u", i + 1);
        snprintf(l, sizeof l, "l%u", i + 1);
        assert_string_equal(n.joint[i], j);
        assert_string_equal(n.link[i], l);
        assert_int_equal(n.continuous[i], i == 5);
    }
    assert_string_equal(n.flange_joint, "tool");
    assert_string_equal(n.flange_link, "tool0");
    assert_int_equal(n.n_dropped, 2); /* world_joint, sensor */
    /* the same with a UTF-8 byte-order mark */
    /* sizes stated once (a strcpy to bom + 3 was -Werror=array-bounds in the ASan+UBSan build) */
    size_t len = strlen(good_urdf), bom_len = 3 + len;
    char *bom = malloc(bom_len + 1);
    assert_non_null(bom);
    memcpy(bom, "\xEF\xBB\xBF", 3);
    memcpy(bom + 3, good_urdf, len + 1);
    assert_int_equal(rch_urdf_names_parse(&n, bom, bom_len, "bom.urdf", &d), 0);
    assert_string_equal(n.joint[3], "j4");
    free(bom);
}

static void expect_refused(const char *text, const char *needle)
{
    rch_urdf_names n;
    rch_diag d;
    char msg[1024];
    assert_int_equal(rch_urdf_names_parse(&n, text, strlen(text), "bad.urdf", &d), -1);
    rch_diag_str(&d, msg, sizeof msg);
    if (!strstr(msg, needle))
        fail_msg("message \"%s\" lacks \"%s\"", msg, needle);
}

static char *replace(const char *s, const char *from, const char *to)
{
    const char *at = strstr(s, from);
    assert_non_null(at);
    size_t head = (size_t)(at - s), n_to = strlen(to), n_tail = strlen(at + strlen(from));
    char *out = malloc(head + n_to + n_tail + 1);
    assert_non_null(out);
    memcpy(out, s, head);
    memcpy(out + head, to, n_to);
    memcpy(out + head + n_to, at + strlen(from), n_tail + 1);
    return out;
}

/* the XML is expat's (issue 51): a document that is not well formed is
 * refused with expat's reason */
static void test_bad_nominal_refused(void **state)
{
    (void)state;
    static const struct {
        const char *from, *to, *needle;
    } cases[] = {
        {"</robot>", "", "no element found"},
        {"<parent link=\"l2\"></parent>", "<parent link=\"l2\"></child>", "mismatched tag"},
        {"type=\"continuous\"", "type=\"prismatic\"", "prismatic"},
        {"<joint name=\"j5\" type=\"revolute\">", "<joint name=\"j5\" type=\"fixed\">", "5 revolute"},
        {"<parent link=\"l4\"/><child link=\"l5\"/>", "<parent link=\"l3\"/><child link=\"l5\"/>", "serial chain"},
        {"<robot name=", "<robots name=", "not a URDF"},
        {"&amp;", "&nbsp;", "undefined entity"},
        {"<parent link=\"l1\"/>", "", "needs <parent link>"},
        {"name=\"j2\"", "name=\"j2\" x=\"<\"", "not well-formed"},
        {"name=\"j2\"", "name=\"j2", "not well-formed"},
        {"<![CDATA[", "<![CDATA", "not well-formed"},
        {"name=\"j1\" type=\"revolute\"",
         "name=\"j1aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"
         "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\" type=\"revolute\"",
         "too long"},
        {"</robot>\n", "</robot>\n<robot/>", "junk after document element"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char *text = replace(good_urdf, cases[i].from, cases[i].to);
        expect_refused(text, cases[i].needle);
        free(text);
    }
    /* every proper prefix of the document is refused, never read past its end */
    for (size_t len = 0; len + 1 < strlen(good_urdf); ++len) {
        rch_urdf_names n;
        rch_diag d;
        char *cut = malloc(len + 1);
        assert_non_null(cut);
        memcpy(cut, good_urdf, len);
        cut[len] = '\0';
        assert_int_equal(rch_urdf_names_parse(&n, cut, len, "cut.urdf", &d), -1);
        free(cut);
    }
}

/* ---- effects ----------------------------------------------------------- */

static void test_joint_effects(void **state)
{
    (void)state;
    static rch_robot r;
    parse_model(&r, se_model);
    rch_export_cfg cfg = {RCH_EXPORT_URDF, NULL, NULL, "m.json", 0};
    rch_export_result res;
    int rc;
    char *xml = export_str(&cfg, &r, &res, &rc);
    assert_int_equal(rc, -1);
    free(xml);
    cfg.drop_joint_effects = 1;
    xml = export_str(&cfg, &r, &res, &rc);
    assert_int_equal(rc, 0);
    assert_int_equal(res.n_effects_left, 2); /* joint_periodic, length_scale */
    assert_non_null(strstr(xml, "joint_periodic (joint-side) not carried"));
    assert_non_null(strstr(xml, "length_scale (cable-length side) not carried"));
    free(xml);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_origins_reproduce_fk), cmocka_unit_test(test_csv_reads_back),
        cmocka_unit_test(test_se_block),             cmocka_unit_test(test_hostile_names_escaped),
        cmocka_unit_test(test_names_from_nominal),   cmocka_unit_test(test_bad_nominal_refused),
        cmocka_unit_test(test_joint_effects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
