#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""test_report_browser.py - rcal report rendered in a real headless browser.

Builds the report of a real run on the demo data (rcal calibrate --truth --json,
rcal calibrate --out, rcal diagnose --json, rcal report), then:
  - static checks of the HTML: no script, no external resource of any kind (no
    src/href/url() other than a fragment or data:, no http:// or https:// at
    all), every <svg> with a positive width and height, one <svg> per plot;
  - the plot data: every report_<plot>.csv beside the page, its figures equal
    to the JSON the report was made from;
  - Debian's chromium (headless): a 1200x3000 screenshot that is a PNG and not
    blank; the DOM after parsing (--dump-dom) passes the same static checks;
    Chromium's own network log shows no request made by the page (the log
    detector is proven on a page that does make one, and a host-resolver rule
    keeps every name unresolved, so nothing leaves the machine either way);
  - every plot visible: a copy of the page with a probe script (the shipped
    page has none) reports each <svg>'s box after layout; each box must be
    displayed, non-empty, inside the page, and the full-page screenshot must
    show ink inside it.
Skips (exit 77) with a message when chromium or the demo data are absent.

usage: test_report_browser.py RCAL SOURCE_DIR WORK_DIR [--screenshot-out PNG]
(--screenshot-out copies the 1200x3000 screenshot, e.g. to
docs/report_screenshot.png.)
"""
import csv
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "common"))
from rct_check import check, failures as FAILS, passes as PASSES  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pngread  # noqa: E402


def run(cmd, cwd, stdout=None):
    p = subprocess.run(cmd, cwd=cwd, stdout=stdout or subprocess.PIPE, stderr=subprocess.PIPE, timeout=300)
    if p.returncode != 0:
        sys.stderr.write(p.stderr.decode(errors='replace'))
        raise SystemExit('FAIL: %s exited %d' % (' '.join(cmd), p.returncode))
    return p


# ---- static checks ------------------------------------------------------

FORBIDDEN_TAGS = {'script', 'link', 'img', 'iframe', 'frame', 'object', 'embed', 'source', 'video', 'audio',
                  'track', 'base', 'form', 'input', 'picture', 'image', 'use', 'foreignobject', 'feimage'}
URL_ATTRS = {'src', 'href', 'xlink:href', 'action', 'formaction', 'poster', 'srcset', 'data', 'background',
             'ping', 'manifest', 'cite', 'longdesc'}


def local_ref(v):
    v = v.strip()
    return v.startswith('#') or v.startswith('data:')


class Scan(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.problems, self.svgs, self.in_style, self.style = [], [], False, []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in FORBIDDEN_TAGS:
            self.problems.append('<%s> element' % tag)
        if tag == 'meta' and (a.get('http-equiv') or '').lower() == 'refresh':
            self.problems.append('<meta http-equiv=refresh>')
        for k, v in attrs:
            if k.startswith('on'):
                self.problems.append('event handler %s= on <%s>' % (k, tag))
            if k in URL_ATTRS and v is not None and not local_ref(v):
                self.problems.append('%s="%s" on <%s>' % (k, v, tag))
            if k == 'style' and v:
                self.style.append(v)
        if tag == 'svg':
            self.svgs.append((a.get('width'), a.get('height')))
        if tag == 'style':
            self.in_style = True

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)

    def handle_endtag(self, tag):
        if tag == 'style':
            self.in_style = False

    def handle_data(self, data):
        if self.in_style:
            self.style.append(data)


def static_problems(text):
    s = Scan()
    s.feed(text)
    s.close()
    probs = list(s.problems)
    for css in s.style:
        if '@import' in css:
            probs.append('@import in CSS')
    for m in re.finditer(r'url\(\s*[\'"]?([^\'")]*)', text):
        if not local_ref(m.group(1)):
            probs.append('url(%s)' % m.group(1))
    for scheme in ('http://', 'https://', 'ftp://', 'file://', 'ws://', 'wss://'):
        if scheme in text.lower():
            probs.append('"%s" in the page' % scheme)
    for w, h in s.svgs:
        try:
            ok = float(w) > 0 and float(h) > 0
        except (TypeError, ValueError):
            ok = False
        if not ok:
            probs.append('<svg width=%r height=%r>' % (w, h))
    return probs, len(s.svgs)


# ---- chromium -----------------------------------------------------------

def chromium_cmd(chrome, profile, *extra):
    return [chrome, '--headless', '--no-sandbox', '--disable-gpu', '--hide-scrollbars', '--no-first-run',
            '--disable-background-networking', '--disable-component-update', '--disable-sync',
            '--disable-extensions', '--host-resolver-rules=MAP * ~NOTFOUND', '--user-data-dir=' + profile] + list(extra)


def page_requests(netlog_path):
    """URLs the page (a file:// document) asked the network stack for."""
    log = json.load(open(netlog_path))
    names = {v: k for k, v in log['constants']['logEventTypes'].items()}
    urls = []
    for e in log['events']:
        p = e.get('params') or {}
        if names.get(e['type']) == 'URL_REQUEST_START_JOB' and 'file://' in str(p.get('network_isolation_key', '')):
            if not (p['url'].startswith('file:') or p['url'].startswith('data:')):
                urls.append(p['url'])
    return urls


def screenshot(chrome, profile, page, png, size, netlog=None):
    if os.path.exists(png):
        os.remove(png)
    extra = ['--screenshot=' + png, '--window-size=%d,%d' % size]
    if netlog:
        extra.append('--log-net-log=' + netlog)
    run(chromium_cmd(chrome, profile, *extra, 'file://' + page), cwd=os.path.dirname(page))


def dump_dom(chrome, profile, page, size=(1200, 3000)):
    """The DOM after parsing and layout at the screenshot's width (or size)."""
    return run(chromium_cmd(chrome, profile, '--window-size=%d,%d' % size, '--dump-dom', 'file://' + page),
               cwd=os.path.dirname(page)).stdout.decode('utf-8', errors='replace')


PROBE = """<script>
(function () {
  var out = [];
  document.querySelectorAll('svg').forEach(function (s) {
    var r = s.getBoundingClientRect(), cs = getComputedStyle(s);
    out.push({x: r.left + scrollX, y: r.top + scrollY, w: r.width, h: r.height, display: cs.display,
              visibility: cs.visibility, opacity: cs.opacity});
  });
  var pre = document.createElement('pre');
  pre.id = 'probe';
  pre.textContent = JSON.stringify({page_w: document.documentElement.scrollWidth,
                                    page_h: document.documentElement.scrollHeight, svgs: out});
  document.body.appendChild(pre);
})();
</script>"""


# ---- the test -----------------------------------------------------------

def make_report(rcal, src, work):
    data, truth = 'data/sim_irb120.csv', 'data/sim_irb120_truth.json'
    cal, model, diag, page = (os.path.join(work, n) for n in ('cal.json', 'model.json', 'diag.json', 'report.html'))
    with open(cal, 'wb') as f:
        run([rcal, 'calibrate', '--data', data, '--truth', truth, '--json'], src, stdout=f)
    run([rcal, 'calibrate', '--data', data, '--out', model], src)
    with open(diag, 'wb') as f:
        run([rcal, 'diagnose', '--data', data, '--json'], src, stdout=f)
    p = run([rcal, 'report', '--calibration', cal, '--diagnosis', diag, '--model', model, '--out', page], src)
    msg = p.stderr.decode()
    m = re.search(r'\((\d+) plots', msg)
    check(m is not None, 'rcal report says how many plots it drew: %s' % msg.splitlines()[0])
    return page, json.load(open(cal)), json.load(open(diag)), int(m.group(1)) if m else -1


def post_class(u):
    """The class the report shows: the one vocabulary ("seen", rch_seen.h) when the file has it, else what the data
    did to the prior for a MAP fit, else the identifiability class."""
    words = {'data': 'determined by the data', 'partly': 'partly determined', 'prior_only': 'prior only',
             'unseen': 'not seen by the data', 'held': 'held'}
    if u.get('seen') in words:
        return words[u['seen']]
    p = u.get('data_vs_prior')
    return p if p and p != 'no prior' else u['class']


def check_csvs(work, cal, diag):
    rows = list(csv.DictReader(open(os.path.join(work, 'report_metrics.csv'))))
    after = [r for r in rows if r['set'] == 'held-out' and r['model'] == 'after' and r['metric'] == 'rmse_mm']
    check(len(after) == 1 and abs(float(after[0]['value_mm']) - cal['after']['rmse_mm']) < 1e-12,
          'report_metrics.csv: held-out RMSE after = %s (JSON %s)' % (after[0]['value_mm'] if after else '?',
                                                                    cal['after']['rmse_mm']))
    rows = list(csv.DictReader(open(os.path.join(work, 'report_params.csv'))))
    check([r['name'] for r in rows] == [p['name'] for p in cal['params']], 'report_params.csv: the %d parameters'
          % len(cal['params']))
    check(all(abs(float(r['correction']) - p['delta']) <= 1e-8 * max(1.0, abs(p['delta']))
              for r, p in zip(rows, cal['params'])), 'report_params.csv: corrections equal the JSON deltas')
    unc = {u['name']: u for u in cal.get('uncertainty', {}).get('parameters', [])}
    if unc:
        se_ok = all((r['std_error'] == '') == (unc[r['name']]['std_error'] is None) and
                    (r['std_error'] == '' or abs(float(r['std_error']) - unc[r['name']]['std_error'])
                     <= 1e-8 * unc[r['name']]['std_error']) and r['class'] == post_class(unc[r['name']])
                    for r in rows)
        check(se_ok, 'report_params.csv: standard errors and classes equal the JSON uncertainty')
    rows = list(csv.DictReader(open(os.path.join(work, 'report_candidates.csv'))))
    check([r['effect'] for r in rows] == [c['effect'] for c in diag['candidates']],
          'report_candidates.csv: the %d candidates of the diagnosis' % len(diag['candidates']))
    rows = list(csv.DictReader(open(os.path.join(work, 'report_accuracy.csv'))))
    truth = [r for r in rows if r['quantity'] == 'truth, after: RMS']
    check(len(truth) == 1 and abs(float(truth[0]['value_mm']) - cal['truth_flange']['after_rms_mm']) < 1e-12,
          'report_accuracy.csv: flange RMS against the truth after = %s' % (truth[0]['value_mm'] if truth else '?'))


def check_browser(chrome, work, page, n_plots, shot_out):
    profile = os.path.join(work, 'chromium-profile')
    shot, netlog = os.path.join(work, 'report.png'), os.path.join(work, 'netlog.json')
    screenshot(chrome, profile, page, shot, (1200, 3000), netlog)
    check(os.path.exists(shot), 'chromium wrote the screenshot %s' % shot)
    img = pngread.read(shot)
    check(img[0] == 1200 and img[1] == 3000, 'screenshot is 1200 x 3000 (%d x %d)' % (img[0], img[1]))
    ink = pngread.count_non_white(img, level=200)
    check(ink > 0.01 * img[0] * img[1], 'screenshot is not blank: %d dark pixels (%.1f %%)'
          % (ink, 100.0 * ink / (img[0] * img[1])))
    reqs = page_requests(netlog)
    check(reqs == [], 'no request leaves the page (network log): %s' % (reqs or 'none'))
    probs, _ = static_problems(dump_dom(chrome, profile, page))
    check(probs == [], 'DOM after parsing: no script, no external resource: %s' % (probs or 'none'))

    # the detector itself: a page that does ask for a remote image is caught
    bad = os.path.join(work, 'leaky.html')
    with open(bad, 'w') as f:
        f.write('<!DOCTYPE html><html><body><p>leak</p><img src="http://example.invalid/x.png"></body></html>')
    screenshot(chrome, profile, bad, os.path.join(work, 'leaky.png'), (400, 300), os.path.join(work, 'leaky.json'))
    check(page_requests(os.path.join(work, 'leaky.json')) == ['http://example.invalid/x.png'],
          'the network-log check catches a page that loads a remote image')

    # every plot visible: boxes after layout, and ink inside each in a full-page shot
    text = open(page, encoding='utf-8').read()
    probe_page = os.path.join(work, 'report_probe.html')
    with open(probe_page, 'w', encoding='utf-8') as f:
        f.write(text.replace('</body>', PROBE + '</body>'))
    m = re.search(r'<pre id="probe">(.*?)</pre>', dump_dom(chrome, profile, probe_page), re.S)
    check(m is not None, 'the probe copy reports the layout')
    if not m:
        return
    probe = json.loads(html.unescape(m.group(1)))
    # a laptop's 1280 px: the page never scrolls sideways (issue 33; a wide table scrolls inside its section)
    m1280 = re.search(r'<pre id="probe">(.*?)</pre>', dump_dom(chrome, profile, probe_page, (1280, 900)), re.S)
    w1280 = json.loads(html.unescape(m1280.group(1)))['page_w'] if m1280 else -1
    check(0 < w1280 <= 1280, 'at 1280 px wide the page is %s px wide: no sideways scrolling' % w1280)
    check(len(probe['svgs']) == n_plots, '%d plots laid out (rcal report drew %d)' % (len(probe['svgs']), n_plots))
    full = os.path.join(work, 'report_full.png')
    h = int(probe['page_h']) + 20
    screenshot(chrome, profile, probe_page, full, (1200, h))
    img = pngread.read(full)
    for k, s in enumerate(probe['svgs']):
        shown = s['display'] != 'none' and s['visibility'] == 'visible' and float(s['opacity']) > 0.5
        inside = s['w'] > 50 and s['h'] > 50 and s['x'] >= 0 and s['x'] + s['w'] <= 1200 + 0.5 \
            and s['y'] >= 0 and s['y'] + s['h'] <= h
        ink = pngread.count_non_white(img, int(s['x']) + 2, int(s['y']) + 2, int(s['x'] + s['w']) - 2,
                                      int(s['y'] + s['h']) - 2, level=200)
        check(shown and inside and ink > 300, 'plot %d: %.0f x %.0f at (%.0f, %.0f), %s, %d dark pixels'
              % (k + 1, s['w'], s['h'], s['x'], s['y'], 'shown' if shown else 'HIDDEN', ink))
    if shot_out:
        shutil.copyfile(shot, shot_out)
        print('screenshot copied to %s' % shot_out)


def main(argv):
    if len(argv) < 4:
        raise SystemExit(__doc__)
    rcal, src, work = os.path.abspath(argv[1]), os.path.abspath(argv[2]), os.path.abspath(argv[3])
    shot_out = os.path.abspath(argv[argv.index('--screenshot-out') + 1]) if '--screenshot-out' in argv else None
    chrome = os.environ.get('RCAL_CHROMIUM') or shutil.which('chromium') or shutil.which('chromium-browser')
    if not chrome:
        print('SKIP: chromium not found (Debian package chromium); the report is not rendered in a browser')
        return 77
    if not os.path.exists(os.path.join(src, 'data', 'sim_irb120.csv')):
        print('SKIP: the demo data data/sim_irb120.csv is absent')
        return 77
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    page, cal, diag, n_plots = make_report(rcal, src, work)
    text = open(page, encoding='utf-8').read()
    probs, n_svg = static_problems(text)
    check(probs == [], 'HTML: self-contained, no script, no external resource: %s' % (probs or 'none'))
    check(n_svg == n_plots and n_plots >= 5, '%d inline <svg> charts, all with a positive size' % n_svg)
    check('<style>' in text, 'CSS inline')
    check_csvs(work, cal, diag)
    check_browser(chrome, work, page, n_plots, shot_out)
    print('%d passed, %d failed' % (len(PASSES), len(FAILS)))
    return 1 if FAILS else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
