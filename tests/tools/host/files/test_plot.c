/* SPDX-License-Identifier: MIT */
/* test_plot.c - rch_plot writes well-formed SVG with escaped text, legend,
 * ticks, log axis and bars, and survives degenerate input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rch_plot.h"

static char *render(const rch_plot *p)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    assert_int_equal(rch_plot_write_svg_stream(p, f), 0);
    fclose(f);
    return buf;
}

static size_t count(const char *hay, const char *needle)
{
    size_t n = 0;
    const char *s = hay;
    while ((s = strstr(s, needle)) != NULL) {
        n++;
        s += strlen(needle);
    }
    return n;
}

/* Every '<' opens a tag whose name is known, and tags balance. */
static void assert_balanced(const char *svg)
{
    long depth = 0;
    const char *s = svg;
    while ((s = strchr(s, '<')) != NULL) {
        const char *e = strchr(s, '>');
        assert_non_null(e);
        if (s[1] == '?') {
        } else if (s[1] == '/') {
            depth--;
        } else if (e[-1] != '/') {
            depth++;
        }
        assert_true(depth >= 0);
        s = e + 1;
    }
    assert_int_equal(depth, 0);
}

static void test_lines_legend_escape(void **state)
{
    double x[50], y1[50], y2[50];
    size_t k;
    rch_plot *p;
    char *svg;
    (void)state;
    for (k = 0; k < 50; k++) {
        x[k] = (double)k;
        y1[k] = exp(-0.1 * (double)k);
        y2[k] = 0.5 * exp(-0.05 * (double)k);
    }
    y2[10] = NAN; /* breaks the line, must not print "nan" */
    p = rch_plot_new("A <b> & \"c\"", "iteration", "RMS (mm)");
    assert_non_null(p);
    rch_plot_line(p, "LM & co", x, y1, 50);
    rch_plot_line(p, "EKF<2>", x, y2, 50);
    rch_plot_scatter(p, "pts", x, y1, 5);
    svg = render(p);
    assert_non_null(strstr(svg, "<svg"));
    assert_non_null(strstr(svg, "A &lt;b&gt; &amp; &quot;c&quot;"));
    assert_non_null(strstr(svg, "LM &amp; co"));
    assert_non_null(strstr(svg, "EKF&lt;2&gt;"));
    assert_null(strstr(svg, "nan"));
    assert_null(strstr(svg, "inf"));
    assert_null(strstr(svg, "<b>"));
    /* two lines in distinct colours, both in the legend */
    assert_non_null(strstr(svg, "#0072B2"));
    assert_non_null(strstr(svg, "#D55E00"));
    /* the NaN splits the second path into two sub-paths */
    assert_true(count(svg, "\"M") + count(svg, "M") >= 3);
    /* ticks: several labelled y and x ticks */
    assert_true(count(svg, "text-anchor=\"end\">") >= 4);
    assert_balanced(svg);
    free(svg);
    rch_plot_free(p);
}

static void test_logy_bars_file(void **state)
{
    const char *labels[3] = {"BC", "LM", "a&b"};
    double v[3] = {2.18, 0.36, 0.32}, e[3] = {0.1, 0.02, 0.01};
    double x[3] = {1, 2, 3}, y[3] = {1e-3, 0.1, 10.0};
    char path[] = "/tmp/rcal_plot_XXXXXX";
    int fd;
    rch_plot *p = rch_plot_new("bars", "method", "mm");
    rch_plot *q = rch_plot_new("log", "x", "y");
    char *svg;
    (void)state;
    rch_plot_bars(p, labels, v, e, 3);
    svg = render(p);
    assert_int_equal(count(svg, "<rect") - 2 /* background, frame */ - 1 /* clip */, 3);
    assert_non_null(strstr(svg, ">BC<"));
    assert_non_null(strstr(svg, "a&amp;b"));
    assert_balanced(svg);
    free(svg);

    rch_plot_logy(q, 1);
    rch_plot_line(q, "decay", x, y, 3);
    svg = render(q);
    /* decade ticks 0.001 .. 10 */
    assert_non_null(strstr(svg, ">0.001<"));
    assert_non_null(strstr(svg, ">10<"));
    assert_balanced(svg);
    free(svg);

    fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(rch_plot_write_svg(q, path), 0);
    {
        FILE *f = fopen(path, "r");
        char head[64] = {0};
        assert_non_null(f);
        assert_true(fread(head, 1, sizeof head - 1, f) > 10);
        fclose(f);
        assert_non_null(strstr(head, "<?xml"));
    }
    remove(path);
    assert_int_equal(rch_plot_write_svg(q, "/nonexistent-dir/x.svg"), -1);
    rch_plot_free(p);
    rch_plot_free(q);
}

static void test_degenerate(void **state)
{
    double one = 3.0;
    rch_plot *p = rch_plot_new(NULL, NULL, NULL);
    char *svg;
    (void)state;
    svg = render(p); /* empty chart */
    assert_balanced(svg);
    free(svg);
    rch_plot_line(p, "", &one, &one, 1); /* one point, constant range, no legend */
    rch_plot_logy(p, 1);
    svg = render(p);
    assert_balanced(svg);
    assert_null(strstr(svg, "nan"));
    free(svg);
    rch_plot_free(p);
    rch_plot_free(NULL);
    rch_plot_line(NULL, "x", &one, &one, 1);
    assert_int_equal(rch_plot_write_svg(NULL, "/tmp/x.svg"), -1);
}
/* The plot-directory helpers the commands share: mkdir -p (refusing a file
 * in the way), save-into-dir with its log line and error text, never over
 * one of the command's inputs (the input survives byte for byte), the
 * colour map's ends, XML text escaping. */
static void test_dir_helpers(void **state)
{
    char dir[64], sub[128], path[320], *buf = NULL;
    size_t len = 0;
    struct stat sb;
    rch_diag d;
    (void)state;
    strcpy(dir, "/tmp/rcal_plotdir_XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(sub, sizeof sub, "%s/a/b/c", dir);
    assert_int_equal(rch_plot_mkdir(sub), 0);
    assert_int_equal(stat(sub, &sb), 0);
    assert_true(S_ISDIR(sb.st_mode));
    assert_int_equal(rch_plot_mkdir(sub), 0); /* existing: fine */
    FILE *log = open_memstream(&buf, &len);
    assert_non_null(log);
    /* an input of the command that happens to carry a plot's name */
    char input[192];
    snprintf(input, sizeof input, "%s/q.svg", sub);
    FILE *in = fopen(input, "w");
    assert_non_null(in);
    fputs("measurements\n", in);
    fclose(in);
    char input2[192];
    snprintf(input2, sizeof input2, "%s/s.csv", sub);
    const char *const inputs[3] = {NULL, input, input2};
    const rch_plot_dir pd = {sub, inputs, 3, log};
    rch_plot *p = rch_plot_new("t", "x", "y");
    const double x[2] = {0, 1}, y[2] = {1, 2};
    rch_plot_line(p, "l", x, y, 2);
    assert_int_equal(rch_plot_save(p, &pd, "p.svg", &d), 0);
    fclose(log);
    snprintf(path, sizeof path, "  wrote %s/p.svg\n  wrote %s/p.csv\n", sub, sub);
    assert_string_equal(buf, path); /* the data beside the plot, always */
    free(buf);
    snprintf(path, sizeof path, "%s/p.svg", sub);
    assert_int_equal(stat(path, &sb), 0);
    assert_int_equal(rch_plot_save(rch_plot_new("t", "x", "y"), &pd, "q.svg", &d), -1);
    assert_non_null(strstr(d.msg, "same file as the input"));
    assert_int_equal(stat(input, &sb), 0);
    assert_int_equal(sb.st_size, 13); /* untouched */
    /* an input named like a plot's CSV: refused before the SVG is written */
    snprintf(input, sizeof input, "%s", input2);
    in = fopen(input, "w");
    assert_non_null(in);
    fputs("measurements\n", in);
    fclose(in);
    assert_int_equal(rch_plot_save(rch_plot_new("t", "x", "y"), &pd, "s.svg", &d), -1);
    assert_non_null(strstr(d.msg, "same file as the input"));
    snprintf(path, sizeof path, "%s/s.svg", sub);
    assert_int_not_equal(stat(path, &sb), 0);
    assert_int_equal(stat(input, &sb), 0);
    assert_int_equal(sb.st_size, 13);
    /* a file where a directory is wanted */
    snprintf(path, sizeof path, "%s/p.svg/d", sub);
    errno = 0;
    assert_int_equal(rch_plot_mkdir(path), -1);
    assert_int_equal(errno, ENOTDIR);
    /* unwritable target and a failed allocation (NULL chart) are errors naming the file */
    const rch_plot_dir bad = {path, NULL, 0, NULL};
    assert_int_equal(rch_plot_save(rch_plot_new("t", "x", "y"), &bad, "q.svg", &d), -1);
    assert_int_equal(rch_plot_save(NULL, &pd, "r.svg", &d), -1);
    assert_non_null(strstr(d.msg, "r.svg"));
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    assert_int_equal(system(path), 0);
}

/* Count the points drawn inside each <g class="series">: vertices (M/L)
 * of an unfilled path, one per marker (circle, rect, filled path). */
static size_t drawn_points(const char *svg)
{
    size_t n = 0;
    const char *g = svg;
    while ((g = strstr(g, "<g class=\"series\">")) != NULL) {
        const char *end = strstr(g, "</g>");
        assert_non_null(end);
        for (const char *e = strchr(g + 1, '<'); e && e < end; e = strchr(e + 1, '<')) {
            if (strncmp(e, "<path fill=\"none\"", 17) == 0) {
                const char *d = strstr(e, " d=\"");
                for (d += 4; *d != '"'; d++)
                    n += *d == 'M' || *d == 'L';
            } else if (strncmp(e, "<circle", 7) == 0 || strncmp(e, "<rect", 5) == 0 || strncmp(e, "<path", 5) == 0) {
                n++;
            }
        }
        g = end;
    }
    return n;
}

/* The data of every chart as CSV: one row per point with the axis labels
 * (and their units) as column names; bars by category with a legend, one
 * colour without; a subtitle; the drawn points match the rows; a single
 * point is one marker; p-values never print as 0. */
static void test_csv_categories(void **state)
{
    (void)state;
    double x[7], y[7];
    for (int k = 0; k < 7; k++) {
        x[k] = k;
        y[k] = 1.0 + k * k;
    }
    rch_plot *p = rch_plot_new("T", "iteration (count)", "RMS, length \"error\" (mm)");
    rch_plot_subtitle(p, "the paper's Fig. 9");
    rch_plot_line(p, "a", x, y, 7);
    rch_plot_scatter(p, "b", x, y, 3);
    rch_plot_line(p, "one", x + 2, y + 2, 1);
    char *svg = render(p);
    assert_non_null(strstr(svg, ">the paper&#39;s Fig. 9</text>"));
    assert_int_equal(drawn_points(svg), 7 + 3 + 1);
    assert_int_equal(count(svg, "<g class=\"series\">"), 3);
    free(svg);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_int_equal(rch_plot_write_csv_stream(p, f), 0);
    fclose(f);
    assert_true(strncmp(buf, "series,iteration (count),\"RMS, length \"\"error\"\" (mm)\"\n", 50) == 0);
    assert_int_equal(count(buf, "\n"), 1 + 7 + 3 + 1);
    assert_non_null(strstr(buf, "\na,6,37\n"));
    assert_non_null(strstr(buf, "\none,2,5\n"));
    free(buf);
    rch_plot_free(p);

    /* bars: one colour unless categories are given; categories get a legend */
    const char *labels[3] = {"BC", "LM", "EKF"};
    const double v[3] = {2.5, 1.5, 1.8}, e[3] = {0.2, 0.1, NAN};
    p = rch_plot_new("bars", "method", "RMSE (mm)");
    rch_plot_bars(p, labels, v, e, 3);
    svg = render(p);
    assert_int_equal(count(svg, "fill=\"#56B4E9\""), 3);
    assert_int_equal(count(svg, "fill=\"#E69F00\""), 0);
    free(svg);
    const unsigned cat[3] = {0, 1, 1};
    const char *names[2] = {"before calibration", "method"};
    rch_plot_bar_categories(p, cat, names, 2);
    svg = render(p);
    assert_int_equal(count(svg, "fill=\"#56B4E9\""), 1 + 1); /* bar + legend swatch */
    assert_int_equal(count(svg, "fill=\"#E69F00\""), 2 + 1);
    assert_non_null(strstr(svg, ">before calibration</text>"));
    const char *bars = strstr(svg, "<g class=\"bars\">");
    assert_non_null(bars);
    free(svg);
    buf = NULL;
    f = open_memstream(&buf, &len);
    assert_int_equal(rch_plot_write_csv_stream(p, f), 0);
    fclose(f);
    assert_non_null(strstr(buf, "series,category,method,RMSE (mm),+- RMSE (mm) (error bar half-length)\n"));
    assert_non_null(strstr(buf, "\nRMSE (mm),LM,1,1.5,0.1\n"));
    assert_non_null(strstr(buf, "\nRMSE (mm),EKF,2,1.8,nan\n"));
    free(buf);
    rch_plot_free(p);

    /* a table with no columns or missing cells is refused */
    const rch_plot_table bad = {NULL, 0, 0, 0, NULL, NULL};
    f = open_memstream(&buf, &len);
    assert_int_equal(rch_plot_table_write(f, &bad), -1);
    fclose(f);
    free(buf);

    char pb[32];
    assert_string_equal(rch_plot_fmt_p(pb, sizeof pb, 0.0), "< 1e-300");
    assert_string_equal(rch_plot_fmt_p(pb, sizeof pb, 1e-310), "< 1e-300");
    assert_string_equal(rch_plot_fmt_p(pb, sizeof pb, 3.04e-17), "3.0e-17");
    assert_string_equal(rch_plot_fmt_p(pb, sizeof pb, 1.0), "1.0e+00");
    assert_string_equal(rch_plot_fmt_p(pb, sizeof pb, NAN), "-");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lines_legend_escape),
        cmocka_unit_test(test_logy_bars_file),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_dir_helpers),
        cmocka_unit_test(test_csv_categories),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
