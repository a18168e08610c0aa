/* SPDX-License-Identifier: MIT */
/* test_svg.c - rch_svg, the one writer of SVG markup: the document's start
 * (the order readers rely on), escaping of every text and attribute,
 * non-finite coordinates, the cut of a long formatted text between whole
 * UTF-8 characters, paths, groups and the clip region, the tick step and
 * the colour map. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_svg.h"
#include "rch_text.h"

typedef struct mem {
    char *buf;
    size_t len;
    FILE *f;
} mem;

static void mem_open(mem *m)
{
    m->buf = NULL;
    m->len = 0;
    m->f = open_memstream(&m->buf, &m->len);
    assert_non_null(m->f);
}

static char *mem_close(mem *m)
{
    assert_int_equal(fclose(m->f), 0);
    return m->buf;
}

/* Every '<' opens a tag that closes; elements nest. */
static void assert_balanced(const char *svg)
{
    long depth = 0;
    for (const char *s = strchr(svg, '<'); s; s = strchr(s + 1, '<')) {
        const char *e = strchr(s, '>');
        assert_non_null(e);
        if (s[1] == '/')
            depth--;
        else if (s[1] != '?' && e[-1] != '/')
            depth++;
        assert_true(depth >= 0);
    }
    assert_int_equal(depth, 0);
}

static void test_document(void **state)
{
    (void)state;
    mem m;
    mem_open(&m);
    const rch_svg_doc alone = {.width_px = 300.4, .height_px = 200, .title = "a \"b\"\n<c>"};
    rch_svg_begin(m.f, &alone);
    rch_svg_end(m.f);
    char *s = mem_close(&m);
    assert_true(strncmp(s, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
                           "width=\"300\" height=\"200\" viewBox=\"0 0 300 200\"",
                        strlen("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
                               "width=\"300\" height=\"200\" viewBox=\"0 0 300 200\"")) == 0);
    /* the title as an attribute keeps its line break as a reference, as text it is plain */
    assert_non_null(strstr(s, "aria-label=\"a &quot;b&quot;&#10;&lt;c&gt;\""));
    assert_non_null(strstr(s, "<title>a &quot;b&quot;\n&lt;c&gt;</title>"));
    assert_non_null(strstr(s, "fill=\"white\"/>"));
    assert_balanced(s);
    free(s);

    mem_open(&m);
    const rch_svg_doc in_page = {.width_px = NAN, .height_px = -5, .cls = "chart", .in_html = 1};
    rch_svg_begin(m.f, &in_page);
    rch_svg_end(m.f);
    s = mem_close(&m);
    /* inline in HTML: no declaration, no namespace; a size that is no size is one pixel, never "nan" */
    assert_true(strncmp(s, "<svg class=\"chart\" width=\"1\" height=\"1\"", 39) == 0);
    assert_null(strstr(s, "<title>"));
    assert_null(strstr(s, "nan"));
    free(s);
}

static void test_shapes_text(void **state)
{
    (void)state;
    mem m;
    mem_open(&m);
    const rch_svg_paint line = {.stroke = "#123456", .stroke_px = 1.8, .dash = "4 3", .round_cap = 1};
    const rch_svg_paint bar = {.fill = "#56B4E9", .fill_opacity = 0.85};
    rch_svg_group(m.f, "series", "segments", "a&b");
    rch_svg_line(m.f, 1, 2, INFINITY, NAN, &line);
    rch_svg_rect(m.f, 0, 0, -3, 4, &bar, "tip <x>");
    rch_svg_circle(m.f, 1.005, 2, 3, NULL);
    rch_svg_group_end(m.f);
    char *s = mem_close(&m);
    assert_non_null(strstr(s, "<g class=\"series\" data-kind=\"segments\"><title>a&amp;b</title>\n"));
    assert_non_null(strstr(s, "<line x1=\"1.00\" y1=\"2.00\" x2=\"0.00\" y2=\"0.00\" stroke=\"#123456\" "
                              "stroke-width=\"1.8\" stroke-dasharray=\"4 3\" stroke-linecap=\"round\"/>"));
    /* a negative width is an empty rectangle; the tooltip is the rectangle's own title */
    assert_non_null(strstr(s, "<rect x=\"0.00\" y=\"0.00\" width=\"0.00\" height=\"4.00\" fill=\"#56B4E9\" "
                              "fill-opacity=\"0.85\"><title>tip &lt;x&gt;</title></rect>"));
    /* no paint: an unfilled shape, not a black one */
    assert_non_null(strstr(s, "<circle cx=\"1.00\" cy=\"2.00\" r=\"3.00\" fill=\"none\"/>"));
    assert_balanced(s);
    free(s);

    mem_open(&m);
    rch_svg_pen pn;
    rch_svg_path_begin(&pn, m.f, &line);
    rch_svg_path_move(&pn, 1, 2);
    rch_svg_path_line(&pn, 3, 4.567);
    rch_svg_path_end(&pn);
    const double tri[6] = {0, 0, 1, 0, 0, 1};
    const rch_svg_paint solid = {.fill = "red"};
    rch_svg_polygon(m.f, tri, 3, &solid);
    rch_svg_polygon(m.f, tri, 0, &solid); /* nothing */
    rch_svg_clip(m.f, "area", 1, 2, 3, 4);
    rch_svg_group_end(m.f);
    s = mem_close(&m);
    /* fill first: a reader tells a polyline (fill="none") from a marker by the element's start */
    assert_non_null(strstr(s, "<path fill=\"none\" stroke=\"#123456\""));
    assert_non_null(strstr(s, " d=\"M1.00 2.00L3.00 4.57\"/>"));
    assert_non_null(strstr(s, "<path fill=\"red\" d=\"M0.00 0.00L1.00 0.00L0.00 1.00Z\"/>"));
    assert_int_equal((int)(strstr(s, "Z\"/>") != NULL) + (int)(strstr(strstr(s, "Z\"/>") + 1, "Z\"/>") != NULL), 1);
    assert_non_null(strstr(s, "<clipPath id=\"area\"><rect x=\"1.00\" y=\"2.00\" width=\"3.00\" height=\"4.00\"/>"));
    assert_non_null(strstr(s, "<g clip-path=\"url(#area)\">"));
    assert_balanced(s);
    free(s);

    mem_open(&m);
    const rch_svg_font ft = {.size_px = 11, .anchor = RCH_SVG_END, .fill = "#555", .bold = 1, .italic = 1,
                             .rotate_deg = -90};
    rch_svg_text(m.f, 10, 20, &ft, "a<b & \"c\" 'd'");
    rch_svg_text(m.f, 0, 0, NULL, "\xff ok");
    rch_svg_text(m.f, 0, 0, NULL, NULL);
    s = mem_close(&m);
    assert_non_null(strstr(s, "<text x=\"10.00\" y=\"20.00\" text-anchor=\"end\" font-size=\"11\" font-weight=\"bold\" "
                              "font-style=\"italic\" fill=\"#555\" transform=\"rotate(-90 10.00 20.00)\">"
                              "a&lt;b &amp; &quot;c&quot; &#39;d&#39;</text>"));
    assert_non_null(strstr(s, "<text x=\"0.00\" y=\"0.00\">&#xFFFD; ok</text>")); /* invalid UTF-8 replaced */
    assert_non_null(strstr(s, "<text x=\"0.00\" y=\"0.00\"></text>"));
    free(s);
}

/* A formatted text longer than the buffer is cut between whole characters:
 * what is written is well-formed UTF-8. */
static void test_textf_cut(void **state)
{
    (void)state;
    char big[1201];
    for (int i = 0; i < 600; ++i)
        memcpy(big + 2 * i, "\xc3\xa9", 2); /* e acute */
    big[1200] = '\0';
    for (int shift = 0; shift < 3; ++shift) {
        mem m;
        mem_open(&m);
        rch_svg_textf(m.f, 0, 0, NULL, "%.*s%s", shift, "xx", big);
        char *s = mem_close(&m);
        const char *a = strchr(s, '>') + 1, *b = strstr(a, "</text>");
        assert_non_null(b);
        assert_true(b - a <= 511 && b - a >= 509);
        for (const char *p = a; p < b;) {
            const size_t n = rch_utf8_len((const unsigned char *)p);
            assert_true(n > 0 && p + n <= b);
            p += n;
        }
        free(s);
    }
    rch_svg_textf(NULL, 0, 0, NULL, "%d", 1); /* no stream: nothing, no crash */
    rch_svg_text(NULL, 0, 0, NULL, "x");
    rch_svg_begin(NULL, NULL);
}

static void test_arithmetic(void **state)
{
    (void)state;
    assert_true(fabs(rch_svg_nice_step(10.0, 5.0) - 2.0) < 1e-12);
    assert_true(fabs(rch_svg_nice_step(1.0, 6.0) - 0.2) < 1e-12);
    assert_true(fabs(rch_svg_nice_step(7.5, 1.0) - 10.0) < 1e-12);
    assert_true(fabs(rch_svg_nice_step(3e-5, 1.0) - 2e-5) < 1e-17);
    assert_true(fabs(rch_svg_nice_step(4.0e6, 8.0) - 5e5) < 1e-6);
    assert_true(rch_svg_nice_step(0.0, 5.0) == 1.0);
    assert_true(rch_svg_nice_step(-1.0, 5.0) == 1.0);
    assert_true(rch_svg_nice_step(NAN, 5.0) == 1.0);
    assert_true(rch_svg_nice_step(1.0, 0.0) == 1.0);
    char c[8];
    rch_svg_viridis(c, 0.0);
    assert_string_equal(c, "#440154");
    rch_svg_viridis(c, 1.0);
    assert_string_equal(c, "#fde725");
    rch_svg_viridis(c, 7.0);
    assert_string_equal(c, "#fde725");
    rch_svg_viridis(c, -1.0);
    assert_string_equal(c, "#440154");
    rch_svg_viridis(c, NAN);
    assert_string_equal(c, "#440154");
    rch_svg_viridis(c, 0.5);
    assert_string_equal(c, "#21918c");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_document),
        cmocka_unit_test(test_shapes_text),
        cmocka_unit_test(test_textf_cut),
        cmocka_unit_test(test_arithmetic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
