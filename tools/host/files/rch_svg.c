/* SPDX-License-Identifier: MIT */
/* rch_svg.c - the one writer of SVG markup; see rch_svg.h. */
#include "rch_svg.h"

#include <math.h>
#include <stdarg.h>
#include <string.h>

#include "rch_text.h"

/* A pixel coordinate: two decimals, 0 when not finite. */
static void num(FILE *f, const char *attr, double v)
{
    fprintf(f, " %s=\"%.2f\"", attr, isfinite(v) ? v : 0.0);
}

static void str(FILE *f, const char *attr, const char *s)
{
    fprintf(f, " %s=\"", attr);
    rch_xml_put(f, s, RCH_XML_WS_REFS);
    fputc('"', f);
}

static void paint(FILE *f, const rch_svg_paint *pt, int filled)
{
    static const rch_svg_paint none = {0};
    if (!pt)
        pt = &none;
    if (filled) {
        str(f, "fill", pt->fill ? pt->fill : "none");
        if (pt->fill && pt->fill_opacity > 0.0 && pt->fill_opacity < 1.0)
            fprintf(f, " fill-opacity=\"%.3g\"", pt->fill_opacity);
    }
    if (pt->stroke) {
        str(f, "stroke", pt->stroke);
        if (pt->stroke_px > 0.0)
            fprintf(f, " stroke-width=\"%.3g\"", pt->stroke_px);
        if (pt->dash)
            str(f, "stroke-dasharray", pt->dash);
        if (pt->round_cap)
            fputs(" stroke-linecap=\"round\"", f);
    }
}

static void title(FILE *f, const char *tip)
{
    if (!tip)
        return;
    fputs("<title>", f);
    rch_xml_put(f, tip, 0);
    fputs("</title>", f);
}

void rch_svg_begin(FILE *f, const rch_svg_doc *d)
{
    if (!f || !d)
        return;
    const double w = isfinite(d->width_px) && d->width_px > 0 ? d->width_px : 1.0;
    const double h = isfinite(d->height_px) && d->height_px > 0 ? d->height_px : 1.0;
    if (!d->in_html)
        fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"", f);
    else
        fputs("<svg", f);
    if (d->cls)
        str(f, "class", d->cls);
    fprintf(f, " width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\"", w, h, w, h);
    if (d->title) {
        fputs(" role=\"img\"", f);
        str(f, "aria-label", d->title);
    }
    str(f, "font-family", d->font_family ? d->font_family : "Helvetica, Arial, sans-serif");
    fprintf(f, " font-size=\"%.3g\">\n", d->font_px > 0.0 ? d->font_px : 12.0);
    title(f, d->title);
    fprintf(f, "<rect x=\"0\" y=\"0\" width=\"%.0f\" height=\"%.0f\" fill=\"white\"/>\n", w, h);
}

void rch_svg_end(FILE *f)
{
    if (f)
        fputs("</svg>\n", f);
}

void rch_svg_group(FILE *f, const char *cls, const char *kind, const char *tip)
{
    if (!f)
        return;
    fputs("<g", f);
    if (cls)
        str(f, "class", cls);
    if (kind)
        str(f, "data-kind", kind);
    fputc('>', f);
    title(f, tip);
    fputc('\n', f);
}

void rch_svg_group_end(FILE *f)
{
    if (f)
        fputs("</g>\n", f);
}

void rch_svg_clip(FILE *f, const char *id, double x, double y, double w, double h)
{
    if (!f || !id)
        return;
    fputs("<defs><clipPath", f);
    str(f, "id", id);
    fputs("><rect", f);
    num(f, "x", x);
    num(f, "y", y);
    num(f, "width", w);
    num(f, "height", h);
    fputs("/></clipPath></defs>\n<g clip-path=\"url(#", f);
    rch_xml_put(f, id, 0);
    fputs(")\">\n", f);
}

void rch_svg_rect(FILE *f, double x, double y, double w, double h, const rch_svg_paint *pt, const char *tip)
{
    if (!f)
        return;
    fputs("<rect", f);
    num(f, "x", x);
    num(f, "y", y);
    num(f, "width", w > 0.0 ? w : 0.0);
    num(f, "height", h > 0.0 ? h : 0.0);
    paint(f, pt, 1);
    if (tip) {
        fputc('>', f);
        title(f, tip);
        fputs("</rect>\n", f);
    } else {
        fputs("/>\n", f);
    }
}

void rch_svg_line(FILE *f, double x1, double y1, double x2, double y2, const rch_svg_paint *pt)
{
    if (!f)
        return;
    fputs("<line", f);
    num(f, "x1", x1);
    num(f, "y1", y1);
    num(f, "x2", x2);
    num(f, "y2", y2);
    paint(f, pt, 0);
    fputs("/>\n", f);
}

void rch_svg_circle(FILE *f, double cx, double cy, double r, const rch_svg_paint *pt)
{
    if (!f)
        return;
    fputs("<circle", f);
    num(f, "cx", cx);
    num(f, "cy", cy);
    num(f, "r", r);
    paint(f, pt, 1);
    fputs("/>\n", f);
}

void rch_svg_path_begin(rch_svg_pen *pn, FILE *f, const rch_svg_paint *pt)
{
    if (!pn)
        return;
    pn->f = f;
    if (!f)
        return;
    fputs("<path", f);
    paint(f, pt, 1);
    fputs(" d=\"", f);
}

static void pen_to(rch_svg_pen *pn, char cmd, double x, double y)
{
    if (pn && pn->f)
        fprintf(pn->f, "%c%.2f %.2f", cmd, isfinite(x) ? x : 0.0, isfinite(y) ? y : 0.0);
}

void rch_svg_path_move(rch_svg_pen *pn, double x, double y) { pen_to(pn, 'M', x, y); }
void rch_svg_path_line(rch_svg_pen *pn, double x, double y) { pen_to(pn, 'L', x, y); }

void rch_svg_path_close(rch_svg_pen *pn)
{
    if (pn && pn->f)
        fputc('Z', pn->f);
}

void rch_svg_path_end(rch_svg_pen *pn)
{
    if (pn && pn->f)
        fputs("\"/>\n", pn->f);
}

void rch_svg_polygon(FILE *f, const double *xy, size_t n, const rch_svg_paint *pt)
{
    rch_svg_pen pn;
    if (!f || !xy || n == 0)
        return;
    rch_svg_path_begin(&pn, f, pt);
    for (size_t k = 0; k < n; ++k)
        pen_to(&pn, k ? 'L' : 'M', xy[2 * k], xy[2 * k + 1]);
    rch_svg_path_close(&pn);
    rch_svg_path_end(&pn);
}

void rch_svg_text(FILE *f, double x, double y, const rch_svg_font *ft, const char *s)
{
    static const char *const anchor[3] = {"start", "middle", "end"};
    static const rch_svg_font plain = {0};
    if (!f)
        return;
    if (!ft)
        ft = &plain;
    fputs("<text", f);
    num(f, "x", x);
    num(f, "y", y);
    if (ft->anchor == RCH_SVG_MIDDLE || ft->anchor == RCH_SVG_END)
        fprintf(f, " text-anchor=\"%s\"", anchor[ft->anchor]);
    if (ft->size_px > 0.0)
        fprintf(f, " font-size=\"%.3g\"", ft->size_px);
    if (ft->bold)
        fputs(" font-weight=\"bold\"", f);
    if (ft->italic)
        fputs(" font-style=\"italic\"", f);
    if (ft->fill)
        str(f, "fill", ft->fill);
    if (ft->rotate_deg != 0.0 && isfinite(ft->rotate_deg))
        fprintf(f, " transform=\"rotate(%.3g %.2f %.2f)\"", ft->rotate_deg, isfinite(x) ? x : 0.0,
                isfinite(y) ? y : 0.0);
    fputc('>', f);
    rch_xml_put(f, s, 0);
    fputs("</text>\n", f);
}

void rch_svg_textf(FILE *f, double x, double y, const rch_svg_font *ft, const char *fmt, ...)
{
    char buf[512];
    va_list ap;
    if (!f || !fmt)
        return;
    va_start(ap, fmt);
    const int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0)
        buf[0] = '\0';
    else if ((size_t)n >= sizeof buf) { /* cut: drop a partial UTF-8 character at the end */
        const size_t end = sizeof buf - 1;
        size_t k = end;
        while (k > 0 && end - k < 3 && ((unsigned char)buf[k - 1] & 0xC0u) == 0x80u)
            --k;
        if (k > 0 && ((unsigned char)buf[k - 1] & 0xC0u) == 0xC0u) { /* the last character's lead byte */
            const unsigned c = (unsigned char)buf[k - 1];
            const size_t need = c >= 0xF0u ? 4 : c >= 0xE0u ? 3 : 2;
            if (k - 1 + need > end)
                buf[k - 1] = '\0';
        }
    }
    rch_svg_text(f, x, y, ft, buf);
}

double rch_svg_nice_step(double span, double want)
{
    const double raw = span / want;
    if (!(raw > 0.0) || !isfinite(raw))
        return 1.0;
    const double mag = pow(10.0, floor(log10(raw))), m = raw / mag;
    return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * mag;
}

void rch_svg_viridis(char out[8], double t)
{
    static const double stops[5][3] = {
        {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
    t = !(t > 0.0) ? 0.0 : (t > 1.0 ? 1.0 : t);
    const double u = t * 4.0;
    int i = (int)floor(u);
    if (i > 3)
        i = 3;
    const double fr = u - i;
    int rgb[3];
    for (int c = 0; c < 3; ++c)
        rgb[c] = (int)lround(stops[i][c] + fr * (stops[i + 1][c] - stops[i][c]));
    snprintf(out, 8, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
}
