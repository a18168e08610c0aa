#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""doc_links - every link between the project's Markdown pages resolves.

Usage: scripts/doc_links.py [FILE.md ...]   (default: DESIGN.md, README.md, docs/*.md)

Checks markdown links `[text](path#anchor)` and bare references `docs/page.md#anchor` (DESIGN.md names its
figures' sections that way): the file exists (relative to the page, else to the repository root) and the
anchor is a heading of that page as GitHub spells it (lower case, punctuation dropped, spaces as hyphens,
a repeated heading suffixed -1, -2, ...). Prints each broken reference as FILE: what, exits 1 if any.
"""
import glob
import os
import re
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))


def anchors(path):
    out, seen, in_code = set(), {}, False
    with open(path, encoding='utf-8') as f:
        for line in f:
            if line.startswith('```'):
                in_code = not in_code
                continue
            m = None if in_code else re.match(r'^(#{1,6})\s+(.*?)\s*#*\s*$', line)
            if not m:
                continue
            slug = re.sub(r'[^\w\- ]', '', m.group(2).strip().lower()).replace(' ', '-')
            n = seen.get(slug, 0)
            seen[slug] = n + 1
            out.add(slug if n == 0 else '%s-%d' % (slug, n))
    return out


def check(page):
    bad = 0
    path = os.path.join(ROOT, page)
    with open(path, encoding='utf-8') as f:
        text = f.read()
    refs = set(re.findall(r'\]\(([^)\s]+)\)', text))
    refs |= set(re.findall(r'(?<![\w/(\[\-.])((?:docs/|python/)?[\w\-]+\.md#[\w\-]+)', text))
    for ref in sorted(refs):
        if re.match(r'^[a-z]+:', ref):
            continue
        target, _, anchor = ref.partition('#')
        if target:
            cands = [os.path.normpath(os.path.join(os.path.dirname(path), target)),
                     os.path.normpath(os.path.join(ROOT, target))]
            found = next((c for c in cands if os.path.exists(c)), None)
            if found is None:
                print('%s: no file %s' % (page, ref))
                bad += 1
                continue
        else:
            found = path
        if anchor and found.endswith('.md') and anchor not in anchors(found):
            print('%s: no heading #%s in %s' % (page, anchor, os.path.relpath(found, ROOT)))
            bad += 1
    return bad


def main(argv):
    pages = argv or ['DESIGN.md', 'README.md'] + sorted(
        os.path.relpath(p, ROOT) for p in glob.glob(os.path.join(ROOT, 'docs', '*.md')))
    bad = sum(check(p) for p in pages)
    print('doc_links: %d pages, %d broken references' % (len(pages), bad))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
