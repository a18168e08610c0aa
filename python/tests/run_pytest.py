# SPDX-License-Identifier: MIT
"""Run pytest on the package's tests; exit 77 (ctest: skipped) with a clear
message when pytest is not installed (Debian: apt-get install python3-pytest)."""
import sys

try:
    import pytest
except ImportError:
    print("python_pytest: SKIPPED: pytest is not installed for %s (Debian: apt-get install python3-pytest)"
          % sys.executable)
    sys.exit(77)

sys.exit(pytest.main(sys.argv[1:]))
