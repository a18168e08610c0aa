# SPDX-License-Identifier: MIT
"""test_plots_read.py - the plots every command writes can be read without the code.

Runs every command that writes plots (rcal calibrate, diagnose, compare, grind,
chaos with --plots) on the demo data, and on the real data when
../shared/data/robotcali.csv is present, then checks each SVG written:
  - it parses as XML (xml.etree);
  - a CSV with the same base name lies beside it, with a header row, and it has
    as many data rows (finite numbers) as the SVG draws points: vertices of
    every line and one per marker inside <g class="series">, one per bar
    rect inside <g class="bars">, n points for the n - 1 coloured segments of
    a <g class="series" data-kind="segments">;
  - every text lies inside the viewBox (its width estimated from its length
    and font size; rotated labels along their rotated extent), the colour
    bars' labels included;
  - no p-value reads 0 ("p = 0", "p = 0.0e+00"), in the plots and in the
    text the commands print;
  - titles name no paper figure or equation (that goes in a subtitle);
  - bars have one colour, or each colour is a category named in the legend;
  - the set-up groups carry the same numbers in diagnose's two group plots;
  - the inline charts of rcal report's page keep their text inside them too;
  - a plot's CSV never replaces an input that carries its name (calibrate,
    diagnose, compare: the command refuses, the input is intact).
Exit 0 when every check passes, 1 otherwise.

usage: test_plots_read.py RCAL SOURCE_DIR WORK_DIR
"""
import csv
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "common"))
from rct_check import check, failures as FAILS  # noqa: E402

SVG = '{http://www.w3.org/2000/svg}'


def run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=600)
    if p.returncode != 0:
        sys.stderr.write(p.stderr.decode(errors='replace'))
        raise SystemExit('FAIL: %s exited %d' % (' '.join(cmd), p.returncode))
    return p.stdout.decode(errors='replace')


def tag(e):
    return e.tag[len(SVG):] if e.tag.startswith(SVG) else e.tag


# ---- what the SVG draws ---------------------------------------------------

def path_vertices(d):
    return len(re.findall(r'[ML]', d))


def drawn_points(root):
    n = 0
    for g in root.iter(SVG + 'g'):
        cls = g.get('class', '')
        if cls == 'series':
            if g.get('data-kind') == 'segments':
                lines = sum(1 for e in g if tag(e) == 'line')
                n += lines + 1 if lines else 0
                continue
            for e in g:
                t = tag(e)
                if t == 'path' and e.get('fill') == 'none':
                    n += path_vertices(e.get('d', ''))
                elif t in ('circle', 'rect', 'path'):
                    n += 1
        elif cls == 'bars':
            n += sum(1 for e in g if tag(e) == 'rect')
    return n


def csv_points(path):
    """Rows of the CSV whose numeric cells are all finite (error-bar column aside)."""
    with open(path, newline='') as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]

    def num(s):
        try:
            return float(s)
        except ValueError:
            return None
    numeric = [c for c in range(len(head)) if not head[c].startswith('+- ')
               and body and all(num(r[c]) is not None for r in body)]
    n = sum(1 for r in body if all(math.isfinite(num(r[c])) for c in numeric))
    return head, body, n


# ---- text placement ---------------------------------------------------------

def text_of(e):
    return ''.join(e.itertext())


def font_size(e, parents):
    for x in [e] + parents:
        if x.get('font-size'):
            return float(x.get('font-size'))
    return 12.0


def text_box(e, parents):
    """(x0, y0, x1, y1) of a text element, width estimated at 0.6 em per character."""
    fs = font_size(e, parents)
    s = text_of(e)
    w = 0.6 * fs * len(s)
    x, y = float(e.get('x', 0)), float(e.get('y', 0))
    anchor = e.get('text-anchor') or next((p.get('text-anchor') for p in parents if p.get('text-anchor')), 'start')
    x0 = {'start': x, 'middle': x - w / 2, 'end': x - w}[anchor]
    box = (x0, y - fs, x0 + w, y + 0.25 * fs)
    m = re.match(r'rotate\(\s*(-?[\d.]+)[ ,]+(-?[\d.]+)[ ,]+(-?[\d.]+)\s*\)', e.get('transform', ''))
    if m:
        a, cx, cy = math.radians(float(m.group(1))), float(m.group(2)), float(m.group(3))
        pts = [(box[0], box[1]), (box[2], box[1]), (box[0], box[3]), (box[2], box[3])]
        rot = [(cx + (px - cx) * math.cos(a) - (py - cy) * math.sin(a),
                cy + (px - cx) * math.sin(a) + (py - cy) * math.cos(a)) for px, py in pts]
        box = (min(p[0] for p in rot), min(p[1] for p in rot), max(p[0] for p in rot), max(p[1] for p in rot))
    return box


def texts_with_parents(root):
    out = []

    def walk(e, parents):
        for c in e:
            if tag(c) == 'text':
                out.append((c, [e] + parents))
            walk(c, [e] + parents)
    walk(root, [])
    return out


P_VALUE = re.compile(r'\bp\s*(?:=|<|is)?\s*(-?[0-9][0-9.]*(?:[eE][-+]?[0-9]+)?)')


def p_values(s):
    return [float(m.group(1)) for m in P_VALUE.finditer(s)]


# ---- one SVG ----------------------------------------------------------------

def check_svg(path):
    name = os.path.relpath(path, WORK)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        check(False, '%s parses as XML (%s)' % (name, e))
        return
    check(True, '%s parses as XML' % name)
    vb = [float(v) for v in root.get('viewBox').split()]
    csv_path = path[:-4] + '.csv'
    if check(os.path.isfile(csv_path), '%s has its data beside it (%s)' % (name, os.path.basename(csv_path))):
        head, body, n_csv = csv_points(csv_path)
        n_svg = drawn_points(root)
        check(n_svg > 0 and n_svg == n_csv,
              '%s draws %d points, its CSV has %d rows of finite numbers (columns: %s)' % (name, n_svg, n_csv,
                                                                                         ' | '.join(head)))
    outside = []
    for e, parents in texts_with_parents(root):
        x0, y0, x1, y1 = text_box(e, parents)
        if x0 < vb[0] - 1 or y0 < vb[1] - 1 or x1 > vb[0] + vb[2] + 1 or y1 > vb[1] + vb[3] + 1:
            outside.append('"%s" at (%.0f..%.0f, %.0f..%.0f)' % (text_of(e), x0, x1, y0, y1))
    check(not outside, '%s: every text inside the viewBox %s%s' % (name, vb, ('; outside: ' + ', '.join(outside))
                                                                  if outside else ''))
    bars = [t for t in texts_with_parents(root) if any(p.get('class') == 'colourbar' for p in t[1])]
    if bars:
        check(True, '%s: its %d colour-bar labels are among them' % (name, len(bars)))
    all_text = [text_of(e) for e, _ in texts_with_parents(root)]
    zero = [t for t in all_text if any(v <= 0.0 for v in p_values(t))]
    check(not zero, '%s: no p-value printed as 0%s' % (name, (': ' + '; '.join(zero)) if zero else ''))
    titles = [text_of(e) for e, parents in texts_with_parents(root) if font_size(e, parents) >= 15]
    jargon = [t for t in titles if re.search(r'\b(Fig|Eq)\.|\bkind\)', t)]
    check(titles and not jargon, '%s: the title says what is plotted (%s)' % (name, titles[0] if titles else '-'))
    for g in root.iter(SVG + 'g'):
        if g.get('class') != 'bars':
            continue
        fills = {e.get('fill') for e in g if tag(e) == 'rect'}
        legend = {e.get('fill') for e in root.iter(SVG + 'rect') if e not in list(g)}
        check(len(fills) == 1 or fills <= legend,
              '%s: bar colours %s are one colour or categories in the legend' % (name, sorted(fills)))


def groups_agree(diag_dir):
    """group_means and residuals_structure (when it is against the groups) use the same group numbers."""
    gm = os.path.join(diag_dir, 'group_means.csv')
    rs = os.path.join(diag_dir, 'residuals_structure.csv')
    if not (os.path.isfile(gm) and os.path.isfile(rs)):
        return
    with open(gm, newline='') as f:
        rows = list(csv.reader(f))
    g_means = {float(r[1]) for r in rows[1:]}
    with open(rs, newline='') as f:
        rows = list(csv.reader(f))
    if 'set-up group' not in rows[0][1]:
        print('     (%s: the strongest structure is not the groups)' % os.path.relpath(diag_dir, WORK))
        return
    check(rows[0][1] == 'set-up group (number as in the data\'s group column, else 0.. in file order)',
          'residuals_structure.csv names where its group numbers come from')
    g_struct = {float(r[1]) for r in rows[1:]}
    check(g_means == g_struct, '%s: the same %d group numbers in group_means and residuals_structure (%g..%g)'
          % (os.path.relpath(diag_dir, WORK), len(g_means), min(g_means), max(g_means)))


def text_p_values(name, out):
    zeros = [ln.strip() for ln in out.splitlines() if re.search(r'(^|\s)0\.0e\+00(\s|$)', ln)
             or any(v <= 0.0 for v in p_values(ln))]
    check(not zeros, '%s text: no p-value printed as 0%s' % (name, (': ' + zeros[0]) if zeros else ''))


def check_report_charts(rcal, src, data, d):
    """The inline SVG charts of rcal report: XML, every text inside the chart."""
    os.makedirs(d)
    cal, diag, page = (os.path.join(d, n) for n in ('cal.json', 'diag.json', 'report.html'))
    with open(cal, 'w') as f:
        f.write(run([rcal, 'calibrate', '--data', data, '--json'], src))
    with open(diag, 'w') as f:
        f.write(run([rcal, 'diagnose', '--data', data, '--json'], src))
    run([rcal, 'report', '--calibration', cal, '--diagnosis', diag, '--out', page], src)
    html = open(page, encoding='utf-8').read()
    charts = re.findall(r'<svg\b.*?</svg>', html, re.S)
    check(len(charts) >= 3, 'report: %d inline charts' % len(charts))
    for k, c in enumerate(charts):
        c = re.sub(r'^<svg\b', '<svg xmlns="http://www.w3.org/2000/svg"', c) if 'xmlns=' not in c[:300] else c
        try:
            root = ET.fromstring(c)
        except ET.ParseError as e:
            check(False, 'report chart %d parses as XML (%s)' % (k, e))
            continue
        vb = [float(v) for v in root.get('viewBox').split()]
        title = root.get('aria-label', '')
        outside = []
        for e, parents in texts_with_parents(root):
            x0, y0, x1, y1 = text_box(e, parents)
            if x0 < vb[0] - 1 or y0 < vb[1] - 1 or x1 > vb[0] + vb[2] + 1 or y1 > vb[1] + vb[3] + 1:
                outside.append('"%s" at (%.0f..%.0f)' % (text_of(e), x0, x1))
        check(not outside, 'report chart "%s": every text inside the chart%s' % (title, ('; outside: ' + ', '.join(
            outside)) if outside else ''))


def inputs_survive(rcal, src, demo):
    """A data file named like a plot's CSV, in the plot directory: refused, intact."""
    original = open(demo, 'rb').read()
    for cmd, name in (('calibrate', 'uncertainty_position.csv'), ('diagnose', 'group_means.csv'),
                      ('compare', 'rmse_bars.csv')):
        d = os.path.join(WORK, 'clash_' + cmd)
        os.makedirs(d)
        data = os.path.join(d, name)
        shutil.copyfile(demo, data)
        extra = ['--cases', '1', '--samples', '100'] if cmd == 'compare' else []
        p = subprocess.run([rcal, cmd, '--data', data, '--plots', d] + extra, cwd=src, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, timeout=600)
        check(p.returncode != 0 and open(data, 'rb').read() == original,
              '%s --plots: the input %s is refused as an output and stays intact (exit %d: %s)'
              % (cmd, name, p.returncode, p.stderr.decode(errors='replace').strip()[:120]))


def main():
    global WORK
    if len(sys.argv) != 4:
        raise SystemExit(__doc__)
    rcal, src, WORK = (os.path.abspath(a) for a in sys.argv[1:])
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    demo, truth = os.path.join(src, 'data', 'sim_irb120.csv'), os.path.join(src, 'data', 'sim_irb120_truth.json')
    real = os.path.join(src, '..', 'shared', 'data', 'robotcali.csv')
    sets = [('demo', demo)]
    if os.path.isfile(real):
        sets.append(('real', real))
    else:
        print('note: %s absent: the real-data plots are not checked' % real)
    for tagname, data in sets:
        d = os.path.join(WORK, tagname)
        model = os.path.join(WORK, tagname + '_model.json')
        # the real file's lengths jump and its joints are rounded: what a user runs on it
        extra = ['--jumps', '--dequantize-joints'] if tagname == 'real' else []
        run([rcal, 'calibrate', '--data', data, '--plots', os.path.join(d, 'calibrate'), '--out', model] + extra, src)
        out = run([rcal, 'diagnose', '--data', data, '--plots', os.path.join(d, 'diagnose')], src)
        text_p_values(tagname + ' diagnose', out)
        run([rcal, 'compare', '--data', data, '--cases', '2', '--samples', '200', '--seed', '1',
             '--plots', os.path.join(d, 'compare')], src)
    run([rcal, 'grind', '--model', os.path.join(WORK, 'demo_model.json'), '--truth', truth,
         '--plots', os.path.join(WORK, 'demo', 'grind')], src)
    run([rcal, 'chaos', '--plots', os.path.join(WORK, 'chaos')], src)
    check_report_charts(rcal, src, sets[-1][1], os.path.join(WORK, 'report'))
    inputs_survive(rcal, src, demo)
    svgs = sorted(os.path.join(dp, f) for dp, _, fs in os.walk(WORK) for f in fs
                  if f.endswith('.svg') and '/clash_' not in dp)
    # calibrate, diagnose and compare write 10 per data set; grind and chaos 2 each
    want = 10 * len(sets) + 4
    check(len(svgs) >= want, '%d SVG files written (at least %d for %d data sets)' % (len(svgs), want, len(sets)))
    for s in svgs:
        check_svg(s)
    for tagname, _ in sets:
        groups_agree(os.path.join(WORK, tagname, 'diagnose'))
    print('%d checks failed' % len(FAILS) if FAILS else 'all checks passed')
    return 1 if FAILS else 0


WORK = ''
if __name__ == '__main__':
    sys.exit(main())
