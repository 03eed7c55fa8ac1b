"""``python -m app serve`` does what the ``lagrange-lab`` console script does."""

from app.cli import main

raise SystemExit(main())
