"""`python -m benchmarks derive|integrate|load ...` (benchmarks/derive.py's commands),
`python -m benchmarks page ...` (first and repeat visits in Chromium) and
`python -m benchmarks class ...` (a class of students typing their own answers)."""

import sys

if len(sys.argv) > 1 and sys.argv[1] in ("page", "class"):
    command = sys.argv.pop(1)
    if command == "page":
        from benchmarks.page import main
    else:
        from benchmarks.classroom import main
else:
    from benchmarks.derive import main

sys.exit(main())
