# SPDX-License-Identifier: MIT
"""rct_check - the one check of the project's script tests: a line per check
("ok" or "FAIL" and what was checked), the results kept for the summary and
the exit status (failures, passes)."""

failures = []
passes = []


def check(cond, what):
    print(("ok    " if cond else "FAIL  ") + what)
    (passes if cond else failures).append(what)
    return cond
