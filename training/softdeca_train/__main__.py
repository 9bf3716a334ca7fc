"""Entry point: ``python -m softdeca_train <step> [options]``; every step has ``--help``."""

from __future__ import annotations

from softdeca_train.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
