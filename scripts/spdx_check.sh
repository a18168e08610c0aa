#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/spdx_check.sh - every source file carries its licence: lists each
# file (*.c *.h *.inc *.sh CMakeLists.txt *.cmake *.in *.py, as git sees the tree:
# tracked and new files, ignored ones left out) without an
# "SPDX-License-Identifier: MIT" line in its first 3 lines, and fails when
# there is one. Outside git: every such file under the tree but build*/.
set -uo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT" || exit 2

list_files() {
    if git rev-parse --git-dir >/dev/null 2>&1; then
        git ls-files --cached --others --exclude-standard
    else
        find . -path './build*' -prune -o -type f -print | sed 's|^\./||'
    fi
}

n=0
missing=0
while IFS= read -r f; do
    case "$f" in
    *.c | *.h | *.inc | *.sh | *.cmake | *.in | *.py | CMakeLists.txt | */CMakeLists.txt) ;;
    *) continue ;;
    esac
    [ -f "$f" ] || continue # deleted in the work tree
    n=$((n + 1))
    if ! head -n 3 "$f" | grep -q 'SPDX-License-Identifier: MIT'; then
        echo "$f"
        missing=$((missing + 1))
    fi
done < <(list_files | sort)

if [ "$missing" -gt 0 ]; then
    echo "spdx_check: $missing of $n source files without 'SPDX-License-Identifier: MIT' in their first 3 lines" >&2
    exit 1
fi
echo "spdx_check: all $n source files carry SPDX-License-Identifier: MIT"
